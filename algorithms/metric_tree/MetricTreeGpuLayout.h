#pragma once
// Host mirror of the metric_tree GPU structures. The constants live once, in
// shaders/metric_tree/layout.glsl (#defines only, valid C++ and GLSL); the structs are mirrored from
// shaders/metric_tree/tree.glsl (std430).
#include "shaders/metric_tree/layout.glsl"

#include <cstddef>
#include <cstdint>

namespace shadowlab::mt {

/// One cluster (see MtCluster in tree.glsl).
struct ClusterGpu {
    float a[4];    ///< sphere centre or capsule end A (world); w: radius
    float b[4];    ///< capsule end B (= a for a sphere); w: cos of the normal cone's half-angle (-1: any)
    float axis[4]; ///< normal cone axis (unit, also the slabs' normal); w: lower slab
    float slabMax; ///< upper slab, dot(axis, x)
    uint32_t first, count, flags;
};
static_assert(sizeof(ClusterGpu) == MT_CLUSTER_BYTES, "MtCluster is 64 bytes in std430");

/// One metric tree node (see MtNode in tree.glsl).
struct NodeGpu {
    float a[4];          ///< light-space first end of the centre element; w: angular radius
    float b[4];          ///< light-space second end; w: partitioning distance delta
    uint32_t child[3];   ///< near, far, overlap: node index + 1, 0 = empty
    uint32_t minDist;    ///< float bits: smallest light distance of the subtree
    uint32_t overlapMin; ///< float bits: interval of the overlap subtree's distances from the pivot
    uint32_t overlapMax;
    uint32_t flags;      ///< MT_NODE_*
    uint32_t pad;
};
static_assert(sizeof(NodeGpu) == MT_NODE_BYTES, "MtNode is 64 bytes in std430");

constexpr size_t kCounterBytes = MT_COUNTER_WORDS * sizeof(uint32_t);
/// Clusters + nodes: the paper's 128 bytes per cluster.
constexpr size_t structureBytes(size_t clusters) { return clusters * (MT_CLUSTER_BYTES + MT_NODE_BYTES); }
static_assert(structureBytes(1000) == 128 * 1000);

} // namespace shadowlab::mt
