#include "algorithms/metric_tree/ClusterCache.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace shadowlab::mt {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'S', 'L', 'M', 'T', 'C', 'L', 'U', '\0'};

/// Fixed-size header, raw bytes (the cache is machine-local, like ~/.cache itself).
struct Header {
    char magic[8];
    uint32_t version, clusterSize, capsules, randomOrder, seed, reserved;
    uint64_t sceneHash, triangles, clusters, capsuleCount;
    uint64_t payloadChecksum;
    uint64_t headerChecksum; ///< of every byte above
};

uint64_t checksum(const void* data, size_t bytes, uint64_t h = 1469598103934665603ull) {
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

uint64_t payloadChecksum(const Clustering& c) {
    return checksum(c.order.data(), c.order.size() * sizeof(uint32_t),
                    checksum(c.clusters.data(), c.clusters.size() * sizeof(ClusterGpu)));
}

bool fail(std::string* why, const std::string& reason) {
    if (why) *why = reason;
    return false;
}

} // namespace

std::string cacheDirectory() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/shadowlab/metric_tree";
    if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/shadowlab/metric_tree";
    return "";
}

std::string cacheFile(const std::string& dir, uint64_t sceneHash, const ClusteringOptions& o) {
    char name[96];
    std::snprintf(name, sizeof name, "%016llx_s%d_c%d_r%d_%u_v%u.bin", (unsigned long long)sceneHash, o.clusterSize,
                  int(o.capsules), int(o.randomOrder), o.seed, kCacheVersion);
    return dir + "/" + name;
}

bool saveCache(const std::string& path, uint64_t sceneHash, const ClusteringOptions& o, size_t triangles,
               const Clustering& c, std::string* why) {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kCacheVersion;
    h.clusterSize = uint32_t(o.clusterSize), h.capsules = o.capsules, h.randomOrder = o.randomOrder, h.seed = o.seed;
    h.sceneHash = sceneHash, h.triangles = triangles, h.clusters = c.clusters.size(), h.capsuleCount = c.capsules;
    h.payloadChecksum = payloadChecksum(c);
    h.headerChecksum = checksum(&h, offsetof(Header, headerChecksum));
    std::error_code ec;
    fs::create_directories(fs::path(path).parent_path(), ec);
    // Written beside the target and renamed over it: a reader never sees half a file.
    const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return fail(why, "cannot create " + tmp);
        out.write(reinterpret_cast<const char*>(&h), sizeof h);
        out.write(reinterpret_cast<const char*>(c.clusters.data()), std::streamsize(c.clusters.size() * sizeof(ClusterGpu)));
        out.write(reinterpret_cast<const char*>(c.order.data()), std::streamsize(c.order.size() * sizeof(uint32_t)));
        if (!out) {
            fs::remove(tmp, ec);
            return fail(why, "cannot write " + tmp);
        }
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        return fail(why, "cannot rename " + tmp + " to " + path);
    }
    return true;
}

std::optional<Clustering> loadCache(const std::string& path, uint64_t sceneHash, const ClusteringOptions& o,
                                    size_t triangles, std::string* why) {
    auto bad = [why](const std::string& reason) {
        fail(why, reason);
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
        h.capsules != uint32_t(o.capsules) || h.randomOrder != uint32_t(o.randomOrder) || h.seed != o.seed)
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
    for (uint32_t t : c.order)
        if (t >= triangles) return bad("triangle index out of range");
    return c;
}

} // namespace shadowlab::mt
