#pragma once
// What the per-scene disk caches of the algorithms share (line_space's N-tree, metric_tree's
// clustering): where they live, how a file is checksummed, and how it is written so that a reader
// never sees half of it. Each cache keeps its own header and validation.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>

namespace shadowlab::diskcache {

/// $XDG_CACHE_HOME/shadowlab/<name>, else ~/.cache/shadowlab/<name>; "" when neither is set to an
/// absolute path (a relative one is ignored, as the XDG base directory spec says).
std::string directory(const std::string& name);

constexpr uint64_t kChecksumSeed = 1469598103934665603ull;
/// FNV-1a over 64-bit words (8× faster than per byte on pools of ~100 MB; the tail per byte).
/// Chain calls by passing the previous result as `h`.
uint64_t checksum(const void* data, size_t bytes, uint64_t h = kChecksumSeed);

struct Part {
    const void* data;
    size_t bytes;
};
/// Writes the parts, in order, to a temporary file beside `path` and renames it over `path`:
/// a reader never sees half a file, and two processes writing the same key each replace it whole.
/// Creates the folder. On failure returns false with the reason in `why` and leaves no temporary.
bool writeAtomically(const std::string& path, std::initializer_list<Part> parts, std::string* why);

/// The value cached at `path` when `load(&why)` accepts it, else `build()`'s, then written back with
/// `save(value, &why)`. `path` "" means no cache. A missing file is the normal first run (silent); a
/// file that fails validation is reported on stderr and replaced; a failed write is reported and
/// ignored. `hit` tells which happened.
template <class Load, class Build, class Save>
auto loadOrBuild(const char* owner, const std::string& path, Load load, Build build, Save save, bool* hit) {
    std::string why;
    std::error_code ec;
    auto status = path.empty() ? std::filesystem::file_status{} : std::filesystem::status(path, ec);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
        // A FIFO or device would block or stream forever on open; a directory cannot be read.
        std::fprintf(stderr, "%s: cache path %s is not a regular file; running without the cache\n", owner, path.c_str());
        if (hit) *hit = false;
        return build();
    }
    if (std::filesystem::exists(status)) {
        if (auto cached = load(&why)) {
            if (hit) *hit = true;
            return std::move(*cached);
        }
        std::fprintf(stderr, "%s: ignoring cache file %s (%s); recomputing\n", owner, path.c_str(), why.c_str());
    }
    if (hit) *hit = false;
    auto value = build();
    if (!path.empty() && !save(value, &why))
        std::fprintf(stderr, "%s: cannot write the cache (%s); continuing without it\n", owner, why.c_str());
    return value;
}

} // namespace shadowlab::diskcache
