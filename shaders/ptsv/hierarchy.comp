#version 450
// Hierarchy build, pass one (paper 2.2): one invocation per view sample, one workgroup per tile
// (so a sample's slot is its tile's, tile-major). Every invocation computes its sample's
// shadow-ray origin and cluster key and clears its shadow mark. clusters.comp then finds the
// tile's distinct clusters and reduce.comp builds the levels above. No shared memory and no
// barrier: a barrier makes llvmpipe run the workgroups as coroutines.
#include "common/light.glsl"
#include "common/watertight.glsl"
#include "common/scene.glsl"
#include "ptsv/ptsv.glsl"
layout(local_size_x = PTSV_TILE, local_size_y = PTSV_TILE) in;

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
uniform float uRayOffset; // world units: the reference's shadow-ray origin offset along the normal

void main() {
    uint tile = gl_WorkGroupID.y * uint(uTilesX) + gl_WorkGroupID.x;
    uint slot = tile * ptsvTileSamples() + gl_LocalInvocationIndex;
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    uint key = PTSV_KEY_BACKGROUND;
    vec3 q = vec3(0.0);
    if (all(lessThan(px, uResolution))) {
        vec4 pos = texelFetch(uPosition, px, 0);
        if (pos.w >= 0.5) {
            vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
            key = PTSV_KEY_AWAY;
            // Facing the light and inside a spot's cone, decided as the reference decides it (Light::reaches).
            if (lightReaches(p, n)) {
                // The reference's ray origin: the same offset along the same (unnormalised) normal.
                q = watertightOrigin(p, n, uRayOffset);
                // The key follows the G-buffer point p (in this pixel's frustum); q is at most
                // uRayOffset away, which the implicit-bounds test allows for.
                float depth = -(uView * vec4(p, 1.0)).z;
                key = ptsvKey(uvec3(gl_WorkGroupID.xy, uint(ptsvSlice(depth))));
            }
        }
    }
    ptsvSamples[slot] = uvec4(floatBitsToUint(q), key);
    ptsvShadow[slot] = 0u;
#if PTSV_HEAT_MAP
    ptsvHeat[slot] = 0u;
#endif
}
