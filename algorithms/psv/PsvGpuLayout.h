#pragma once
// Host mirror of the PSV GPU structures. The constants live once, in shaders/psv/layout.glsl
// (#defines only, valid C++ and GLSL); the node struct is mirrored from shaders/psv/tree.glsl.
#include "framework/core/CheckedMath.h"
#include "shaders/psv/layout.glsl"

#include <cstddef>
#include <cstdint>

namespace shadowlab::psv {

/// One TOP tree node, std430 (see PsvNode in shaders/psv/tree.glsl).
struct NodeGpu {
    float plane[4];      ///< unit normal, offset; the shadow frustum's inside is negative
    uint32_t pos;        ///< positive child, 0 = empty leaf
    uint32_t inter;      ///< intersection child
    uint32_t wedgeOrNeg; ///< shadow plane: float bits of the wedge; capping plane: negative child
    uint32_t minDepth;   ///< capping plane: float bits of the subtree's smallest light depth
};
static_assert(sizeof(NodeGpu) == PSV_NODE_BYTES, "PsvNode is 32 bytes in std430");

constexpr size_t kCounterBytes = PSV_COUNTER_WORDS * sizeof(uint32_t);
static_assert(kCounterBytes == 96, "memory_bytes = 128 (n + 1) relies on a 96-byte counter block");

/// Nodes for n triangles: the sentinel (root pointer) plus four per triangle (kSaturated past size_t).
constexpr size_t nodeCount(size_t triangles) { return saturatingSum({saturatingMul(PSV_NODES_PER_TRIANGLE, triangles), 1}); }
/// GPU bytes PSV holds for n triangles: 32 (4n + 1) + 96 = 128 (n + 1), the paper's figure
/// (kSaturated past size_t).
constexpr size_t memoryBytes(size_t triangles) {
    return saturatingSum({saturatingMul(nodeCount(triangles), PSV_NODE_BYTES), kCounterBytes});
}
static_assert(memoryBytes(1000) == 128 * 1001);
static_assert(memoryBytes(SIZE_MAX / 4) == kSaturated, "a size past 64 bits saturates instead of wrapping");

} // namespace shadowlab::psv
