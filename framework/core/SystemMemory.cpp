#include "framework/core/SystemMemory.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <sys/resource.h>
#include <thread>

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

namespace {
/// The headroom of this process's cgroup (v2) under its memory.max, bytes; SIZE_MAX when unlimited or unknown.
size_t cgroupHeadroom() {
    std::FILE* f = std::fopen("/proc/self/cgroup", "r");
    if (!f) return SIZE_MAX;
    char line[4096];
    std::string path;
    while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, "0::", 3) == 0) {
            path = line + 3;
            while (!path.empty() && (path.back() == '\n' || path.back() == '\r')) path.pop_back();
        }
    std::fclose(f);
    if (path.empty() || path.find("..") != std::string::npos) return SIZE_MAX;
    auto readNumber = [&](const char* name) -> size_t {
        std::FILE* g = std::fopen(("/sys/fs/cgroup" + path + "/" + name).c_str(), "r");
        if (!g) return SIZE_MAX;
        unsigned long long v = 0;
        const bool ok = std::fscanf(g, "%llu", &v) == 1;  // "max" reads as no number: unlimited
        std::fclose(g);
        return ok ? size_t(v) : SIZE_MAX;
    };
    const size_t max = readNumber("memory.max"), current = readNumber("memory.current");
    if (max == SIZE_MAX) return SIZE_MAX;
    return current == SIZE_MAX || current >= max ? 0 : max - current;
}
/// Address space the libraries map after the plan is made, which no estimate of held bytes counts:
/// Embree's device, the shaders' JIT code and each worker thread's stack (llvmpipe's and Embree's,
/// one of each per core, each the size RLIMIT_STACK gives a thread). Under `ulimit -v` a run past it
/// dies in a library (eighteenth probe: a 300,000-triangle run planned within a 683 MiB limit ended
/// in SIGSEGV, a 16-triangle one in Embree's out of memory); measured at 2 cores, a run's VmPeak is
/// about 190 MB above its VmSize when planned (results/reference/memory_bounds_llvmpipe.md).
size_t laterAddressSpace() {
    const size_t cores = std::max(1u, std::thread::hardware_concurrency());
    return (size_t(256) << 20) + 2 * cores * threadStackBytes();
}

} // namespace

size_t threadStackBytes() {
    struct rlimit stack {};
    if (getrlimit(RLIMIT_STACK, &stack) == 0 && stack.rlim_cur != RLIM_INFINITY && stack.rlim_cur > 0) return size_t(stack.rlim_cur);
    return size_t(8) << 20;  // glibc's default for threads when the limit is unlimited
}

SystemMemory systemMemory() {
    SystemMemory m{procKilobytes("/proc/meminfo", "MemTotal"), procKilobytes("/proc/meminfo", "MemAvailable"), ""};
    struct rlimit limit {};
    if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
        const size_t used = procKilobytes("/proc/self/status", "VmSize") + laterAddressSpace();
        const size_t headroom = size_t(limit.rlim_cur) > used ? size_t(limit.rlim_cur) - used : 0;
        if (m.available == 0 || headroom < m.available) m = {m.total, headroom, "ulimit -v"};
    }
    if (const size_t headroom = cgroupHeadroom(); headroom != SIZE_MAX && (m.available == 0 || headroom < m.available))
        m = {m.total, headroom, "cgroup memory.max"};
    return m;
}

size_t peakResidentBytes() { return procKilobytes("/proc/self/status", "VmHWM"); }

size_t residentBytes() { return procKilobytes("/proc/self/status", "VmRSS"); }

} // namespace shadowlab
