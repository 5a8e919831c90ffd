#include "framework/core/SystemMemory.h"

#include <cstdio>
#include <cstring>

namespace shadowlab {
namespace {

/// The value in kB of the line "<key>: <value> kB" of a /proc file, in bytes; 0 when absent.
size_t procKilobytes(const char* file, const char* key) {
    std::FILE* f = std::fopen(file, "r");
    if (!f) return 0;
    char line[256];
    size_t bytes = 0;
    const size_t keyLength = std::strlen(key);
    while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, key, keyLength) == 0 && line[keyLength] == ':') {
            unsigned long long kb = 0;
            if (std::sscanf(line + keyLength + 1, "%llu", &kb) == 1) bytes = size_t(kb) * 1024;
            break;
        }
    std::fclose(f);
    return bytes;
}

} // namespace

SystemMemory systemMemory() { return {procKilobytes("/proc/meminfo", "MemTotal"), procKilobytes("/proc/meminfo", "MemAvailable")}; }

size_t peakResidentBytes() { return procKilobytes("/proc/self/status", "VmHWM"); }

size_t residentBytes() { return procKilobytes("/proc/self/status", "VmRSS"); }

} // namespace shadowlab
