#include "framework/accel/BvhBuilder.h"

#include <algorithm>
#include <array>
#include <limits>

namespace shadowlab::bvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct Box {
    glm::vec3 lo{kInf}, hi{-kInf};
    void extend(glm::vec3 p) { lo = glm::min(lo, p), hi = glm::max(hi, p); }
    void extend(const Box& b) { lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi); }
    bool empty() const { return lo.x > hi.x; }
    float halfArea() const {
        if (empty()) return 0.0f;
        glm::vec3 e = hi - lo;
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
};

struct Bin {
    Box box;
    uint32_t count = 0;
};

/// A range of triIndices still to be split, and where its node goes.
struct Task {
    uint32_t begin, end, node;
    int depth;
};

class Builder {
public:
    Builder(const Scene& scene, const BuildOptions& o) : opt_(o) {
        const size_t n = scene.triangleCount();
        triBox_.resize(n);
        centroid_.resize(n);
        for (size_t t = 0; t < n; ++t) {
            for (int k = 0; k < 3; ++k) triBox_[t].extend(scene.positions[3 * t + size_t(k)]);
            centroid_[t] = 0.5f * (triBox_[t].lo + triBox_[t].hi);
        }
        bvh_.triIndices.resize(n);
        for (uint32_t t = 0; t < uint32_t(n); ++t) bvh_.triIndices[t] = t;
    }

    Bvh run(const Scene& scene) {
        Bvh out = build();
        out.triangles.resize(3 * out.triIndices.size());
        for (size_t i = 0; i < out.triIndices.size(); ++i)
            for (size_t k = 0; k < 3; ++k) out.triangles[3 * i + k] = glm::vec4(scene.positions[3 * size_t(out.triIndices[i]) + k], 0.0f);
        return out;
    }

private:
    Bvh build() {
        const uint32_t n = uint32_t(bvh_.triIndices.size());
        bvh_.nodes.push_back(emptyNode());
        Box all = rangeBox(0, n);
        rootArea_ = std::max(all.halfArea(), 1e-30f);
        if (n <= uint32_t(opt_.maxLeafSize)) { // one leaf (or none): child 1 stays absent
            if (n > 0) setChild(0, 0, all, 0, n);
            bvh_.depth = 1;
            bvh_.leaves = n > 0 ? 1 : 0;
            bvh_.sahCost = opt_.traversalCost + n;
            return std::move(bvh_);
        }
        sah_ = opt_.traversalCost; // the root is always entered
        std::vector<Task> work{{0, n, 0, 1}};
        while (!work.empty()) {
            Task t = work.back();
            work.pop_back();
            bvh_.depth = std::max(bvh_.depth, t.depth);
            uint32_t mid = split(t.begin, t.end);
            const uint32_t range[2][2] = {{t.begin, mid}, {mid, t.end}};
            for (int k = 0; k < 2; ++k) {
                uint32_t b = range[k][0], e = range[k][1];
                Box box = rangeBox(b, e);
                if (e - b <= uint32_t(opt_.maxLeafSize)) {
                    setChild(t.node, k, box, b, e - b);
                    ++bvh_.leaves;
                    sah_ += double(box.halfArea()) / rootArea_ * double(e - b);
                } else {
                    uint32_t child = uint32_t(bvh_.nodes.size());
                    bvh_.nodes.push_back(emptyNode());
                    setChild(t.node, k, box, child, 0);
                    sah_ += double(box.halfArea()) / rootArea_ * opt_.traversalCost;
                    work.push_back({b, e, child, t.depth + 1});
                }
            }
        }
        bvh_.sahCost = sah_;
        return std::move(bvh_);
    }

    static NodeGpu emptyNode() {
        NodeGpu n{};
        for (int a = 0; a < 3; ++a) n.lo0[a] = n.lo1[a] = kInf, n.hi0[a] = n.hi1[a] = -kInf;
        n.child0 = n.child1 = BVH_ABSENT; // overwritten by setChild() for every child that exists
        return n;
    }

    void setChild(uint32_t node, int k, const Box& box, uint32_t child, uint32_t count) {
        NodeGpu& n = bvh_.nodes[node];
        float* lo = k == 0 ? n.lo0 : n.lo1;
        float* hi = k == 0 ? n.hi0 : n.hi1;
        for (int a = 0; a < 3; ++a) lo[a] = box.lo[a], hi[a] = box.hi[a];
        (k == 0 ? n.child0 : n.child1) = child;
        (k == 0 ? n.count0 : n.count1) = count;
    }

    Box rangeBox(uint32_t b, uint32_t e) const {
        Box box;
        for (uint32_t i = b; i < e; ++i) box.extend(triBox_[bvh_.triIndices[i]]);
        return box;
    }

    Box centroidBox(uint32_t b, uint32_t e) const {
        Box box;
        for (uint32_t i = b; i < e; ++i) box.extend(centroid_[bvh_.triIndices[i]]);
        return box;
    }

    /// Partitions [b, e) by the best binned-SAH plane over the three axes; returns the split point,
    /// strictly inside the range (ranges whose centroids all coincide are halved by count).
    uint32_t split(uint32_t b, uint32_t e) {
        const Box cb = centroidBox(b, e);
        const int nb = opt_.bins;
        float bestCost = kInf;
        int bestAxis = -1, bestBin = 0;
        const size_t binCount = size_t(nb);
        std::vector<Bin> bins(binCount);
        std::vector<float> rightArea(binCount);
        std::vector<uint32_t> rightCount(binCount);
        for (int axis = 0; axis < 3; ++axis) {
            const float extent = cb.hi[axis] - cb.lo[axis];
            if (!(extent > 0.0f)) continue;
            const float scale = float(nb) / extent;
            std::fill(bins.begin(), bins.end(), Bin{});
            for (uint32_t i = b; i < e; ++i) {
                uint32_t t = bvh_.triIndices[i];
                int bin = std::min(nb - 1, int((centroid_[t][axis] - cb.lo[axis]) * scale));
                bins[size_t(bin)].box.extend(triBox_[t]);
                ++bins[size_t(bin)].count;
            }
            // Sweep from the right, then from the left: cost of a plane after bin j.
            Box acc;
            uint32_t cnt = 0;
            for (int j = nb - 1; j > 0; --j) {
                acc.extend(bins[size_t(j)].box);
                cnt += bins[size_t(j)].count;
                rightArea[size_t(j)] = acc.halfArea();
                rightCount[size_t(j)] = cnt;
            }
            acc = Box{};
            cnt = 0;
            for (int j = 0; j < nb - 1; ++j) {
                acc.extend(bins[size_t(j)].box);
                cnt += bins[size_t(j)].count;
                if (cnt == 0 || rightCount[size_t(j + 1)] == 0) continue;
                float cost = acc.halfArea() * float(cnt) + rightArea[size_t(j + 1)] * float(rightCount[size_t(j + 1)]);
                if (cost < bestCost) bestCost = cost, bestAxis = axis, bestBin = j;
            }
        }
        if (bestAxis < 0) return b + (e - b) / 2; // every centroid coincides: split by count
        const float scale = float(nb) / (cb.hi[bestAxis] - cb.lo[bestAxis]);
        auto* first = bvh_.triIndices.data() + b;
        auto* mid = std::partition(first, bvh_.triIndices.data() + e, [&](uint32_t t) {
            return std::min(nb - 1, int((centroid_[t][bestAxis] - cb.lo[bestAxis]) * scale)) <= bestBin;
        });
        return uint32_t(mid - bvh_.triIndices.data());
    }

    BuildOptions opt_;
    std::vector<Box> triBox_;
    std::vector<glm::vec3> centroid_;
    Bvh bvh_;
    float rootArea_ = 1.0f;
    double sah_ = 0;
};

} // namespace

Bvh buildBvh(const Scene& scene, const BuildOptions& options) { return Builder(scene, options).run(scene); }

void refitBvh(Bvh& tree, const std::vector<glm::vec3>& positions) {
    for (size_t i = 0; i < tree.triIndices.size(); ++i)
        for (size_t k = 0; k < 3; ++k) tree.triangles[3 * i + k] = glm::vec4(positions[3 * size_t(tree.triIndices[i]) + k], 0.0f);
    // Children are always stored after their parent (build() appends them), so one pass from the
    // last node to the root sees every child's boxes final before its parent reads them.
    for (size_t n = tree.nodes.size(); n-- > 0;) {
        NodeGpu& node = tree.nodes[n];
        for (int k = 0; k < 2; ++k) {
            const uint32_t child = k == 0 ? node.child0 : node.child1;
            const uint32_t count = k == 0 ? node.count0 : node.count1;
            if (child == BVH_ABSENT) continue;
            glm::vec3 lo(kInf), hi(-kInf);
            if (count > 0) {
                for (size_t i = 3 * size_t(child); i < 3 * size_t(child + count); ++i) {
                    lo = glm::min(lo, glm::vec3(tree.triangles[i]));
                    hi = glm::max(hi, glm::vec3(tree.triangles[i]));
                }
            } else {
                const NodeGpu& c = tree.nodes[child];
                lo = glm::min(glm::min(glm::vec3(c.lo0[0], c.lo0[1], c.lo0[2]), glm::vec3(c.lo1[0], c.lo1[1], c.lo1[2])), lo);
                hi = glm::max(glm::max(glm::vec3(c.hi0[0], c.hi0[1], c.hi0[2]), glm::vec3(c.hi1[0], c.hi1[1], c.hi1[2])), hi);
            }
            float* l = k == 0 ? node.lo0 : node.lo1;
            float* h = k == 0 ? node.hi0 : node.hi1;
            for (int a = 0; a < 3; ++a) l[a] = lo[a], h[a] = hi[a];
        }
    }
}

} // namespace shadowlab::bvh
