#pragma once
// What the per-scene disk caches of the algorithms share (line_space's N-tree, metric_tree's
// clustering): where they live, how a file is checksummed, and how it is written so that a reader
// never sees half of it. Each cache keeps its own header and validation.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>

namespace shadowlab::diskcache {

/// $XDG_CACHE_HOME/shadowlab/<name>, else ~/.cache/shadowlab/<name>; "" when neither is set.
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

} // namespace shadowlab::diskcache
