#include "algorithms/line_space/LineSpaceCache.h"

#include "framework/core/DiskCache.h"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace shadowlab::ls {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'S', 'L', 'N', 'T', 'R', 'E', 'E', '\0'};

/// Fixed-size file header, written as raw bytes (the cache is machine-local, like ~/.cache itself).
struct Header {
    char magic[8];
    uint32_t version, n, d, reserved;
    uint64_t sceneHash;
    uint64_t nodeCount, treeWords, bitWords, occupancyWords;
    uint64_t nodesPerLevel[kMaxDepth];
    float margin, pad;
    double buildMs;
    uint64_t payloadChecksum;
    uint64_t headerChecksum; ///< of every byte above
};

using diskcache::checksum;

uint64_t payloadChecksum(const NTree& t) {
    uint64_t h = checksum(t.nodes.data(), t.nodes.size() * sizeof(NodeGpu));
    h = checksum(t.tree.data(), t.tree.size() * sizeof(uint32_t), h);
    h = checksum(t.bits.data(), t.bits.size() * sizeof(uint32_t), h);
    return checksum(t.occupancy.data(), t.occupancy.size() * sizeof(uint32_t), h);
}

} // namespace

std::string cacheDirectory() { return diskcache::directory("line_space"); }

std::string cacheFile(const std::string& dir, uint64_t sceneHash, int n, int d) {
    char name[64];
    std::snprintf(name, sizeof name, "%016llx_n%d_d%d_v%u.bin", (unsigned long long)sceneHash, n, d, kCacheVersion);
    return dir + "/" + name;
}

bool saveCache(const std::string& path, uint64_t sceneHash, const NTree& t, std::string* why) {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kCacheVersion;
    h.n = uint32_t(t.n), h.d = uint32_t(t.d);
    h.sceneHash = sceneHash;
    h.nodeCount = t.nodes.size(), h.treeWords = t.tree.size(), h.bitWords = t.bits.size(), h.occupancyWords = t.occupancy.size();
    for (size_t l = 0; l < t.nodesPerLevel.size() && l < size_t(kMaxDepth); ++l) h.nodesPerLevel[l] = t.nodesPerLevel[l];
    h.margin = t.margin;
    h.buildMs = t.buildMs;
    h.payloadChecksum = payloadChecksum(t);
    h.headerChecksum = checksum(&h, offsetof(Header, headerChecksum));

    // A reader never sees half a file, and two processes building the same key at once each
    // replace the file whole.
    return diskcache::writeAtomically(path,
                                      {{&h, sizeof h},
                                       {t.nodes.data(), t.nodes.size() * sizeof(NodeGpu)},
                                       {t.tree.data(), t.tree.size() * sizeof(uint32_t)},
                                       {t.bits.data(), t.bits.size() * sizeof(uint32_t)},
                                       {t.occupancy.data(), t.occupancy.size() * sizeof(uint32_t)}},
                                      why);
}

std::optional<NTree> loadCache(const std::string& path, uint64_t sceneHash, int n, int d, std::string* why) {
    auto bad = [why](const std::string& reason) {
        if (why) *why = reason;
        return std::optional<NTree>{};
    };
    std::ifstream in(path, std::ios::binary);
    if (!in) return bad("no cache file " + path);
    Header h{};
    if (!in.read(reinterpret_cast<char*>(&h), sizeof h)) return bad("truncated header");
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) return bad("not an N-tree cache file");
    if (h.headerChecksum != checksum(&h, offsetof(Header, headerChecksum))) return bad("header checksum mismatch");
    if (h.version != kCacheVersion) return bad("cache version " + std::to_string(h.version));
    if (h.sceneHash != sceneHash || h.n != uint32_t(n) || h.d != uint32_t(d))
        return bad("the file is for another scene or (N, d)");
    if (h.bitWords != h.nodeCount * wordsPerNode(n) || h.occupancyWords != h.nodeCount * occupancyWords(n) ||
        h.treeWords % size_t(n * n * n) != 0)
        return bad("inconsistent pool sizes");
    const uint64_t expected = sizeof h + h.nodeCount * sizeof(NodeGpu) + (h.treeWords + h.bitWords + h.occupancyWords) * sizeof(uint32_t);
    std::error_code ec;
    if (fs::file_size(path, ec) != expected) return bad("file size differs from its header (truncated?)");

    NTree t;
    t.n = n, t.d = d;
    t.margin = h.margin;
    t.buildMs = h.buildMs;
    t.nodesPerLevel.assign(h.nodesPerLevel, h.nodesPerLevel + d);
    t.nodes.resize(h.nodeCount);
    t.tree.resize(h.treeWords);
    t.bits.resize(h.bitWords);
    t.occupancy.resize(h.occupancyWords);
    in.read(reinterpret_cast<char*>(t.nodes.data()), std::streamsize(t.nodes.size() * sizeof(NodeGpu)));
    in.read(reinterpret_cast<char*>(t.tree.data()), std::streamsize(t.tree.size() * sizeof(uint32_t)));
    in.read(reinterpret_cast<char*>(t.bits.data()), std::streamsize(t.bits.size() * sizeof(uint32_t)));
    in.read(reinterpret_cast<char*>(t.occupancy.data()), std::streamsize(t.occupancy.size() * sizeof(uint32_t)));
    if (!in) return bad("truncated pools");
    if (payloadChecksum(t) != h.payloadChecksum) return bad("pool checksum mismatch (corrupt file)");
    // Child references must stay inside the pools: a shader must never read out of bounds.
    for (const NodeGpu& node : t.nodes)
        if (node.children != LS_NO_CHILDREN && node.children + uint64_t(n * n * n) > t.tree.size())
            return bad("children group out of range");
    for (uint32_t c : t.tree)
        if (c != LS_EMPTY && c >= t.nodes.size()) return bad("child index out of range");
    return t;
}

} // namespace shadowlab::ls
