#include "algorithms/shadow_volumes/EdgeAdjacency.h"

#include "framework/core/Error.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <unordered_map>

namespace shadowlab {
namespace {

// A corner's weld key: its rigid part (0 = static, k + 1 = moving part k) and its position's bits.
// Exact bits, not a distance: corners that are the same float stay the same under a part's pose
// (one transform of one input), and a near miss must stay two edges (a crack the volumes close).
struct CornerKey {
    uint32_t part, x, y, z;
    bool operator==(const CornerKey& o) const { return part == o.part && x == o.x && y == o.y && z == o.z; }
};
struct CornerHash {
    size_t operator()(const CornerKey& k) const {
        uint64_t h = 1469598103934665603ull;
        for (uint32_t w : {k.part, k.x, k.y, k.z}) h = (h ^ w) * 1099511628211ull;
        return size_t(h ^ (h >> 29));
    }
};

uint32_t bits(float f) {
    if (f == 0.0f) f = 0.0f; // -0 and +0 are one position
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

} // namespace

EdgeAdjacency buildEdgeAdjacency(const Scene& scene) {
    const size_t n = scene.triangleCount();
    if (n >= kMaxEdgeSideTriangles)
        throw RuntimeError("shadow_volumes' edge list names at most " + std::to_string(kMaxEdgeSideTriangles - 1) +
                                          " triangles; the scene has " + std::to_string(n));
    // Rigid part of every triangle.
    std::vector<uint32_t> part(n, 0);
    for (size_t k = 0; k < scene.moving.size(); ++k)
        for (size_t t = scene.moving[k].firstTriangle; t < scene.moving[k].firstTriangle + scene.moving[k].triangleCount; ++t)
            part[t] = uint32_t(k + 1);
    // Welded vertex id of every corner.
    std::unordered_map<CornerKey, uint32_t, CornerHash> ids;
    ids.reserve(n * 3 / 2 + 1);
    std::vector<uint32_t> corner(3 * n);
    for (size_t i = 0; i < 3 * n; ++i) {
        const glm::vec3& p = scene.positions[i];
        const CornerKey key{part[i / 3], bits(p.x), bits(p.y), bits(p.z)};
        corner[i] = ids.emplace(key, uint32_t(ids.size())).first->second;
    }
    // Every triangle's three edges, keyed by their two vertex ids (smaller first), then grouped.
    struct Walk {
        uint64_t key;
        uint32_t triangle, corner;
        bool down; ///< walks from the larger id to the smaller
    };
    std::vector<Walk> walks;
    walks.reserve(3 * n);
    for (size_t t = 0; t < n; ++t)
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t a = corner[3 * t + k], b = corner[3 * t + (k + 1) % 3];
            if (a == b) continue; // a zero-length edge bounds nothing
            const uint32_t lo = std::min(a, b), hi = std::max(a, b);
            walks.push_back({uint64_t(lo) << 32 | hi, uint32_t(t), k, a > b});
        }
    std::sort(walks.begin(), walks.end(), [](const Walk& x, const Walk& y) {
        return x.key != y.key ? x.key < y.key : x.triangle != y.triangle ? x.triangle < y.triangle : x.corner < y.corner;
    });
    EdgeAdjacency out;
    out.sides.reserve(walks.size());
    for (size_t i = 0; i < walks.size();) {
        size_t j = i;
        while (j < walks.size() && walks[j].key == walks[i].key) ++j;
        out.first.push_back(uint32_t(out.sides.size()));
        for (size_t s = i; s < j; ++s)
            out.sides.push_back(packEdgeSide({walks[s].triangle, walks[s].corner, walks[s].down != walks[i].down}));
        const size_t count = j - i;
        out.maxSides = std::max(out.maxSides, count);
        out.openEdges += count == 1;
        out.nonManifold += count >= 3;
        i = j;
    }
    out.first.push_back(uint32_t(out.sides.size()));
    return out;
}

} // namespace shadowlab
