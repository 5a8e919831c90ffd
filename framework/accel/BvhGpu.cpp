#include "framework/accel/BvhGpu.h"

#include "framework/accel/BvhGpuLayout.h"
#include "framework/core/Error.h"

#include <algorithm>

namespace shadowlab::bvh {

void BvhGpu::bind(unsigned nodeUnit, unsigned triUnit) const {
    glBindTextureUnit(nodeUnit, nodeTexels.id());
    glBindTextureUnit(triUnit, triTexels.id());
}

BvhGpu uploadBvh(const Bvh& tree, size_t limit, GLbitfield flags, const std::string& owner) {
    const bool own = owner == "bvh_raytrace"; // another plugin's errors say whose tree it is
    checkStorageBlock(own ? "the BVH nodes" : (owner + "'s BVH nodes").c_str(), tree.nodes.size() * sizeof(NodeGpu), limit);
    checkStorageBlock(own ? "the leaf-ordered triangles" : (owner + "'s leaf-ordered BVH triangles").c_str(),
                      tree.triangles.size() * sizeof(glm::vec4), limit);
    if (tree.triIndices.size() >= (size_t(1) << 27))
        throw RuntimeError(owner + ": more than 2^27 triangles cannot be addressed by the BVH traversal stack");
    BvhGpu g;
    g.nodes = GlBuffer::fromVector(tree.nodes, flags);
    g.triangles = GlBuffer::fromVector(tree.triangles, flags);
    g.nodeTexels = makeBufferTexture(g.nodes, GL_RGBA32UI, 16, (owner + " BVH nodes").c_str());
    g.triTexels = makeBufferTexture(g.triangles, GL_RGBA32F, 16, (owner + " BVH triangles").c_str());
    // A correct walk enters each inner node and each leaf at most once (traverse.glsl, bvhTrace).
    g.stepCap = uint32_t(std::min<uint64_t>(uint64_t(tree.nodes.size()) + 2 * uint64_t(tree.leaves) + 1, UINT32_MAX));
    return g;
}

} // namespace shadowlab::bvh
