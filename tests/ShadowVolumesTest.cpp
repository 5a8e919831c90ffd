// shadow_volumes' edge adjacency on the CPU: welding, directions, open and non-manifold edges, and
// parts kept apart.
#include "algorithms/shadow_volumes/EdgeAdjacency.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

namespace shadowlab {
namespace {

Scene soup(const std::vector<glm::vec3>& corners) {
    Scene s;
    s.addTriangles(corners, Material{});
    return s;
}

// A closed tetrahedron, consistently wound: 6 edges, each walked once each way.
TEST(EdgeAdjacencyTest, ClosedMeshHasTwoOppositeSidesPerEdge) {
    const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0, 0, 1);
    const EdgeAdjacency adj = buildEdgeAdjacency(soup({a, c, b, a, b, d, a, d, c, b, c, d}));
    ASSERT_EQ(adj.edgeCount(), 6u);
    EXPECT_EQ(adj.sides.size(), 12u);
    EXPECT_EQ(adj.openEdges, 0u);
    EXPECT_EQ(adj.nonManifold, 0u);
    EXPECT_EQ(adj.maxSides, 2u);
    for (size_t e = 0; e < adj.edgeCount(); ++e) {
        ASSERT_EQ(adj.first[e + 1] - adj.first[e], 2u);
        EXPECT_FALSE(unpackEdgeSide(adj.sides[adj.first[e]]).reversed) << "the first side gives the direction";
        EXPECT_TRUE(unpackEdgeSide(adj.sides[adj.first[e] + 1]).reversed) << "a closed mesh walks each edge both ways";
    }
}

// One triangle: three open edges. Five triangles around one edge: that edge has five sides.
TEST(EdgeAdjacencyTest, OpenAndNonManifoldEdgesAreCounted) {
    EXPECT_EQ(buildEdgeAdjacency(soup({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})).openEdges, 3u);
    std::vector<glm::vec3> fins;
    for (int k = 0; k < 5; ++k) {
        const float angle = 1.2566371f * float(k);
        fins.insert(fins.end(), {{0, 0, 0}, {0, 1, 0}, {std::cos(angle), 0.5f, std::sin(angle)}});
    }
    const EdgeAdjacency adj = buildEdgeAdjacency(soup(fins));
    EXPECT_EQ(adj.edgeCount(), 11u); // the spine, and two open edges per fin
    EXPECT_EQ(adj.nonManifold, 1u);
    EXPECT_EQ(adj.maxSides, 5u);
    EXPECT_EQ(adj.openEdges, 10u);
}

// Equal positions weld within a part only: the same triangle in a moving part and in the static
// rest keeps its own edges (the part moves away from the rest, so a shared edge would not stay).
TEST(EdgeAdjacencyTest, WeldsWithinARigidPartOnly) {
    Scene s = soup({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 1, 0}, {1, 0, 0}});
    EXPECT_EQ(buildEdgeAdjacency(s).edgeCount(), 3u);
    MovingPart part;
    part.firstTriangle = 1;
    part.triangleCount = 1;
    s.moving.push_back(part);
    EXPECT_EQ(buildEdgeAdjacency(s).edgeCount(), 6u);
}

// Every side names a real triangle's edge, once: 3 sides per triangle in all.
TEST(EdgeAdjacencyTest, EverySideOfEveryTriangleOnce) {
    std::vector<glm::vec3> grid;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            const glm::vec3 p(float(i), 0, float(j));
            grid.insert(grid.end(), {p, p + glm::vec3(0, 0, 1), p + glm::vec3(1, 0, 0)});
            grid.insert(grid.end(), {p + glm::vec3(1, 0, 0), p + glm::vec3(0, 0, 1), p + glm::vec3(1, 0, 1)});
        }
    const Scene s = soup(grid);
    const EdgeAdjacency adj = buildEdgeAdjacency(s);
    ASSERT_EQ(adj.sides.size(), 3 * s.triangleCount());
    std::set<std::pair<uint32_t, uint32_t>> seen;
    for (uint32_t w : adj.sides) {
        const EdgeSide side = unpackEdgeSide(w);
        ASSERT_LT(side.triangle, s.triangleCount());
        EXPECT_TRUE(seen.insert({side.triangle, side.corner}).second);
    }
    EXPECT_EQ(adj.edgeCount(), 16u * 3u + 8u); // 3 per cell, plus the far border of the 4 × 4 grid
    EXPECT_EQ(adj.openEdges, 16u);
}

} // namespace
} // namespace shadowlab
