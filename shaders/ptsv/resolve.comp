#version 450
// Final pass (paper 2, "Merge TA"): one invocation per view sample writes its visibility. A sample
// is shadowed when a test-and-set marked it, or when any node on its path from the root has lost
// its bit in its parent's mask: that node was trivially accepted by some triangle's volume.
#include "common/light.glsl"
#include "common/scene.glsl"
#define PTSV_TEXEL_READS 1
#include "ptsv/ptsv.glsl"
layout(local_size_x = PTSV_TILE, local_size_y = PTSV_TILE) in;

layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
layout(r32f, binding = 1) writeonly uniform image2D uHeat; // test-and-set operations per pixel

shared uint sShadowed;

void main() {
    if (gl_LocalInvocationIndex == 0u) sShadowed = 0u;
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    uint tile = gl_WorkGroupID.y * uint(uTilesX) + gl_WorkGroupID.x;
    uint slot = tile * ptsvTileSamples() + gl_LocalInvocationIndex;
    if (all(lessThan(px, uResolution))) {
        uint key = ptsvKeyAt(slot);
        float visibility = 1.0; // background: nothing to shadow (the reference's convention)
        if (key == PTSV_KEY_AWAY) {
            visibility = 0.0;
        } else if (key != PTSV_KEY_BACKGROUND) {
            bool shadowed = ptsvShadowAt(slot) != 0u;
            for (int d = 0; d < uLevels && !shadowed; ++d) {
                uint word = ptsvMaskAt(uMaskOffset[d] + (key >> uint(5 * (uLevels - d))));
                shadowed = ((word >> ((key >> uint(5 * (uLevels - 1 - d))) & 31u)) & 1u) == 0u;
            }
            visibility = shadowed ? 0.0 : 1.0;
#if SHADOWLAB_STATISTICS
            if (shadowed) atomicAdd(sShadowed, 1u);
#endif
        }
        imageStore(uVisibility, px, vec4(visibility));
#if PTSV_HEAT_MAP
        imageStore(uHeat, px, vec4(float(ptsvHeat[slot])));
#endif
    }
#if SHADOWLAB_STATISTICS
    barrier();
    if (gl_LocalInvocationIndex == 0u && sShadowed != 0u) atomicAdd(ptsvCounters[PTSV_C_SHADOWED], sShadowed);
#endif
}
