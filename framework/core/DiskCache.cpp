#include "framework/core/DiskCache.h"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace shadowlab::diskcache {

namespace fs = std::filesystem;

std::string directory(const std::string& name) {
    // Absolute paths only: the XDG base directory spec calls a relative one invalid, to be ignored
    // (probe 25: a relative one put cache files in the working folder, outside any output).
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && xdg[0] == '/') return std::string(xdg) + "/shadowlab/" + name;
    if (const char* home = std::getenv("HOME"); home && home[0] == '/') return std::string(home) + "/.cache/shadowlab/" + name;
    return "";
}

uint64_t checksum(const void* data, size_t bytes, uint64_t h) {
    const auto* p = static_cast<const unsigned char*>(data);
    size_t i = 0;
    for (; i + 8 <= bytes; i += 8) {
        uint64_t w;
        std::memcpy(&w, p + i, 8);
        h = (h ^ w) * 1099511628211ull;
    }
    for (; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

bool writeAtomically(const std::string& path, std::initializer_list<Part> parts, std::string* why) {
    auto fail = [why](const std::string& reason) {
        if (why) *why = reason;
        return false;
    };
    std::error_code ec;
    fs::create_directories(fs::path(path).parent_path(), ec);
    const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return fail("cannot create " + tmp);
        for (const Part& p : parts) out.write(static_cast<const char*>(p.data), std::streamsize(p.bytes));
        if (!out) {
            fs::remove(tmp, ec);
            return fail("cannot write " + tmp);
        }
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        return fail("cannot rename " + tmp + " to " + path);
    }
    return true;
}

} // namespace shadowlab::diskcache
