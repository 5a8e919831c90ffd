#pragma once
// The view-sample cluster hierarchy's shape, derived from the resolution, the tile size and the
// camera's field of view and near/far ratio (nothing is fixed to the paper's 1024²), plus the
// host mirror of the GPU constants (shaders/ptsv/layout.glsl, included below, holds them once).
#include "shaders/ptsv/layout.glsl"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <cstdint>

namespace shadowlab::ptsv {

/// Where every bit of a cluster key comes from, and where every level of the tree lives.
struct KeyLayout {
    int tile = 8;                ///< tile width and height, pixels
    int tilesX = 0, tilesY = 0;  ///< tiles covering the image
    int slices = 0;              ///< exponential depth slices between near and far
    float sliceLog = 0;          ///< log(1 + 2 tan(fovY / 2) / tilesY) × 2^merged: depth ratio of one slice, as a log
    int merged = 0;              ///< times slices were merged in pairs to fit maxKeyBits
    int bitsX = 0, bitsY = 0, bitsZ = 0;
    int keyBits = 0;             ///< bitsX + bitsY + bitsZ
    int levels = 0;              ///< levels of child masks: ceil(keyBits / 5); leaves (clusters) lie one below
    /// Key bit i (from the least significant) is bit (entry >> 2) of coordinate (entry & 3): x, y, z.
    std::array<uint32_t, 32> keyBit{};
    std::array<uint32_t, PTSV_MAX_LEVELS + 1> maskOffset{}; ///< first mask word of depth d (0 = root)
    std::array<uint32_t, PTSV_MAX_LEVELS + 2> nodeOffset{}; ///< first bounds slot of depth d (1 .. levels)
    size_t maskWords = 0;        ///< child-mask words of all levels
    size_t boundsNodes = 0;      ///< nodes below the root (bounds slots)

    /// Nodes at depth d (0 = root, levels = leaf clusters).
    size_t nodesAt(int depth) const;
    /// The cluster key of cluster coordinate c (x tile, y tile, z slice), as the shader computes it.
    uint32_t key(glm::uvec3 c) const;
    /// The coordinate a key (or node prefix at `depth`) was built from; low bits of a prefix are 0.
    glm::uvec3 coordinate(uint32_t nodeId, int depth) const;
};

/// When the key would need more than `maxKeyBits` bits, depth slices are merged in pairs (z loses a
/// bit) until it fits, so the full tree's memory stays bounded; throws RuntimeError when even no z
/// bit at all cannot fit.
KeyLayout makeKeyLayout(glm::ivec2 resolution, int tile, float fovYDeg, float nearPlane, float farPlane,
                        int maxKeyBits = PTSV_MAX_KEY_BITS);

/// Slice of a view depth, as the hierarchy shader computes it (clamped to [0, slices - 1]).
int depthSlice(const KeyLayout& l, float viewDepth, float nearPlane);

} // namespace shadowlab::ptsv
