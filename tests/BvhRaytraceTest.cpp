// bvh_raytrace's CPU side without GL: the binned-SAH builder's tree is a valid BVH (every triangle in
// exactly one leaf, every box enclosing its subtree, leaves within the size limit) on ordinary and
// degenerate inputs, deterministic, and the SSBO-limit check reports what does not fit.
#include "framework/accel/BvhBuilder.h"
#include "framework/core/Error.h"
#include "framework/scene/Procedural.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cstring>
#include <functional>

namespace shadowlab {
namespace {

using bvh::NodeGpu;

bool contains(const float* lo, const float* hi, glm::vec3 p) {
    for (int a = 0; a < 3; ++a)
        if (p[a] < lo[a] || p[a] > hi[a]) return false;
    return true;
}

/// Walks the tree: every leaf triangle lies in the boxes on its path; returns leaf triangles seen.
void checkTree(const Scene& s, const bvh::Bvh& t, int maxLeaf) {
    std::vector<int> seen(s.triangleCount(), 0);
    int maxDepth = 0;
    std::function<void(uint32_t, int, std::vector<std::pair<const float*, const float*>>&)> walk =
        [&](uint32_t node, int depth, std::vector<std::pair<const float*, const float*>>& boxes) {
            ASSERT_LT(node, t.nodes.size());
            maxDepth = std::max(maxDepth, depth);
            const NodeGpu& n = t.nodes[node];
            for (int k = 0; k < 2; ++k) {
                const uint32_t child = k == 0 ? n.child0 : n.child1, count = k == 0 ? n.count0 : n.count1;
                const float* lo = k == 0 ? n.lo0 : n.lo1;
                const float* hi = k == 0 ? n.hi0 : n.hi1;
                if (child == BVH_ABSENT) {
                    EXPECT_EQ(node, 0u) << "only the root of a one-leaf tree has an absent child";
                    continue;
                }
                boxes.push_back({lo, hi});
                if (count > 0) {
                    EXPECT_LE(count, uint32_t(maxLeaf));
                    ASSERT_LE(size_t(child) + count, t.triIndices.size());
                    for (uint32_t i = child; i < child + count; ++i) {
                        const uint32_t tri = t.triIndices[i];
                        ++seen[tri];
                        for (auto [blo, bhi] : boxes)
                            for (int v = 0; v < 3; ++v) EXPECT_TRUE(contains(blo, bhi, s.positions[3 * tri + v]));
                    }
                } else {
                    EXPECT_GT(child, node) << "children are created after their parent";
                    walk(child, depth + 1, boxes);
                }
                boxes.pop_back();
            }
        };
    std::vector<std::pair<const float*, const float*>> boxes;
    if (!t.nodes.empty()) walk(0, 1, boxes);
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "triangle " << i;
    EXPECT_EQ(maxDepth, t.depth);
}

Scene objects() {
    Scene s = makePlane({8, 8}, 4, Material{});
    s.append(makeSphere(0.6f, 2000, Material{}), glm::translate(glm::mat4(1.0f), {-0.8f, 0.8f, 0}));
    s.append(makeTorus(0.5f, 0.15f, 1500, Material{}), glm::translate(glm::mat4(1.0f), {0.9f, 0.6f, 0.3f}));
    return s;
}

TEST(BvhRaytraceTest, TreeIsAValidBvh) {
    Scene s = objects();
    for (int leaf : {1, 4, 16}) {
        bvh::BuildOptions o;
        o.maxLeafSize = leaf;
        bvh::Bvh t = bvh::buildBvh(s, o);
        checkTree(s, t, leaf);
        EXPECT_EQ(t.nodes.size() + 1, t.leaves) << "a binary tree has one inner node fewer than leaves";
        EXPECT_GE(t.leaves * size_t(leaf), s.triangleCount());
        // SAH quality: far shallower than a list, and a cost well below testing every triangle.
        EXPECT_LT(t.depth, 40);
        EXPECT_LT(t.sahCost, 0.02 * double(s.triangleCount()));
    }
}

// The shader reads a leaf's triangles contiguously: triangle i of the leaf order is the scene's
// triangle triIndices[i], vertex for vertex.
TEST(BvhRaytraceTest, TrianglesAreInLeafOrder) {
    Scene s = objects();
    bvh::Bvh t = bvh::buildBvh(s);
    ASSERT_EQ(t.triangles.size(), 3 * s.triangleCount());
    for (size_t i = 0; i < t.triIndices.size(); ++i)
        for (size_t k = 0; k < 3; ++k)
            ASSERT_EQ(glm::vec3(t.triangles[3 * i + k]), s.positions[3 * size_t(t.triIndices[i]) + k]) << "triangle " << i;
}

// Moving parts: the tree keeps its shape, and after a refit every box again holds its triangles
// (checkTree walks every path) and the leaf-ordered copy is the moved scene's.
TEST(BvhRaytraceTest, RefitHoldsTheMovedTriangles) {
    Scene s = objects();
    bvh::Bvh t = bvh::buildBvh(s);
    const size_t nodes = t.nodes.size();
    Scene moved = s;
    const glm::mat4 m = glm::rotate(glm::translate(glm::mat4(1.0f), {2.5f, 1.0f, -1.0f}), 1.2f, glm::vec3(0, 1, 0));
    for (size_t i = 3 * 2 * 4 * 4; i < moved.positions.size(); ++i)  // everything but the ground (2·4² triangles) moves
        moved.positions[i] = glm::vec3(m * glm::vec4(moved.positions[i], 1.0f));
    bvh::refitBvh(t, moved.positions);
    EXPECT_EQ(t.nodes.size(), nodes);
    checkTree(moved, t, 4);
    for (size_t i = 0; i < t.triIndices.size(); ++i)
        ASSERT_EQ(glm::vec3(t.triangles[3 * i]), moved.positions[3 * size_t(t.triIndices[i])]) << "triangle " << i;
}

TEST(BvhRaytraceTest, DegenerateInputs) {
    // Nothing, one triangle, and 50 copies of one triangle (identical centroids: split by count).
    Scene empty;
    bvh::Bvh t0 = bvh::buildBvh(empty);
    ASSERT_EQ(t0.nodes.size(), 1u);
    EXPECT_EQ(t0.nodes[0].child0, BVH_ABSENT);
    EXPECT_EQ(t0.nodes[0].child1, BVH_ABSENT);

    Scene one;
    one.addTriangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, Material{});
    bvh::Bvh t1 = bvh::buildBvh(one);
    checkTree(one, t1, 4);
    EXPECT_EQ(t1.nodes[0].count0, 1u);
    EXPECT_EQ(t1.nodes[0].child1, BVH_ABSENT);

    Scene same;
    for (int i = 0; i < 50; ++i) same.addTriangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, Material{});
    bvh::Bvh t2 = bvh::buildBvh(same);
    checkTree(same, t2, 4);
}

TEST(BvhRaytraceTest, BuildIsDeterministic) {
    Scene s = objects();
    bvh::Bvh a = bvh::buildBvh(s), b = bvh::buildBvh(s);
    EXPECT_EQ(a.triIndices, b.triIndices);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(NodeGpu)));
}

TEST(BvhRaytraceTest, StorageLimitIsReported) {
    EXPECT_NO_THROW(bvh::checkStorageBlock("the BVH nodes", 128u << 20, 128u << 20));
    try {
        bvh::checkStorageBlock("the BVH nodes", (128u << 20) + 1, 128u << 20);
        ADD_FAILURE() << "one byte over the limit must be refused";
    } catch (const RuntimeError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("bvh_raytrace"), std::string::npos) << what;
        EXPECT_NE(what.find("the BVH nodes"), std::string::npos) << what;
        EXPECT_NE(what.find("GL_MAX_SHADER_STORAGE_BLOCK_SIZE"), std::string::npos) << what;
    }
}

} // namespace
} // namespace shadowlab
