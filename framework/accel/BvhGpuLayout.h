#pragma once
// Host mirror of the scene BVH's GPU structures. The constants live once, in
// shaders/common/bvh_layout.glsl (#defines only, valid C++ and GLSL); the node struct is
// mirrored from BvhNode in shaders/common/bvh_traverse.glsl.
#include "shaders/common/bvh_layout.glsl"

#include <cstddef>
#include <cstdint>

namespace shadowlab::bvh {

/// One BVH node, std430: the boxes of both children and how to reach them (see layout.glsl).
struct NodeGpu {
    float lo0[3];
    uint32_t child0; ///< count0 > 0: first index of the leaf's triangles; else the inner node index
    float hi0[3];
    uint32_t child1;
    float lo1[3];
    uint32_t count0; ///< triangles in leaf child 0; 0 = child 0 is an inner node
    float hi1[3];
    uint32_t count1;
};
static_assert(sizeof(NodeGpu) == BVH_NODE_BYTES, "BvhNode is 64 bytes in std430");

/// Throws RuntimeError naming `what` when a buffer of `bytes` exceeds `limit`
/// (an SSBO larger than the limit cannot be addressed whole: the image would silently be wrong).
void checkStorageBlock(const char* what, size_t bytes, size_t limit);

} // namespace shadowlab::bvh
