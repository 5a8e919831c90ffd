#include "algorithms/ptsv/PtsvLayout.h"

#include "framework/core/Error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace shadowlab::ptsv {
namespace {

int bitsFor(int count) { // smallest b with 2^b >= count
    int b = 0;
    while ((1 << b) < count) ++b;
    return b;
}

} // namespace

KeyLayout makeKeyLayout(glm::ivec2 resolution, int tile, float fovYDeg, float nearPlane, float farPlane,
                        int maxKeyBits) {
    KeyLayout l;
    l.tile = tile;
    l.tilesX = (resolution.x + tile - 1) / tile;
    l.tilesY = (resolution.y + tile - 1) / tile;
    // Olsson et al. 2012: slices grow with depth so that a cluster is about as deep as it is wide.
    const double tanHalf = std::tan(glm::radians(double(fovYDeg)) * 0.5);
    const double sliceLog = std::log1p(2.0 * tanHalf / double(l.tilesY));
    const double ratio = std::max(double(farPlane) / double(nearPlane), 1.0 + 1e-6);
    l.bitsX = bitsFor(l.tilesX);
    l.bitsY = bitsFor(l.tilesY);
    const int limit = std::min(maxKeyBits, PTSV_MAX_KEY_BITS);
    // The full tree's bounds take 24 bytes per possible cluster: past the limit, slices twice as deep
    // (clusters twice as deep as wide) cost one z bit, which is cheaper than running out of memory.
    for (;;) {
        l.sliceLog = float(std::ldexp(sliceLog, l.merged));
        l.slices = std::max(1, int(std::ceil(std::log(ratio) / double(l.sliceLog))));
        l.bitsZ = bitsFor(l.slices);
        l.keyBits = l.bitsX + l.bitsY + l.bitsZ;
        if (l.keyBits <= limit || l.bitsZ == 0) break;
        ++l.merged;
    }
    if (l.keyBits > limit)
        throw RuntimeError("ptsv: " + std::to_string(resolution.x) + "x" + std::to_string(resolution.y) + " needs " +
                           std::to_string(l.keyBits) +
                           "-bit cluster keys even with a single depth slice (at most " + std::to_string(limit) +
                           "): use a larger tile_size or max_key_bits");
    l.levels = std::max(1, (l.keyBits + 4) / 5);
    // Morton order from the least significant bit: one bit of each coordinate in turn while it has
    // any left, so low levels split x, y and z alike (nodes stay roughly cubic) and the surplus of
    // the longest coordinate (usually z) ends up at the top of the tree.
    int next = 0;
    const int bits[3] = {l.bitsX, l.bitsY, l.bitsZ};
    for (int r = 0; r < 32; ++r)
        for (uint32_t dim = 0; dim < 3; ++dim)
            if (r < bits[dim]) l.keyBit[size_t(next++)] = dim | (uint32_t(r) << 2);
    uint32_t words = 0, nodes = 0;
    for (int d = 0; d < l.levels; ++d) {
        l.maskOffset[size_t(d)] = words;
        words += uint32_t(l.nodesAt(d));
    }
    l.maskOffset[size_t(l.levels)] = words;
    l.maskWords = words;
    for (int d = 1; d <= l.levels; ++d) {
        l.nodeOffset[size_t(d)] = nodes;
        nodes += uint32_t(l.nodesAt(d));
    }
    l.nodeOffset[size_t(l.levels) + 1] = nodes;
    l.boundsNodes = nodes;
    return l;
}

size_t KeyLayout::nodesAt(int depth) const {
    const int shift = keyBits - 5 * (levels - depth); // bits of a node id at this depth
    return shift <= 0 ? 1 : size_t(1) << shift;
}

uint32_t KeyLayout::key(glm::uvec3 c) const {
    uint32_t k = 0;
    for (int i = 0; i < keyBits; ++i) {
        const uint32_t e = keyBit[size_t(i)];
        k |= ((c[int(e & 3u)] >> (e >> 2)) & 1u) << i;
    }
    return k;
}

glm::uvec3 KeyLayout::coordinate(uint32_t nodeId, int depth) const {
    glm::uvec3 c(0);
    const int low = 5 * (levels - depth);
    for (int i = std::max(low, 0); i < keyBits; ++i) {
        const uint32_t e = keyBit[size_t(i)];
        c[int(e & 3u)] |= ((nodeId >> (i - low)) & 1u) << (e >> 2);
    }
    return c;
}

int depthSlice(const KeyLayout& l, float viewDepth, float nearPlane) {
    const float z = std::floor(std::log(viewDepth / nearPlane) / l.sliceLog);
    return int(std::clamp(z, 0.0f, float(l.slices - 1)));
}

} // namespace shadowlab::ptsv
