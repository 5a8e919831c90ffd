#include "algorithms/metric_tree/ClusterCache.h"

#include "framework/core/DiskCache.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace shadowlab::mt {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'S', 'L', 'M', 'T', 'C', 'L', 'U', '\0'};

/// Fixed-size header, raw bytes (the cache is machine-local, like ~/.cache itself).
struct Header {
    char magic[8];
    uint32_t version, clusterSize, capsules, randomOrder, seed, chunkTriangles, kmeansIterations, reserved;
    uint64_t sceneHash, triangles, clusters, capsuleCount;
    uint64_t payloadChecksum;
    uint64_t headerChecksum; ///< of every byte above
};

using diskcache::checksum;

uint64_t payloadChecksum(const Clustering& c) {
    return checksum(c.order.data(), c.order.size() * sizeof(uint32_t),
                    checksum(c.clusters.data(), c.clusters.size() * sizeof(ClusterGpu)));
}

/// Whether each cluster encloses its triangles as the shaders assume; the reason when not.
/// Tolerances are those of the float rounding the clustering itself allows for.
const char* boundsWrong(const Clustering& c, const Scene& scene) {
    const float extent = std::max(1.0f, glm::length(scene.bounds.extent()));
    const float tol = 1e-4f * extent;
    for (const ClusterGpu& cl : c.clusters) {
        const glm::vec3 a(cl.a[0], cl.a[1], cl.a[2]), b(cl.b[0], cl.b[1], cl.b[2]), axis(cl.axis[0], cl.axis[1], cl.axis[2]);
        const glm::vec3 ab = b - a;
        const float l2 = glm::dot(ab, ab);
        for (uint32_t k = cl.first; k < cl.first + cl.count; ++k) {
            const uint32_t t = c.order[k];
            if (cl.b[3] > -1.0f && glm::dot(axis, scene.normals[t]) < cl.b[3] - 1e-3f) return "a normal lies outside its cone";
            for (int v = 0; v < 3; ++v) {
                const glm::vec3 p = scene.positions[3 * size_t(t) + size_t(v)];
                const float s = l2 > 0 ? std::clamp(glm::dot(p - a, ab) / l2, 0.0f, 1.0f) : 0.0f;
                if (glm::length(p - (a + s * ab)) > cl.a[3] + tol) return "a vertex lies outside its cluster's bounds";
                const float d = glm::dot(axis, p);
                if (d < cl.axis[3] - tol || d > cl.slabMax + tol) return "a vertex lies outside its cluster's slabs";
            }
        }
    }
    return nullptr;
}

} // namespace

std::string cacheDirectory() { return diskcache::directory("metric_tree"); }

std::string cacheFile(const std::string& dir, uint64_t sceneHash, const ClusteringOptions& o) {
    char name[96];
    std::snprintf(name, sizeof name, "%016llx_s%d_c%d_r%d_%u_k%d_i%d_v%u.bin", (unsigned long long)sceneHash,
                  o.clusterSize, int(o.capsules), int(o.randomOrder), o.seed, o.chunkTriangles, o.kmeansIterations,
                  kCacheVersion);
    return dir + "/" + name;
}

bool saveCache(const std::string& path, uint64_t sceneHash, const ClusteringOptions& o, size_t triangles,
               const Clustering& c, std::string* why) {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kCacheVersion;
    h.clusterSize = uint32_t(o.clusterSize), h.capsules = o.capsules, h.randomOrder = o.randomOrder, h.seed = o.seed;
    h.chunkTriangles = uint32_t(o.chunkTriangles), h.kmeansIterations = uint32_t(o.kmeansIterations);
    h.sceneHash = sceneHash, h.triangles = triangles, h.clusters = c.clusters.size(), h.capsuleCount = c.capsules;
    h.payloadChecksum = payloadChecksum(c);
    h.headerChecksum = checksum(&h, offsetof(Header, headerChecksum));
    // A reader never sees half a file.
    return diskcache::writeAtomically(path,
                                      {{&h, sizeof h},
                                       {c.clusters.data(), c.clusters.size() * sizeof(ClusterGpu)},
                                       {c.order.data(), c.order.size() * sizeof(uint32_t)}},
                                      why);
}

std::optional<Clustering> loadCache(const std::string& path, uint64_t sceneHash, const ClusteringOptions& o,
                                    const Scene& scene, std::string* why) {
    const size_t triangles = scene.triangleCount();
    auto bad = [why](const std::string& reason) {
        if (why) *why = reason;
        return std::optional<Clustering>{};
    };
    std::ifstream in(path, std::ios::binary);
    if (!in) return bad("no cache file " + path);
    Header h{};
    if (!in.read(reinterpret_cast<char*>(&h), sizeof h)) return bad("truncated header");
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) return bad("not a metric_tree cluster cache file");
    if (h.headerChecksum != checksum(&h, offsetof(Header, headerChecksum))) return bad("header checksum mismatch");
    if (h.version != kCacheVersion) return bad("cache version " + std::to_string(h.version));
    if (h.sceneHash != sceneHash || h.triangles != triangles || h.clusterSize != uint32_t(o.clusterSize) ||
        h.capsules != uint32_t(o.capsules) || h.randomOrder != uint32_t(o.randomOrder) || h.seed != o.seed ||
        h.chunkTriangles != uint32_t(o.chunkTriangles) || h.kmeansIterations != uint32_t(o.kmeansIterations))
        return bad("the file is for another scene or other clustering options");
    std::error_code ec;
    if (fs::file_size(path, ec) != sizeof h + h.clusters * sizeof(ClusterGpu) + h.triangles * sizeof(uint32_t))
        return bad("file size differs from its header (truncated?)");
    Clustering c;
    c.clusters.resize(h.clusters);
    c.order.resize(h.triangles);
    c.capsules = h.capsuleCount;
    in.read(reinterpret_cast<char*>(c.clusters.data()), std::streamsize(c.clusters.size() * sizeof(ClusterGpu)));
    in.read(reinterpret_cast<char*>(c.order.data()), std::streamsize(c.order.size() * sizeof(uint32_t)));
    if (!in) return bad("truncated payload");
    if (payloadChecksum(c) != h.payloadChecksum) return bad("payload checksum mismatch (corrupt file)");
    // Everything a shader indexes with must stay in range.
    for (const ClusterGpu& cl : c.clusters)
        if (uint64_t(cl.first) + cl.count > triangles) return bad("cluster triangles out of range");
    std::vector<bool> seen(triangles, false);
    for (uint32_t t : c.order) {
        if (t >= triangles) return bad("triangle index out of range");
        if (seen[t]) return bad("a triangle is listed twice");
        seen[t] = true;
    }
    // And every place of `order` in exactly one cluster (fifteenth probe: clusters whose counts were
    // set to 0, checksums recomputed, left every triangle out, and their shadows with them, uncounted).
    std::vector<bool> covered(triangles, false);
    for (const ClusterGpu& cl : c.clusters)
        for (uint64_t k = cl.first; k < uint64_t(cl.first) + cl.count; ++k) {
            if (covered[k]) return bad("two clusters hold one triangle");
            covered[k] = true;
        }
    if (std::find(covered.begin(), covered.end(), false) != covered.end()) return bad("a triangle is in no cluster");
    if (const char* wrong = boundsWrong(c, scene)) return bad(std::string(wrong) + ": the file was built from other content");
    return c;
}

} // namespace shadowlab::mt
