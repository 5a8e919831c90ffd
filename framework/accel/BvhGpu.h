#pragma once
// A BVH on the GPU as shaders/common/bvh_traverse.glsl reads it: nodes and leaf-ordered triangles
// with their buffer-texture views, and the walk's step cap. bvh_raytrace traces through it, and so
// do line_space's near field (start_region bvh) and shadow_volumes' close calls.
#include "framework/accel/BvhBuilder.h"
#include "framework/gl/GlObjects.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace shadowlab::bvh {

struct BvhGpu {
    GlBuffer nodes, triangles;
    GlTexture nodeTexels, triTexels; ///< nodes and triangles as buffer textures: how the traversal reads them
    uint32_t stepCap = 1;            ///< uBvhStepCap: most loop passes of one walk, nodes + 2 * leaves + 1
    size_t bytes() const { return nodes.size() + triangles.size(); }
    /// The views on the texture units the including shader gave BVH_TRAVERSE_NODE_UNIT and _TRI_UNIT.
    void bind(unsigned nodeUnit, unsigned triUnit) const;
};

/// Uploads `tree` once it is known the traversal can address it: each buffer within a storage block of
/// `limit` bytes (checkStorageBlock) and fewer than 2^27 triangles (a leaf's first triangle has 27
/// bits of a stack entry, layout.glsl). `flags`: the buffers' storage flags (GL_DYNAMIC_STORAGE_BIT
/// for a tree refitted and uploaded again); `owner` labels the buffers and names who asked in errors.
BvhGpu uploadBvh(const Bvh& tree, size_t limit, GLbitfield flags, const std::string& owner);

} // namespace shadowlab::bvh
