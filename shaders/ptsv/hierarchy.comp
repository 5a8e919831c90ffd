#version 450
// Hierarchy build, pass one (paper 2.2): one workgroup per tile. Every invocation computes its view
// sample's shadow-ray origin and cluster key; the workgroup finds the tile's distinct clusters in
// shared memory, and one invocation per cluster writes the cluster's bounds (a cluster lies in one
// tile, so no other workgroup touches them) and sets its bit in the level above with one atomicOr.
// reduce.comp then builds the levels above, one node per invocation.
#include "common/light.glsl"
#include "common/scene.glsl"
#include "ptsv/ptsv.glsl"
layout(local_size_x = PTSV_TILE, local_size_y = PTSV_TILE) in;

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
uniform float uRayOffset; // world units: the reference's shadow-ray origin offset along the normal

shared uint sKey[PTSV_TILE * PTSV_TILE];
shared vec3 sQ[PTSV_TILE * PTSV_TILE];
shared uint sClusters, sReceivers;

void main() {
    uint local = gl_LocalInvocationIndex;
    uint tile = gl_WorkGroupID.y * uint(uTilesX) + gl_WorkGroupID.x;
    uint slot = tile * ptsvTileSamples() + local;
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (local == 0u) sClusters = sReceivers = 0u;
    uint key = PTSV_KEY_BACKGROUND;
    vec3 q = vec3(0.0);
    if (all(lessThan(px, uResolution))) {
        vec4 pos = texelFetch(uPosition, px, 0);
        if (pos.w >= 0.5) {
            vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
            key = PTSV_KEY_AWAY;
            if (dot(n, toLight(p)) > 0.0) {
                // The reference's ray origin: the same offset along the same (unnormalised) normal.
                q = p + n * uRayOffset;
                // The key follows the G-buffer point p (in this pixel's frustum); q is at most
                // uRayOffset away, which the implicit-bounds test allows for.
                float depth = -(uView * vec4(p, 1.0)).z;
                key = ptsvKey(uvec3(gl_WorkGroupID.xy, uint(ptsvSlice(depth))));
            }
        }
    }
    ptsvKeys[slot] = key;
    ptsvSamples[slot] = vec4(q, 1.0);
    ptsvShadow[slot] = 0u;
#if PTSV_HEAT_MAP
    ptsvHeat[slot] = 0u;
#endif
    sKey[local] = key;
    sQ[local] = q;
    barrier();
    if (key < PTSV_KEY_AWAY) {
#if SHADOWLAB_INSTRUMENTATION
        atomicAdd(sReceivers, 1u);
#endif
        // The first sample of each cluster in the tile speaks for it.
        bool leader = true;
        for (uint j = 0u; j < local && leader; ++j) leader = sKey[j] != key;
        if (leader) {
#if SHADOWLAB_INSTRUMENTATION
            atomicAdd(sClusters, 1u);
#endif
            int leafDepth = uLevels;
            atomicOr(ptsvMasks[uMaskOffset[leafDepth - 1] + (key >> 5u)], 1u << (key & 31u));
#if PTSV_EXPLICIT_BOUNDS
            vec3 bmin = q, bmax = q;
            for (uint j = local + 1u; j < ptsvTileSamples(); ++j)
                if (sKey[j] == key) {
                    bmin = min(bmin, sQ[j]);
                    bmax = max(bmax, sQ[j]);
                }
            uint b = 6u * (uNodeOffset[leafDepth] + key);
            ptsvBounds[b] = bmin.x; ptsvBounds[b + 1u] = bmin.y; ptsvBounds[b + 2u] = bmin.z;
            ptsvBounds[b + 3u] = bmax.x; ptsvBounds[b + 4u] = bmax.y; ptsvBounds[b + 5u] = bmax.z;
#endif
        }
    }
#if SHADOWLAB_INSTRUMENTATION
    barrier();
    if (local == 0u) {
        if (sClusters != 0u) atomicAdd(ptsvCounters[PTSV_C_CLUSTERS], sClusters);
        if (sReceivers != 0u) atomicAdd(ptsvCounters[PTSV_C_RECEIVERS], sReceivers);
    }
#endif
}
