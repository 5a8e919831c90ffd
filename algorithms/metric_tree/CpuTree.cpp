#include "algorithms/metric_tree/CpuTree.h"

#include "algorithms/metric_tree/MetricTreeMath.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace shadowlab::mt {
namespace {

float bitsToFloat(uint32_t b) { float f; std::memcpy(&f, &b, 4); return f; }
uint32_t floatToBits(float f) { uint32_t b; std::memcpy(&b, &f, 4); return b; }

struct Builder {
    std::vector<NodeGpu>& nodes;
    const CpuTreeOptions& o;

    glm::vec3 a(uint32_t i) const { return {nodes[i].a[0], nodes[i].a[1], nodes[i].a[2]}; }
    glm::vec3 b(uint32_t i) const { return {nodes[i].b[0], nodes[i].b[1], nodes[i].b[2]}; }
    float centreDist(uint32_t i, uint32_t j) const { return minDist(o.directional, a(i), b(i), a(j), b(j)); }

    /// Yianilos: among a few candidates, the pivot whose distances to a sample spread the most
    /// (second moment about their median), which splits the set into the most distinct shells.
    uint32_t choosePivot(const std::vector<uint32_t>& ids) const {
        if (ids.size() <= 2) return 0;
        const size_t candidates = std::min<size_t>(8, ids.size()), samples = std::min<size_t>(32, ids.size());
        size_t best = 0;
        double bestSpread = -1;
        std::vector<float> d;
        for (size_t c = 0; c < candidates; ++c) {
            const size_t ci = c * ids.size() / candidates;
            d.clear();
            for (size_t s = 0; s < samples; ++s) d.push_back(centreDist(ids[ci], ids[(s * ids.size()) / samples]));
            std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
            const double median = d[d.size() / 2];
            double spread = 0;
            for (float x : d) spread += (x - median) * (x - median);
            if (spread > bestSpread) bestSpread = spread, best = ci;
        }
        return uint32_t(best);
    }

    /// Builds the subtree of `ids`; returns its root + 1 (0 when empty).
    uint32_t build(std::vector<uint32_t> ids) {
        if (ids.empty()) return MT_NO_CHILD;
        std::swap(ids[0], ids[choosePivot(ids)]);
        const uint32_t p = ids[0];
        NodeGpu& pivot = nodes[p];
        std::vector<float> d;
        for (size_t k = 1; k < ids.size(); ++k) d.push_back(centreDist(p, ids[k]));
        float delta = 0;
        if (!d.empty()) {
            std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
            delta = d[d.size() / 2]; // median partitioning (Uhlmann)
        }
        std::vector<uint32_t> part[3];
        float oMin = std::numeric_limits<float>::infinity(), oMax = 0;
        for (size_t k = 1; k < ids.size(); ++k) {
            const uint32_t e = ids[k];
            const float alpha = nodes[e].a[3];
            // The same bounds, with the same margin, as insert.comp.
            const float dMin = minDist(o.directional, a(p), b(p), a(e), b(e)) - alpha - o.lsEps;
            const float dMax = alpha >= kPi ? std::numeric_limits<float>::infinity()
                                            : maxDist(o.directional, a(p), b(p), a(e), b(e)) + alpha + o.lsEps;
            if (dMax <= delta) {
                part[MT_CHILD_NEAR].push_back(e);
            } else if (dMin > delta) {
                part[MT_CHILD_FAR].push_back(e);
            } else {
                part[MT_CHILD_OVERLAP].push_back(e);
                oMin = std::min(oMin, std::max(dMin, 0.0f));
                oMax = std::max(oMax, dMax);
            }
        }
        pivot.b[3] = delta;
        if (o.overlapInterval) pivot.overlapMin = floatToBits(oMin), pivot.overlapMax = floatToBits(oMax);
        float minD = bitsToFloat(pivot.minDist);
        for (int c = 0; c < 3; ++c) {
            const uint32_t child = build(std::move(part[c]));
            nodes[p].child[c] = child;
            if (child != MT_NO_CHILD) minD = std::min(minD, bitsToFloat(nodes[child - 1].minDist));
        }
        if (o.depthSkip) nodes[p].minDist = floatToBits(minD);
        return p + 1;
    }
};

// MT_CHILD_* are GLSL #defines of tree.glsl; the same three slots here.
static_assert(MT_NO_CHILD == 0u);

} // namespace

uint32_t buildCpuTree(std::vector<NodeGpu>& nodes, const CpuTreeOptions& options) {
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < nodes.size(); ++i)
        if (!(nodes[i].flags & MT_NODE_CULLED)) ids.push_back(i);
    Builder b{nodes, options};
    return b.build(std::move(ids));
}

} // namespace shadowlab::mt
