#version 450
// shadow_volumes: the close calls decided by the reference's own ray (common/shadow_ray.glsl, the
// watertight test) against every triangle. One workgroup per listed pixel; its SV_CLOSE_LANES
// invocations take every SV_CLOSE_LANES-th triangle of this dispatch's range [uFirst, uEnd), so
// that no invocation loops more than SV_CLOSE_RANGE / SV_CLOSE_LANES times: llvmpipe silently ends
// the loops of a shader invocation after 65,535 iterations in all (its gallivm loop limiter), and a
// GPU driver kills a long dispatch. Ranges run as successive dispatches (the host's loop); a pixel
// found blocked skips the later ones, and the last writes the visibility. A lane whose loop ended
// short of its range without a hit was cut off: it is counted (loop_capped_pixels) and the pixel
// written shadowed, never lit by mistake.
#include "common/instrumentation.glsl"
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/shadow_ray.glsl"
#include "common/counters.glsl"
#include "shadow_volumes/layout.glsl"
layout(local_size_x = SV_CLOSE_LANES) in;
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
layout(std430, binding = SV_CLOSE_LIST_BINDING) readonly buffer CloseList { uint closeCount; uint closeList[]; };
layout(std430, binding = SV_CLOSE_BLOCKED_BINDING) buffer CloseBlocked { uint closeBlocked[]; };
layout(std430, binding = SV_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform float uRayOffset;
uniform uint uFirst, uEnd; // this dispatch's triangles
uniform int uLast;         // 1 on the last range: write the visibility

shared uint groupBlocked;

void addWide(int lo, uint value) COUNTER_ADD_WIDE(counters, lo, value)

void main() {
    uint entry = gl_WorkGroupID.y * uint(SV_CLOSE_ROW) + gl_WorkGroupID.x;
    if (entry >= closeCount) return; // the whole workgroup: uniform
    if (gl_LocalInvocationIndex == 0u) groupBlocked = closeBlocked[entry];
    barrier();
    uint blocked = groupBlocked;
    if (blocked == 0u) {
        uint word = closeList[entry];
        ivec2 px = ivec2(int(word & 0xFFFFu), int(word >> 16));
        vec3 p = texelFetch(uPosition, px, 0).xyz, n = texelFetch(uNormal, px, 0).xyz;
        WatertightRay r = shadowRayToLight(p + n * uRayOffset, uRayOffset);
        uint t = uFirst + gl_LocalInvocationIndex, tests = 0u;
        bool hit = false;
        for (; t < uEnd; t += uint(SV_CLOSE_LANES)) {
            ++tests;
            if (watertightHit(r, sceneVertex(t, 0u), sceneVertex(t, 1u), sceneVertex(t, 2u))) { hit = true; break; }
        }
        if (!hit && t < uEnd) { // the loop was ended from outside: count it, cast the pixel shadowed
            atomicAdd(counters[SV_C_CUT_LOOPS], 1u);
            hit = true;
        }
        if (hit) atomicOr(groupBlocked, 1u);
#if SHADOWLAB_INSTRUMENTATION
        addWide(SV_C_CLOSE_TESTS_LO, tests);
#endif
    }
    barrier();
    if (gl_LocalInvocationIndex != 0u) return;
    blocked = groupBlocked;
    closeBlocked[entry] = blocked;
    if (uLast != 0) {
        uint word = closeList[entry];
        imageStore(uVisibility, ivec2(int(word & 0xFFFFu), int(word >> 16)), vec4(blocked != 0u ? 0.0 : 1.0));
    }
}
