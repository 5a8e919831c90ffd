#pragma once
// On-disk cache of built N-trees: the build of a big scene takes seconds to minutes and depends
// only on the scene's content and (N, d). One file per key, written atomically (temporary file +
// rename); a file that is short, foreign, of another version or whose checksum fails is reported
// and rebuilt, never trusted.
#include "algorithms/line_space/NTree.h"

#include <optional>
#include <string>

namespace shadowlab::ls {

/// Bumped whenever the build's output changes (layout, margins, tests): old files then miss.
constexpr uint32_t kCacheVersion = 2; ///< 2: the occupancy pool

/// $XDG_CACHE_HOME/shadowlab/line_space, else $HOME/.cache/shadowlab/line_space, else "" (no cache).
std::string cacheDirectory();
/// The file of key (scene content hash, n, d) in `dir`.
std::string cacheFile(const std::string& dir, uint64_t sceneHash, int n, int d);
/// Writes `tree` (creating `dir` as needed); false with the reason in `why` on failure.
bool saveCache(const std::string& path, uint64_t sceneHash, const NTree& tree, std::string* why);
/// Reads the tree of key (sceneHash, n, d); nothing (and the reason in `why`) when the file is
/// missing, of another key or version, truncated, or corrupt.
std::optional<NTree> loadCache(const std::string& path, uint64_t sceneHash, int n, int d, std::string* why);

} // namespace shadowlab::ls
