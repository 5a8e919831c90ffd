#version 450
// shadow_volumes: how many volumes hold the eye, for the resolve pass's check (volume.frag): the
// triangles (those that cast a volume) that the segment from the eye to the light crosses, by the
// reference's watertight test, every one of them (the count is all the hits, not the first). Triangles
// in ranges of SV_EYE_RANGE over dispatches, every SV_EYE_LANES-th one per invocation, so that no
// invocation loops more than 8,192 times (llvmpipe's loop limit, a GPU's watchdog); a loop cut short is counted.
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/shadow_ray.glsl"
#include "shadow_volumes/layout.glsl"
layout(local_size_x = SV_EYE_LANES) in;
layout(std430, binding = SV_FACING_BINDING) readonly buffer Facing { int facing[]; };
layout(std430, binding = SV_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform vec3 uEye;
uniform uint uFirst, uEnd;

void main() {
    WatertightRay r = shadowRayToLight(uEye, 0.0);
    uint t = uFirst + gl_LocalInvocationIndex, inside = 0u, steps = 0u;
    for (; t < uEnd; t += uint(SV_EYE_LANES)) {
        ++steps;
        if (facing[t] != 0 && watertightHit(r, sceneVertex(t, 0u), sceneVertex(t, 1u), sceneVertex(t, 2u))) ++inside;
    }
    if (t < uEnd) atomicAdd(counters[SV_C_CUT_LOOPS], 1u);
    if (inside != 0u) atomicAdd(counters[SV_C_EYE], inside);
}
