#version 450
// Hierarchy build, pass one b: one invocation per view sample, reading hierarchy.comp's keys and
// samples through buffer textures. The first sample of each cluster in its tile speaks for the
// cluster: it writes the cluster's bounds (a cluster lies in one tile, so no other invocation
// writes them, and no atomic is needed) and sets the cluster's bit in the level above with one
// atomicOr. No shared memory and no barrier (see hierarchy.comp).
#include "common/light.glsl"
#include "common/scene.glsl"
#define PTSV_TEXEL_READS 1
#include "ptsv/ptsv.glsl"
layout(local_size_x = PTSV_TILE * PTSV_TILE) in;

void main() {
    uint tile = gl_WorkGroupID.y * uint(uTilesX) + gl_WorkGroupID.x;
    uint first = tile * ptsvTileSamples(), local = gl_LocalInvocationIndex;
    uint key = ptsvKeyAt(first + local);
    if (key >= PTSV_KEY_AWAY) return;
    bool leader = true;
    for (uint j = 0u; j < local && leader; ++j) leader = ptsvKeyAt(first + j) != key;
    if (!leader) return;
    int leafDepth = uLevels;
    atomicOr(ptsvMasks[uMaskOffset[leafDepth - 1] + (key >> 5u)], 1u << (key & 31u));
#if PTSV_EXPLICIT_BOUNDS || SHADOWLAB_STATISTICS
    vec3 q = ptsvSampleAt(first + local), bmin = q, bmax = q;
    uint samples = 1u;
    for (uint j = local + 1u; j < ptsvTileSamples(); ++j)
        if (ptsvKeyAt(first + j) == key) {
            vec3 o = ptsvSampleAt(first + j);
            bmin = min(bmin, o);
            bmax = max(bmax, o);
            ++samples;
        }
#endif
#if PTSV_EXPLICIT_BOUNDS
    uint b = 6u * (uNodeOffset[leafDepth] + key);
    ptsvBounds[b] = bmin.x; ptsvBounds[b + 1u] = bmin.y; ptsvBounds[b + 2u] = bmin.z;
    ptsvBounds[b + 3u] = bmax.x; ptsvBounds[b + 4u] = bmax.y; ptsvBounds[b + 5u] = bmax.z;
#endif
#if SHADOWLAB_STATISTICS
    atomicAdd(ptsvCounters[PTSV_C_CLUSTERS], 1u);
    atomicAdd(ptsvCounters[PTSV_C_RECEIVERS], samples);
#endif
}
