// line_space without GL: the exact overlap tests against brute-force sampling, the N-tree's pools
// (structure, sizes, determinism), the conservativeness of every stored line-space bit against
// random segments through real triangles, and the disk cache (round trip, corruption, keys).
#include "algorithms/line_space/LineSpaceCache.h"
#include "algorithms/line_space/NTree.h"
#include "algorithms/line_space/ShaftFill.h"
#include "framework/core/Error.h"
#include "framework/scene/GltfLoader.h"
#include "framework/scene/Procedural.h"
#include "tests/ShadowTestScenes.h"
#include "tests/TestSupport.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace shadowlab {
namespace {

using ls::DBox;

using test::translate;

/// A small scene of closed objects on a plane (≈ 1,700 triangles).
Scene smallScene() {
    Scene s = makePlane({8, 8}, 4, Material{});
    s.append(makeSphere(0.6f, 800, Material{}), translate({-0.8f, 0.8f, 0}));
    s.append(makeTorus(0.5f, 0.15f, 600, Material{}), translate({0.9f, 0.6f, 0.3f}));
    s.append(makeFence(4, 0.35f, 1.0f, 0.03f, 2, 32, Material{}), translate({0, 0, -1.2f}));
    s.updateBounds();
    return s;
}

DBox randomBox(std::mt19937& rng, double extent) {
    std::uniform_real_distribution<double> u(-extent, extent), w(0.01, 0.5 * extent);
    glm::dvec3 c(u(rng), u(rng), u(rng)), h(w(rng), w(rng), w(rng));
    return {c - h, c + h};
}

glm::dvec3 pointIn(const DBox& b, std::mt19937& rng) {
    std::uniform_real_distribution<double> t(0.0, 1.0);
    return b.lo + (b.hi - b.lo) * glm::dvec3(t(rng), t(rng), t(rng));
}

bool inside(glm::dvec3 p, const DBox& b) { return glm::all(glm::greaterThanEqual(p, b.lo)) && glm::all(glm::lessThanEqual(p, b.hi)); }

// ---- Geometry ------------------------------------------------------------------------------------

TEST(LineSpaceTest, ShaftTestIsExactAgainstSampledSegments) {
    std::mt19937 rng(7);
    const glm::dvec3 lo(-1.0), size(2.0);
    const int n = 4;
    size_t hits = 0, misses = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        std::uniform_int_distribution<int> face(0, 5), cell(0, n - 1);
        int fa = face(rng), fb = face(rng);
        if (fa == fb) continue;
        DBox A = ls::subFaceBox(lo, size, n, fa, cell(rng), cell(rng)), B = ls::subFaceBox(lo, size, n, fb, cell(rng), cell(rng));
        DBox C = randomBox(rng, 1.0);
        C.hi = C.lo + (C.hi - C.lo) * 0.3;
        const bool test = ls::shaftOverlapsBox(A, B, C);
        // Conservative: a sampled segment point inside C proves the overlap.
        bool sampled = false;
        for (int k = 0; k < 400 && !sampled; ++k) {
            glm::dvec3 a = pointIn(A, rng), b = pointIn(B, rng);
            for (int q = 0; q <= 32 && !sampled; ++q) sampled = inside(a + (b - a) * (q / 32.0), C);
        }
        if (sampled) EXPECT_TRUE(test) << "trial " << trial;
        // Tight: when the test says yes, the witness s it found holds a point of C.
        if (test) {
            ++hits;
            double s0 = 0, s1 = 1;
            for (int j = 0; j < 3; ++j) {
                auto clip = [&](double a, double b) {
                    if (b > 0) s1 = std::min(s1, -a / b);
                    else if (b < 0) s0 = std::max(s0, -a / b);
                };
                clip(A.lo[j] - C.hi[j], B.lo[j] - A.lo[j]);
                clip(C.lo[j] - A.hi[j], A.hi[j] - B.hi[j]);
            }
            const double s = 0.5 * (s0 + s1);
            for (int j = 0; j < 3; ++j) {
                double lo2 = (1 - s) * A.lo[j] + s * B.lo[j], hi2 = (1 - s) * A.hi[j] + s * B.hi[j];
                EXPECT_LE(lo2, C.hi[j] + 1e-9);
                EXPECT_GE(hi2, C.lo[j] - 1e-9);
            }
        } else {
            ++misses;
        }
    }
    EXPECT_GT(hits, 100u);
    EXPECT_GT(misses, 200u);
}

TEST(LineSpaceTest, TriangleBoxOverlapMatchesSampling) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.5, 1.5), t(0.0, 1.0);
    const DBox box{glm::dvec3(-0.5, -0.3, -0.4), glm::dvec3(0.4, 0.5, 0.3)};
    size_t overlaps = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        glm::dvec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
        const bool test = ls::triangleOverlapsBox(a, b, c, box);
        overlaps += test;
        bool sampled = false;
        for (int k = 0; k < 3000 && !sampled; ++k) {
            double x = t(rng), y = t(rng);
            if (x + y > 1) x = 1 - x, y = 1 - y;
            sampled = inside(a + (b - a) * x + (c - a) * y, box);
        }
        if (sampled) EXPECT_TRUE(test) << "trial " << trial;
    }
    // A triangle that only grazes a corner, one parallel to a face just outside, one straddling.
    EXPECT_TRUE(ls::triangleOverlapsBox({0.4, 0.5, 0.3}, {2, 2, 2}, {2, 3, 2}, box));
    EXPECT_FALSE(ls::triangleOverlapsBox({-2, 0.51, -2}, {2, 0.51, -2}, {0, 0.51, 2}, box));
    EXPECT_TRUE(ls::triangleOverlapsBox({-2, 0.1, -2}, {2, 0.1, -2}, {0, 0.1, 2}, box));
    EXPECT_GT(overlaps, 400u);
}

// ---- The tree and its pools ----------------------------------------------------------------------

TEST(LineSpaceTest, PoolsHaveThePaperLayout) {
    Scene s = smallScene();
    for (auto [n, d] : {std::pair{4, 3}, {3, 2}, {5, 2}, {2, 1}}) {
        ls::NTree t = ls::buildNTree(s, n, d);
        ASSERT_FALSE(t.nodes.empty());
        const size_t words = ls::wordsPerNode(n);
        EXPECT_EQ(t.bits.size(), t.nodes.size() * words) << n << "," << d;
        size_t total = 0, groups = 0;
        for (int l = 0; l < d; ++l) total += t.nodesPerLevel[size_t(l)];
        EXPECT_EQ(total, t.nodes.size());
        EXPECT_EQ(t.nodesPerLevel[0], 1u);
        for (size_t i = 0; i < t.nodes.size(); ++i) {
            const ls::NodeGpu& node = t.nodes[i];
            if (int(node.level) == d - 1) {
                EXPECT_EQ(node.children, LS_NO_CHILDREN) << "the last level's children are leaves, never stored";
                continue;
            }
            ++groups;
            ASSERT_NE(node.children, LS_NO_CHILDREN);
            for (int c = 0; c < n * n * n; ++c) {
                uint32_t child = t.tree[node.children + size_t(c)];
                if (child == LS_EMPTY) continue;
                ASSERT_LT(child, t.nodes.size());
                EXPECT_EQ(t.nodes[child].level, node.level + 1);
                EXPECT_GT(child, i) << "breadth first";
                // The child's box is cell c of its parent.
                const int x = c % n, y = (c / n) % n, z = c / (n * n);
                EXPECT_EQ(t.nodes[child].lo[0], node.lo[0] + float(x) * (node.size[0] / float(n)));
                EXPECT_EQ(t.nodes[child].lo[2], node.lo[2] + float(z) * (node.size[2] / float(n)));
                (void)y;
            }
        }
        EXPECT_EQ(t.tree.size(), groups * size_t(n * n * n));
        // The occupancy bits say what the tree pool says, wherever there is a children group.
        const size_t occWords = ls::occupancyWords(n);
        ASSERT_EQ(t.occupancy.size(), t.nodes.size() * occWords);
        for (size_t i = 0; i < t.nodes.size(); ++i) {
            if (t.nodes[i].children == LS_NO_CHILDREN) continue;
            for (int c = 0; c < n * n * n; ++c) {
                const bool bit = (t.occupancy[i * occWords + size_t(c >> 5)] >> (c & 31)) & 1u;
                EXPECT_EQ(bit, t.tree[t.nodes[i].children + size_t(c)] != LS_EMPTY) << "node " << i << " child " << c;
            }
        }
        EXPECT_EQ(t.poolBytes(), t.nodes.size() * 32 + t.tree.size() * 4 + t.nodes.size() * (words + occWords) * 4);
    }
}

// The exact start region's leaf lists: a leaf has triangles exactly where its occupancy bit is set
// (the shader finds a leaf's list by counting the bits below it), each triangle touches its leaf.
TEST(LineSpaceTest, LeafListsFollowTheOccupancy) {
    Scene s = smallScene();
    for (auto [n, d] : {std::pair{4, 3}, {3, 2}, {5, 1}}) {
        ls::NTree t = ls::buildNTree(s, n, d);
        ls::LeafLists lists = ls::buildLeafLists(s, t, 2);
        const size_t occWords = ls::occupancyWords(n);
        ASSERT_EQ(lists.wordRank.size(), t.nodes.size() * occWords);
        size_t leaf = 0;
        for (size_t i = 0; i < t.nodes.size(); ++i) {
            if (int(t.nodes[i].level) != d - 1) continue;
            const glm::dvec3 lo(t.nodes[i].lo[0], t.nodes[i].lo[1], t.nodes[i].lo[2]);
            const glm::dvec3 cell = glm::dvec3(t.nodes[i].size[0], t.nodes[i].size[1], t.nodes[i].size[2]) / double(n);
            for (int c = 0; c < n * n * n; ++c) {
                if ((c & 31) == 0) EXPECT_EQ(lists.wordRank[i * occWords + size_t(c >> 5)], leaf) << "node " << i;
                if (!((t.occupancy[i * occWords + size_t(c >> 5)] >> (c & 31)) & 1u)) continue;
                ASSERT_LT(leaf + 1, lists.prefix.size());
                EXPECT_LT(lists.prefix[leaf], lists.prefix[leaf + 1]) << "an occupied leaf without triangles";
                const glm::dvec3 clo = lo + glm::dvec3(c % n, (c / n) % n, c / (n * n)) * cell;
                const ls::DBox box{clo - double(t.margin) - 1e-6, clo + cell + double(t.margin) + 1e-6};
                for (uint32_t k = lists.prefix[leaf]; k < lists.prefix[leaf + 1]; ++k) {
                    const uint32_t tri = lists.tris[k];
                    EXPECT_TRUE(ls::triangleOverlapsBox(glm::dvec3(s.positions[3 * tri]), glm::dvec3(s.positions[3 * tri + 1]),
                                                        glm::dvec3(s.positions[3 * tri + 2]), box));
                }
                ++leaf;
            }
        }
        EXPECT_EQ(leaf + 1, lists.prefix.size());
        EXPECT_EQ(lists.prefix.back(), lists.tris.size());
    }
}

// leaf_split: an occupied leaf's sub-cells are marked exactly where one of its triangles touches
// the sub-cell widened by the tree's margin (brute force over every sub-cell and triangle of the
// leaf), so a ray is blocked by a leaf only where its geometry can be; every occupied leaf has a
// marked sub-cell (the widened sub-cells cover the widened leaf).
TEST(LineSpaceTest, SubCellsAreMarkedWhereTheirLeafsTrianglesTouchThem) {
    Scene s = smallScene();
    for (int split : {2, 4}) {
        const int n = 4, d = 3;
        ls::NTree t = ls::buildNTree(s, n, d);
        ls::LeafLists lists = ls::buildLeafLists(s, t, 2, split);
        ASSERT_EQ(lists.sub.size(), 2 * (lists.prefix.size() - 1));
        const size_t occWords = ls::occupancyWords(n);
        size_t leaf = 0, marked = 0, cells = 0;
        for (size_t i = 0; i < t.nodes.size(); ++i) {
            if (int(t.nodes[i].level) != d - 1) continue;
            const glm::vec3 lo(t.nodes[i].lo[0], t.nodes[i].lo[1], t.nodes[i].lo[2]);
            const glm::vec3 cell = glm::vec3(t.nodes[i].size[0], t.nodes[i].size[1], t.nodes[i].size[2]) / float(n);
            for (int c = 0; c < n * n * n; ++c) {
                if (!((t.occupancy[i * occWords + size_t(c >> 5)] >> (c & 31)) & 1u)) continue;
                const uint64_t mask = uint64_t(lists.sub[2 * leaf]) | uint64_t(lists.sub[2 * leaf + 1]) << 32;
                EXPECT_NE(mask, 0u) << "an occupied leaf with no occupied sub-cell";
                // The shader's boxes: the leaf at lo + c × cell, its sub-cells at leafLo + k × cell / split.
                const glm::vec3 leafLo = lo + glm::vec3(float(c % n), float((c / n) % n), float(c / (n * n))) * cell;
                const glm::vec3 sub = cell / float(split);
                for (int b = 0; b < split * split * split; ++b) {
                    const glm::vec3 slo = leafLo + glm::vec3(float(b % split), float((b / split) % split), float(b / (split * split))) * sub;
                    const ls::DBox box{glm::dvec3(slo) - double(t.margin), glm::dvec3(slo + sub) + double(t.margin)};
                    bool touched = false;
                    for (uint32_t k = lists.prefix[leaf]; k < lists.prefix[leaf + 1] && !touched; ++k) {
                        const uint32_t tri = lists.tris[k];
                        touched = ls::triangleOverlapsBox(glm::dvec3(s.positions[3 * tri]), glm::dvec3(s.positions[3 * tri + 1]),
                                                          glm::dvec3(s.positions[3 * tri + 2]), box);
                    }
                    const bool bit = (mask >> b) & 1u;
                    // A triangle whose widened bounds lie in one sub-cell is marked there untested: a
                    // superset, never fewer.
                    if (touched) EXPECT_TRUE(bit) << "leaf " << leaf << " sub-cell " << b;
                    marked += bit, cells += 1;
                }
                ++leaf;
            }
        }
        // The split is worth it only if most sub-cells of occupied leaves stay empty.
        EXPECT_LT(double(marked), 0.6 * double(cells)) << "split " << split;
    }
}

// Triangle planes of the culled start region: unit normals, the vertices on the plane, zero for a
// degenerate triangle (never culled).
TEST(LineSpaceTest, TrianglePlanesHoldTheirVertices) {
    Scene s = smallScene();
    const std::vector<glm::vec4> planes = ls::trianglePlanes(s);
    ASSERT_EQ(planes.size(), s.triangleCount());
    for (size_t i = 0; i < planes.size(); ++i) {
        EXPECT_NEAR(glm::length(glm::vec3(planes[i])), 1.0f, 1e-5f);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(glm::dot(glm::vec3(planes[i]), s.positions[3 * i + k]) + planes[i].w, 0.0f, 1e-5f);
    }
    Scene degenerate; // addTriangles() drops a zero-area triangle; a soup written directly may hold one
    degenerate.positions = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
    degenerate.normals = {{0, 1, 0}};
    ASSERT_EQ(degenerate.triangleCount(), 1u);
    EXPECT_EQ(ls::trianglePlanes(degenerate).at(0), glm::vec4(0.0f));
}

TEST(LineSpaceTest, BuildIsIndependentOfTheThreadCount) {
    Scene s = smallScene();
    ls::NTree a = ls::buildNTree(s, 4, 3, 1), b = ls::buildNTree(s, 4, 3, 3);
    EXPECT_EQ(a.tree, b.tree);
    EXPECT_EQ(a.bits, b.bits);
    EXPECT_EQ(a.occupancy, b.occupancy);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(ls::NodeGpu)));
}

/// Moller–Trumbore on a segment, in double: the hit parameter in [0, 1], or -1.
double segmentHit(glm::dvec3 a, glm::dvec3 b, glm::dvec3 v0, glm::dvec3 v1, glm::dvec3 v2) {
    glm::dvec3 d = b - a, e1 = v1 - v0, e2 = v2 - v0, p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-300) return -1;
    glm::dvec3 s = a - v0;
    double u = glm::dot(s, p) / det;
    glm::dvec3 q = glm::cross(s, e1);
    double v = glm::dot(d, q) / det, t = glm::dot(e2, q) / det;
    return (u >= 0 && v >= 0 && u + v <= 1 && t >= 0 && t <= 1) ? t : -1;
}

// The defining property: a segment between two sub-faces of a node that crosses a triangle inside
// the node finds the shaft's bit set. Checked on random segments of random nodes of every level.
TEST(LineSpaceTest, EveryShaftThroughGeometryIsMarked) {
    Scene s = smallScene();
    const int n = 4;
    ls::NTree t = ls::buildNTree(s, n, 3);
    std::mt19937 rng(11);
    std::uniform_int_distribution<size_t> pickNode(0, t.nodes.size() - 1);
    std::uniform_int_distribution<int> face(0, 5), cell(0, n - 1);
    size_t blocked = 0, empty = 0, setBits = 0, checked = 0;
    for (int trial = 0; trial < 1500; ++trial) {
        const size_t ni = pickNode(rng);
        const ls::NodeGpu& node = t.nodes[ni];
        const glm::dvec3 lo(node.lo[0], node.lo[1], node.lo[2]), size(node.size[0], node.size[1], node.size[2]);
        const DBox nodeBox{lo, lo + size};
        for (int k = 0; k < 20; ++k) {
            int fa = face(rng), fb = face(rng);
            if (fa == fb) continue;
            int ia = cell(rng), ja = cell(rng), ib = cell(rng), jb = cell(rng);
            glm::dvec3 a = pointIn(ls::subFaceBox(lo, size, n, fa, ia, ja), rng), b = pointIn(ls::subFaceBox(lo, size, n, fb, ib, jb), rng);
            bool hit = false;
            for (size_t tri = 0; tri < s.triangleCount() && !hit; ++tri) {
                glm::dvec3 v0(s.positions[3 * tri]), v1(s.positions[3 * tri + 1]), v2(s.positions[3 * tri + 2]);
                double th = segmentHit(a, b, v0, v1, v2);
                hit = th >= 0 && inside(a + (b - a) * th, nodeBox);
            }
            const bool bit = t.bit(ni, ls::shaftBit(n, fa, ja * n + ia, fb, jb * n + ib));
            ++checked;
            setBits += bit;
            if (hit) {
                ++blocked;
                EXPECT_TRUE(bit) << "node " << ni << " level " << node.level << " faces " << fa << "," << fb;
            } else {
                ++empty;
            }
        }
    }
    std::printf("[line_space] %zu segments: %zu through geometry, %zu free; %zu bits set\n", checked, blocked, empty, setBits);
    EXPECT_GT(blocked, 1000u);
    EXPECT_GT(checked - setBits, 1000u) << "some shafts must be empty, or the test proves nothing";
}

// The fast fill (block hierarchy, pruning, bits marked without a test) sets exactly the bits of the
// brute force: every shaft against every non-empty child with the exact test.
TEST(LineSpaceTest, FastFillEqualsBruteForce) {
    std::mt19937 rng(5);
    for (int n : {2, 3, 5, 8}) {
        for (int trial = 0; trial < 4; ++trial) {
            const glm::vec3 lo(-1.0f, 0.5f, 2.0f), size(2.0f, 0.7f, 1.3f);
            std::vector<uint8_t> occupied(size_t(n * n * n), 0);
            std::bernoulli_distribution fill(trial == 0 ? 0.02 : trial == 1 ? 0.1 : trial == 2 ? 0.4 : 0.9);
            for (auto& o : occupied) o = fill(rng);
            const double margin = 1e-5;
            std::vector<uint32_t> fast(ls::wordsPerNode(n), 0u), brute(ls::wordsPerNode(n), 0u);
            ls::fillLineSpace(n, lo, size, occupied, margin, fast.data());
            const glm::vec3 cell = size / float(n);
            std::vector<DBox> full;
            for (int c = 0; c < n * n * n; ++c)
                if (occupied[size_t(c)]) {
                    glm::vec3 clo = lo + glm::vec3(float(c % n), float((c / n) % n), float(c / (n * n))) * cell;
                    full.push_back({glm::dvec3(clo) - margin, glm::dvec3(clo + cell) + margin});
                }
            for (int fa = 0; fa < 6; ++fa)
                for (int fb = fa + 1; fb < 6; ++fb)
                    for (int sa = 0; sa < n * n; ++sa)
                        for (int sb = 0; sb < n * n; ++sb) {
                            DBox A = ls::subFaceBox(lo, size, n, fa, sa % n, sa / n), B = ls::subFaceBox(lo, size, n, fb, sb % n, sb / n);
                            for (const DBox& C : full)
                                if (ls::shaftOverlapsBox(A, B, C)) {
                                    const uint32_t b = ls::shaftBit(n, fa, sa, fb, sb);
                                    brute[b >> 5] |= 1u << (b & 31);
                                    break;
                                }
                        }
            size_t differ = 0, set = 0;
            for (size_t w = 0; w < fast.size(); ++w) differ += size_t(__builtin_popcount(fast[w] ^ brute[w])), set += size_t(__builtin_popcount(brute[w]));
            EXPECT_EQ(differ, 0u) << "N = " << n << ", trial " << trial << ", " << set << " bits set";
        }
    }
}

TEST(LineSpaceTest, BuildStopsAtTheStorageLimit) {
    Scene s = smallScene();
    // (6, 3) needs ~5 MiB of line space here: four blocks of 1 MiB cannot hold it.
    try {
        ls::buildNTree(s, 6, 3, 0, size_t(1) << 20);
        ADD_FAILURE() << "expected the build to stop";
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("line-space"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(ls::buildNTree(s, 6, 3, 0, size_t(2) << 20)); // three blocks of 2 MiB
}

// ---- Disk cache ----------------------------------------------------------------------------------

class LineSpaceCacheTest : public ::testing::Test {
protected:
    void SetUp() override { dir_ = test::makeTempDir("lscache"); }
    std::string dir_;
};

TEST_F(LineSpaceCacheTest, RoundTripAndKeys) {
    Scene s = smallScene();
    ls::NTree t = ls::buildNTree(s, 3, 2);
    const uint64_t hash = s.contentHash();
    const std::string path = ls::cacheFile(dir_, hash, 3, 2);
    EXPECT_NE(path, ls::cacheFile(dir_, hash, 3, 3));
    EXPECT_NE(path, ls::cacheFile(dir_, hash, 4, 2));
    EXPECT_NE(path, ls::cacheFile(dir_, hash + 1, 3, 2));
    std::string why;
    ASSERT_TRUE(ls::saveCache(path, hash, t, &why)) << why;
    std::optional<ls::NTree> back = ls::loadCache(path, hash, 3, 2, &why);
    ASSERT_TRUE(back.has_value()) << why;
    EXPECT_EQ(back->tree, t.tree);
    EXPECT_EQ(back->bits, t.bits);
    EXPECT_EQ(back->occupancy, t.occupancy);
    EXPECT_EQ(back->nodesPerLevel, t.nodesPerLevel);
    EXPECT_EQ(back->buildMs, t.buildMs);
    EXPECT_EQ(back->margin, t.margin);
    EXPECT_EQ(0, std::memcmp(back->nodes.data(), t.nodes.data(), t.nodes.size() * sizeof(ls::NodeGpu)));
    // Another scene or parameter set never reads this file as its own.
    EXPECT_FALSE(ls::loadCache(path, hash + 1, 3, 2, &why).has_value());
    EXPECT_FALSE(ls::loadCache(path, hash, 3, 3, &why).has_value());
    EXPECT_FALSE(ls::loadCache(dir_ + "/missing.bin", hash, 3, 2, &why).has_value());
}

TEST_F(LineSpaceCacheTest, CorruptFilesAreDetected) {
    Scene s = smallScene();
    ls::NTree t = ls::buildNTree(s, 3, 2);
    const uint64_t hash = s.contentHash();
    const std::string path = ls::cacheFile(dir_, hash, 3, 2);
    ASSERT_TRUE(ls::saveCache(path, hash, t, nullptr));
    const auto size = std::filesystem::file_size(path);
    std::string why;
    for (size_t offset : {size_t(3), size_t(40), size_t(size / 2), size_t(size - 1)}) {
        ASSERT_TRUE(ls::saveCache(path, hash, t, nullptr));
        {
            std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
            f.seekg(std::streamoff(offset));
            char c = 0;
            f.read(&c, 1);
            c = char(c ^ 0x5A);
            f.seekp(std::streamoff(offset));
            f.write(&c, 1);
        }
        EXPECT_FALSE(ls::loadCache(path, hash, 3, 2, &why).has_value()) << "flipped byte " << offset;
        EXPECT_FALSE(why.empty());
    }
    ASSERT_TRUE(ls::saveCache(path, hash, t, nullptr));
    std::filesystem::resize_file(path, size - 7); // truncated (an interrupted copy)
    EXPECT_FALSE(ls::loadCache(path, hash, 3, 2, &why).has_value());
    std::printf("[line_space] truncated cache: %s\n", why.c_str());
}

TEST_F(LineSpaceCacheTest, DirectoryFollowsXdgThenHome) {
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const std::string saved = xdg ? xdg : "";
    setenv("XDG_CACHE_HOME", dir_.c_str(), 1);
    EXPECT_EQ(ls::cacheDirectory(), dir_ + "/shadowlab/line_space");
    unsetenv("XDG_CACHE_HOME");
    if (const char* home = std::getenv("HOME")) EXPECT_EQ(ls::cacheDirectory(), std::string(home) + "/.cache/shadowlab/line_space");
    if (xdg) setenv("XDG_CACHE_HOME", saved.c_str(), 1);
}

// Build times of the Table 1 parameter sets on the 2CylinderEngine (run by hand).
} // namespace
} // namespace shadowlab
