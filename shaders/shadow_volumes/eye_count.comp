#version 450
// shadow_volumes: how many volumes hold the eye, for the resolve pass's check (volume.frag): the
// triangles (those that cast a volume) that the segment from the eye to the light crosses, by the
// reference's watertight test. Triangles in ranges over dispatches, every SV_CLOSE_LANES-th one
// per invocation, as close_rays.comp and for the same reasons; a loop cut short is counted.
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/shadow_ray.glsl"
#include "shadow_volumes/layout.glsl"
layout(local_size_x = SV_CLOSE_LANES) in;
layout(std430, binding = SV_FACING_BINDING) readonly buffer Facing { int facing[]; };
layout(std430, binding = SV_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform vec3 uEye;
uniform uint uFirst, uEnd;

void main() {
    WatertightRay r = shadowRayToLight(uEye, 0.0);
    uint t = uFirst + gl_LocalInvocationIndex, inside = 0u, steps = 0u;
    for (; t < uEnd; t += uint(SV_CLOSE_LANES)) {
        ++steps;
        if (facing[t] != 0 && watertightHit(r, sceneVertex(t, 0u), sceneVertex(t, 1u), sceneVertex(t, 2u))) ++inside;
    }
    if (t < uEnd) atomicAdd(counters[SV_C_CUT_LOOPS], 1u);
    if (inside != 0u) atomicAdd(counters[SV_C_EYE], inside);
}
