#pragma once
// On-disk cache of the clustering: it depends only on the scene's content and the clustering
// options, and takes seconds to minutes on big scenes. One file per key, written atomically
// (temporary file + rename); a short, foreign, stale or corrupt file is reported and rebuilt.
#include "algorithms/metric_tree/Clustering.h"

#include <optional>
#include <string>

namespace shadowlab::mt {

/// Bumped whenever the clustering's output changes: old files then miss.
constexpr uint32_t kCacheVersion = 2; ///< 2: chunk size and k-means iterations in the key

/// $XDG_CACHE_HOME/shadowlab/metric_tree, else $HOME/.cache/shadowlab/metric_tree, else "" (no cache).
std::string cacheDirectory();
/// The file of key (scene hash, options) in `dir`.
std::string cacheFile(const std::string& dir, uint64_t sceneHash, const ClusteringOptions& o);
/// Writes `c` (creating `dir` as needed); false with the reason in `why` on failure.
bool saveCache(const std::string& path, uint64_t sceneHash, const ClusteringOptions& o, size_t triangles,
               const Clustering& c, std::string* why);
/// The clustering of that key, or nothing (and the reason in `why`). Beyond the header's key and
/// checksums, which anyone can rewrite, the clusters are checked against `scene` itself: `order` is a
/// permutation of its triangles, and every cluster's sphere or capsule, normal cone and slabs enclose
/// its triangles. A file built from other content fails this, whatever its header says.
std::optional<Clustering> loadCache(const std::string& path, uint64_t sceneHash, const ClusteringOptions& o,
                                    const Scene& scene, std::string* why);

} // namespace shadowlab::mt
