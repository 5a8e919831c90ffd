#pragma once
// CPU construction of the BVH that bvh_raytrace traverses on the GPU: binned SAH (Wald 2007) over
// triangle centroids, flattened into the two-children-per-node layout of BvhGpuLayout.h.
// GL-free, so the CPU tests can check it directly.
#include "framework/accel/BvhGpuLayout.h"
#include "framework/scene/Scene.h"

#include <cstdint>
#include <vector>

namespace shadowlab::bvh {

struct BuildOptions {
    int maxLeafSize = 4; ///< a leaf holds at most this many triangles (unless they cannot be split)
    int bins = 32;       ///< SAH bins per axis (schema: sah_bins)
    /// SAH cost of one node traversal relative to one ray–triangle test (schema: traversal_cost).
    float traversalCost = 1.0f;
};

struct Bvh {
    std::vector<NodeGpu> nodes;       ///< node 0 is the root
    std::vector<uint32_t> triIndices; ///< leaf ranges index into this; values are scene triangle ids
    /// The triangles in leaf order, 3 vertices (w = 0) each: triangle i of a leaf range is
    /// triangles[3i .. 3i + 2] = the scene's triangle triIndices[i], so the shader reads a leaf's
    /// vertices contiguously with no index indirection.
    std::vector<glm::vec4> triangles;
    int depth = 0;                    ///< most inner nodes on a root-to-leaf path (the stack a ray may need)
    size_t leaves = 0;
    double sahCost = 0;               ///< SAH cost of the tree (relative to one triangle test per ray)
};

/// Builds the BVH of every triangle of `scene`. Deterministic for a given scene and options.
Bvh buildBvh(const Scene& scene, const BuildOptions& options = {});

/// Refits `tree` to new positions of the same triangles (3 per scene triangle): rewrites the
/// leaf-ordered triangles and recomputes every box bottom-up. The tree keeps its shape, so its
/// quality (not its correctness) degrades as moving parts travel away from where it was built.
void refitBvh(Bvh& tree, const std::vector<glm::vec3>& positions);

} // namespace shadowlab::bvh
