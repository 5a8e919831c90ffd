// metric_tree's CPU pieces: the exact enclosing sphere and circle, the sphere/capsule choice and
// its containment guarantee, the clustering (a partition of the triangles into bounded clusters
// whose volumes, normal cones and slabs hold every triangle), the light-space distance bounds the
// tree relies on (checked against brute force), and the disk cache's rejection of bad files.
#include "algorithms/metric_tree/ClusterCache.h"
#include "algorithms/metric_tree/Clustering.h"
#include "algorithms/metric_tree/MetricTreeMath.h"
#include "framework/scene/Procedural.h"
#include "tests/TestSupport.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace shadowlab::mt {
namespace {

std::vector<glm::dvec3> randomPoints(std::mt19937& rng, int n, glm::dvec3 scale) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<glm::dvec3> p;
    for (int i = 0; i < n; ++i) p.push_back(glm::dvec3(u(rng), u(rng), u(rng)) * scale);
    return p;
}

TEST(MetricTreeTest, EnclosingSphereIsMinimal) {
    std::mt19937 rng(3);
    for (int trial = 0; trial < 200; ++trial) {
        auto pts = randomPoints(rng, 2 + trial % 60, {1.0, 0.3 + (trial % 5), 0.5});
        Sphere s = smallestEnclosingSphere(pts);
        for (auto p : pts) EXPECT_LE(glm::length(p - s.centre), s.radius * (1 + 1e-12));
        // Minimal: moving the centre a little in any direction can only grow the radius (the
        // smallest enclosing sphere is the unique minimiser of the largest distance).
        for (glm::dvec3 d : {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1), glm::dvec3(-1, 0, 0),
                             glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1), glm::normalize(glm::dvec3(1, 1, 1))}) {
            double r = 0;
            for (auto p : pts) r = std::max(r, glm::length(p - (s.centre + 1e-3 * s.radius * d)));
            EXPECT_GE(r, s.radius * (1 - 1e-9)) << "trial " << trial;
        }
    }
    // Known answers: a segment's midpoint, a regular tetrahedron's centre.
    Sphere seg = smallestEnclosingSphere({{0, 0, 0}, {2, 0, 0}, {1, 0.1, 0}});
    EXPECT_NEAR(seg.radius, 1.0, 1e-12);
    Sphere tet = smallestEnclosingSphere({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}});
    EXPECT_NEAR(tet.radius, std::sqrt(3.0), 1e-9);
    EXPECT_NEAR(glm::length(tet.centre), 0.0, 1e-9);
}

TEST(MetricTreeTest, EnclosingCircleIsMinimal) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<glm::dvec2> pts;
        for (int i = 0; i < 2 + trial % 40; ++i) pts.emplace_back(u(rng), 0.2 * u(rng));
        Circle c = smallestEnclosingCircle(pts);
        for (auto p : pts) EXPECT_LE(glm::length(p - c.centre), c.radius * (1 + 1e-12));
        for (glm::dvec2 d : {glm::dvec2(1, 0), glm::dvec2(0, 1), glm::dvec2(-1, 0), glm::dvec2(0, -1)}) {
            double r = 0;
            for (auto p : pts) r = std::max(r, glm::length(p - (c.centre + 1e-3 * c.radius * d)));
            EXPECT_GE(r, c.radius * (1 - 1e-9));
        }
    }
}

double distanceToVolume(const BoundingVolume& bv, glm::dvec3 p) {
    const glm::dvec3 ab = bv.b - bv.a;
    const double l2 = glm::dot(ab, ab);
    const double t = l2 > 0 ? std::clamp(glm::dot(p - bv.a, ab) / l2, 0.0, 1.0) : 0.0;
    return glm::length(p - (bv.a + t * ab));
}

TEST(MetricTreeTest, CapsuleOnlyForElongatedClusters) {
    std::mt19937 rng(9);
    // A thin rod: longest OBB extent far above twice the others.
    auto rod = randomPoints(rng, 48, {2.0, 0.05, 0.05});
    BoundingVolume c = boundingVolume(rod, true);
    EXPECT_TRUE(c.capsule);
    for (auto p : rod) EXPECT_LE(distanceToVolume(c, p), c.radius * (1 + 1e-9));
    // The capsule is much tighter than the sphere on a rod.
    BoundingVolume s = boundingVolume(rod, false);
    EXPECT_FALSE(s.capsule);
    EXPECT_LT(c.radius * 5, s.radius);
    // A blob: sphere.
    auto blob = randomPoints(rng, 48, {1.0, 0.8, 0.7});
    EXPECT_FALSE(boundingVolume(blob, true).capsule);
    // A flat disc-like cluster: its longest extent is not twice the second one.
    auto disc = randomPoints(rng, 48, {1.0, 0.9, 0.01});
    EXPECT_FALSE(boundingVolume(disc, true).capsule);
}

Scene testScene() {
    Scene s = makePlane({4, 4}, 6, Material{});
    s.append(makeSphere(0.5f, 900, Material{}), glm::translate(glm::mat4(1.0f), glm::vec3(0, 0.6f, 0)));
    s.append(makeFence(8, 0.3f, 1.0f, 0.02f, 2, 24, Material{}), glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -1)));
    return s;
}

TEST(MetricTreeTest, ClusteringPartitionsTheTrianglesIntoBoundedClusters) {
    const Scene scene = testScene();
    for (int size : {4, 16, 32}) {
        for (bool capsules : {true, false}) {
            ClusteringOptions o;
            o.clusterSize = size;
            o.capsules = capsules;
            Clustering c = clusterScene(scene, o);
            ASSERT_EQ(c.order.size(), scene.triangleCount());
            std::vector<int> seen(scene.triangleCount(), 0);
            for (uint32_t t : c.order) ++seen[t];
            for (int k : seen) ASSERT_EQ(k, 1) << "every triangle exactly once";
            size_t covered = 0, capsuleCount = 0;
            for (const ClusterGpu& cl : c.clusters) {
                ASSERT_GE(cl.count, 1u);
                ASSERT_LE(cl.count, uint32_t(size));
                covered += cl.count;
                const bool isCapsule = cl.flags & MT_FLAG_CAPSULE;
                capsuleCount += isCapsule;
                if (!capsules) EXPECT_FALSE(isCapsule);
                BoundingVolume bv;
                bv.a = glm::dvec3(cl.a[0], cl.a[1], cl.a[2]);
                bv.b = glm::dvec3(cl.b[0], cl.b[1], cl.b[2]);
                const glm::vec3 axis(cl.axis[0], cl.axis[1], cl.axis[2]);
                for (uint32_t k = 0; k < cl.count; ++k) {
                    const uint32_t t = c.order[cl.first + k];
                    // The cone holds every normal, and the slabs and the volume every vertex.
                    EXPECT_GE(glm::dot(axis, scene.normals[t]), cl.b[3]);
                    for (int v = 0; v < 3; ++v) {
                        const glm::vec3 p = scene.positions[3 * t + v];
                        EXPECT_LE(distanceToVolume(bv, glm::dvec3(p)), double(cl.a[3]));
                        EXPECT_GE(glm::dot(axis, p), cl.axis[3] - 1e-6f);
                        EXPECT_LE(glm::dot(axis, p), cl.slabMax + 1e-6f);
                    }
                }
            }
            EXPECT_EQ(covered, scene.triangleCount());
            EXPECT_EQ(capsuleCount, c.capsules);
            if (capsules) EXPECT_GT(c.capsules, 0u) << "the fence has elongated clusters";
            // k-means keeps clusters reasonably full: on average above a third of the bound.
            EXPECT_GT(double(scene.triangleCount()) / double(c.clusters.size()), size / 3.0) << size;
        }
    }
}

TEST(MetricTreeTest, ClusteringIsDeterministic) {
    const Scene scene = testScene();
    ClusteringOptions o;
    Clustering a = clusterScene(scene, o), b = clusterScene(scene, o);
    EXPECT_EQ(a.order, b.order);
    ASSERT_EQ(a.clusters.size(), b.clusters.size());
    EXPECT_EQ(0, std::memcmp(a.clusters.data(), b.clusters.data(), a.clusters.size() * sizeof(ClusterGpu)));
}

// The bounds the tree is built on, against brute force over sampled points of two elements:
// minDist is at most, and maxDist at least, every sampled distance, and both are attained closely.
TEST(MetricTreeTest, LightSpaceDistancesBoundSampledDistances) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    auto unit = [&]() { return glm::normalize(glm::vec3(u(rng), u(rng), u(rng))); };
    for (bool directional : {false, true}) {
        for (int trial = 0; trial < 300; ++trial) {
            glm::vec3 a1, b1, a2, b2;
            if (directional) {
                a1 = {u(rng), u(rng), 0}, b1 = trial % 3 ? glm::vec3(u(rng), u(rng), 0) : a1;
                a2 = {u(rng), u(rng), 0}, b2 = trial % 4 ? glm::vec3(u(rng), u(rng), 0) : a2;
            } else {
                // Arcs shorter than pi: ends within about 100 degrees of each other.
                a1 = unit(), b1 = trial % 3 ? glm::normalize(a1 + 0.8f * unit()) : a1;
                a2 = unit(), b2 = trial % 4 ? glm::normalize(a2 + 0.8f * unit()) : a2;
            }
            auto at = [&](glm::vec3 a, glm::vec3 b, float t) {
                glm::vec3 p = glm::mix(a, b, t);
                return directional ? p : glm::normalize(p); // points of the chord's projection = the arc
            };
            auto dist = [&](glm::vec3 p, glm::vec3 q) { return directional ? glm::length(p - q) : angle(p, q); };
            float lo = 1e30f, hi = 0;
            for (int i = 0; i <= 64; ++i)
                for (int j = 0; j <= 64; ++j) {
                    const float d = dist(at(a1, b1, i / 64.0f), at(a2, b2, j / 64.0f));
                    lo = std::min(lo, d), hi = std::max(hi, d);
                }
            const float dMin = minDist(directional, a1, b1, a2, b2), dMax = maxDist(directional, a1, b1, a2, b2);
            EXPECT_LE(dMin, lo + 1e-5f) << "trial " << trial;
            EXPECT_GE(dMax, hi - 1e-5f) << "trial " << trial;
            EXPECT_GT(dMin, lo - 0.05f) << "trial " << trial << ": the bound should be near the sampled minimum";
            EXPECT_LT(dMax, hi + 0.05f) << "trial " << trial;
            for (int i = 0; i <= 16; ++i) { // point distance: the minimum over the element
                const glm::vec3 p = at(a1, b1, i / 16.0f);
                float best = 1e30f;
                for (int j = 0; j <= 256; ++j) best = std::min(best, dist(p, at(a2, b2, j / 256.0f)));
                EXPECT_LE(pointDist(directional, p, a2, b2), best + 1e-5f);
                EXPECT_GT(pointDist(directional, p, a2, b2), best - 0.02f);
            }
        }
    }
}

TEST(MetricTreeTest, CacheRoundTripsAndRejectsBadFiles) {
    const Scene scene = testScene();
    ClusteringOptions o;
    Clustering c = clusterScene(scene, o);
    const std::string dir = test::makeTempDir("mt-cache-cpu");
    const uint64_t hash = scene.contentHash();
    const std::string path = cacheFile(dir, hash, o);
    std::string why;
    ASSERT_TRUE(saveCache(path, hash, o, scene.triangleCount(), c, &why)) << why;
    auto back = loadCache(path, hash, o, scene, &why);
    ASSERT_TRUE(back) << why;
    EXPECT_EQ(back->order, c.order);
    EXPECT_EQ(back->capsules, c.capsules);
    ClusteringOptions other = o;
    other.clusterSize = 8;
    EXPECT_NE(cacheFile(dir, hash, other), path);
    EXPECT_FALSE(loadCache(path, hash, other, scene, &why));
    EXPECT_FALSE(loadCache(path, hash + 1, o, scene, &why));
    // A flipped byte in the payload, then a truncated file: reported, never trusted.
    {
        std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(200);
        char x = 0x5A;
        f.write(&x, 1);
    }
    EXPECT_FALSE(loadCache(path, hash, o, scene, &why));
    EXPECT_NE(why.find("checksum"), std::string::npos) << why;
    std::filesystem::resize_file(path, 100);
    EXPECT_FALSE(loadCache(path, hash, o, scene, &why));
}

// A file of another scene with the same triangle count, its header rewritten to this scene's key and
// its checksums recomputed (what a copied or hand-edited cache looks like): the clusters themselves
// do not bound this scene's triangles, so it is rejected.
TEST(MetricTreeTest, CacheOfOtherContentIsRejectedWhateverItsHeaderSays) {
    const Scene scene = testScene();
    Scene moved = scene;
    for (auto& p : moved.positions) p += glm::vec3(0.05f, 0.0f, 0.0f);
    moved.updateBounds();
    ClusteringOptions o;
    const std::string dir = test::makeTempDir("mt-cache-forged");
    const uint64_t hash = scene.contentHash();
    const std::string path = cacheFile(dir, hash, o);
    std::string why;
    ASSERT_TRUE(saveCache(path, hash, o, moved.triangleCount(), clusterScene(moved, o), &why)) << why;
    EXPECT_FALSE(loadCache(path, hash, o, scene, &why));
    EXPECT_NE(why.find("other content"), std::string::npos) << why;
    // Its own clustering, under the same key, is accepted: the check is not merely strict.
    ASSERT_TRUE(saveCache(path, hash, o, scene.triangleCount(), clusterScene(scene, o), &why)) << why;
    EXPECT_TRUE(loadCache(path, hash, o, scene, &why)) << why;
}

// Fifteenth probe: a cache whose clusters' counts were set to 0, checksums recomputed, was taken,
// and the triangles in no cluster cast no shadow (5.98 % of pixels, overflow 0). Every triangle is
// in exactly one cluster, or the file is not used.
TEST(MetricTreeTest, CacheWhoseClustersLeaveATriangleOutIsRejected) {
    const Scene scene = testScene();
    ClusteringOptions o;
    const std::string dir = test::makeTempDir("mt-cache-cover");
    const uint64_t hash = scene.contentHash();
    const std::string path = cacheFile(dir, hash, o);
    std::string why;
    Clustering emptied = clusterScene(scene, o);
    for (auto& cl : emptied.clusters) cl.count = 0;
    ASSERT_TRUE(saveCache(path, hash, o, scene.triangleCount(), emptied, &why)) << why;
    EXPECT_FALSE(loadCache(path, hash, o, scene, &why));
    EXPECT_NE(why.find("in no cluster"), std::string::npos) << why;
    Clustering doubled = clusterScene(scene, o);
    ASSERT_GE(doubled.clusters.size(), 2u);
    doubled.clusters[1].first = doubled.clusters[0].first;
    ASSERT_TRUE(saveCache(path, hash, o, scene.triangleCount(), doubled, &why)) << why;
    EXPECT_FALSE(loadCache(path, hash, o, scene, &why));
}

// A bad parameter is the framework's one-line input error (exit 2), naming the key.
TEST(MetricTreeTest, BadParametersAreInputErrors) {
    const std::string smoke = std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json";
    for (const char* set : {"'algorithms=[{\"id\":\"m\",\"algorithm\":\"metric_tree\",\"params\":{\"cluster_size\":1}}]'",
                            "'algorithms=[{\"id\":\"m\",\"algorithm\":\"metric_tree\",\"params\":{\"tree_builder\":\"gpu2\"}}]'",
                            "'algorithms=[{\"id\":\"m\",\"algorithm\":\"metric_tree\",\"params\":{\"capsule\":true}}]'"}) {
        std::string out;
        const int rc = test::runCommand(std::string(SHADOWLAB_BINARY) + " validate " + smoke + " --set " + set, out);
        EXPECT_EQ(rc, 2) << out;
        EXPECT_NE(out.find("params"), std::string::npos) << out;
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << "one line: " << out;
    }
}

} // namespace
} // namespace shadowlab::mt
