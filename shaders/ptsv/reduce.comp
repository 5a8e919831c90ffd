#version 450
// Hierarchy build, pass two (paper 2.2), run once per level from the leaves' parents upwards: one
// invocation per node of depth uDepth. A node whose child mask is not empty exists: it takes the
// union of its children's bounds (explicit bounds) and sets its own bit in its parent's mask. The
// children were completed by the previous dispatch, so only one atomicOr per node remains.
#include "common/light.glsl"
#include "common/scene.glsl"
#include "ptsv/ptsv.glsl"
layout(local_size_x = 64) in;

uniform int uDepth;             // 1 .. levels - 1
uniform uint uNodeCount;        // nodes at uDepth
uniform uint uInvocationsPerRow; // 2D dispatch past 65535 groups

void main() {
    uint id = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (id >= uNodeCount) return;
    uint mask = ptsvMasks[uMaskOffset[uDepth] + id];
    if (mask == 0u) return;
    atomicOr(ptsvMasks[uMaskOffset[uDepth - 1] + (id >> 5u)], 1u << (id & 31u));
#if PTSV_EXPLICIT_BOUNDS
    vec3 bmin = vec3(3.0e38), bmax = vec3(-3.0e38);
    uint childBase = uNodeOffset[uDepth + 1] + id * 32u;
    while (mask != 0u) {
        int c = findLSB(mask);
        mask &= mask - 1u;
        uint b = 6u * (childBase + uint(c));
        bmin = min(bmin, vec3(ptsvBounds[b], ptsvBounds[b + 1u], ptsvBounds[b + 2u]));
        bmax = max(bmax, vec3(ptsvBounds[b + 3u], ptsvBounds[b + 4u], ptsvBounds[b + 5u]));
    }
    uint b = 6u * (uNodeOffset[uDepth] + id);
    ptsvBounds[b] = bmin.x; ptsvBounds[b + 1u] = bmin.y; ptsvBounds[b + 2u] = bmin.z;
    ptsvBounds[b + 3u] = bmax.x; ptsvBounds[b + 4u] = bmax.y; ptsvBounds[b + 5u] = bmax.z;
#endif
}
