#pragma once
// The preprocessing of metric_tree (paper section 4): triangles sorted along a Morton curve, cut
// into chunks of 512, and each chunk split by hierarchical k-means (k-means++ seeding) until every
// cluster holds at most `clusterSize` triangles. Each cluster gets a normal cone, two slabs along
// its axis, and a bounding sphere (exact smallest enclosing sphere) or, when its covariance OBB is
// elongated, a capsule.
#include "algorithms/metric_tree/MetricTreeGpuLayout.h"
#include "framework/scene/Scene.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace shadowlab::mt {

struct ClusteringOptions {
    int clusterSize = 16;   ///< most triangles per cluster
    bool capsules = true;   ///< capsules for elongated clusters (else spheres only)
    bool randomOrder = true; ///< shuffle the clusters: their order is the insertion (pivot) order
    uint32_t seed = 1;
    int chunkTriangles = 512; ///< triangles per Morton chunk before k-means (the paper's 512)
    int kmeansIterations = 8; ///< Lloyd iterations per k-means split
};

struct Clustering {
    std::vector<ClusterGpu> clusters;
    std::vector<uint32_t> order; ///< scene triangle index of each triangle in cluster order
    size_t capsules = 0;         ///< clusters bounded by a capsule
};

Clustering clusterScene(const Scene& scene, const ClusteringOptions& options);

// ---- Building blocks, exposed for the tests ----

struct Sphere {
    glm::dvec3 centre{0.0};
    double radius = 0;
};
/// Smallest sphere enclosing `points` (Welzl's algorithm, exact up to rounding); the radius is then
/// raised to the largest distance actually measured, so every point is inside.
Sphere smallestEnclosingSphere(std::vector<glm::dvec3> points);

struct Circle {
    glm::dvec2 centre{0.0};
    double radius = 0;
};
/// Smallest circle enclosing `points`, same guarantee.
Circle smallestEnclosingCircle(std::vector<glm::dvec2> points);

/// The bounding volume of one cluster's vertices: a capsule (segment a-b, radius) when the longest
/// covariance-OBB extent is at least twice each other one and `capsules` is on, else the smallest
/// enclosing sphere (a = b).
struct BoundingVolume {
    glm::dvec3 a{0.0}, b{0.0};
    double radius = 0;
    bool capsule = false;
};
BoundingVolume boundingVolume(const std::vector<glm::dvec3>& vertices, bool capsules);

} // namespace shadowlab::mt
