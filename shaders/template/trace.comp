#version 450
// template: one invocation per pixel casts the reference's shadow rays (origin p + n * offset, one
// per light sample) against every triangle, in the order setScene() uploaded, and stops at the first
// hit. O(pixels × triangles): a correct baseline for small scenes and a starting point to copy.
#include "common/instrumentation.glsl"
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/watertight.glsl"
#include "common/counters.glsl"
#include "template/layout.glsl"
layout(local_size_x = TEMPLATE_GROUP_SIDE, local_size_y = TEMPLATE_GROUP_SIDE) in;

layout(std430, binding = TEMPLATE_ORDER_BINDING) readonly buffer Order { uint order[]; };
layout(std430, binding = TEMPLATE_SAMPLE_BINDING) readonly buffer LightSamples { vec4 lightSamples[]; };
layout(std430, binding = TEMPLATE_COUNTER_BINDING) buffer Counters { uint counters[]; };

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
#if SHADOWLAB_INSTRUMENTATION // statistics: compiled out in timing mode
layout(r32f, binding = 1) writeonly uniform image2D uTests; // debug view: triangle tests per pixel
#endif
uniform float uRayOffset;    // world units, the reference's
uniform int uSampleCount;    // light samples (1 for point and spot lights)
uniform uint uTriangleCount;

const float kInf = uintBitsToFloat(0x7F800000u);

// Any hit ends the ray; `tests` counts the triangles tested.
bool occluded(WatertightRay r, inout uint tests) {
    for (uint i = 0u; i < uTriangleCount; ++i) {
        ++tests;
        uint t = order[i];
        if (watertightHit(r, sceneVertex(t, 0u), sceneVertex(t, 1u), sceneVertex(t, 2u))) return true;
    }
    return false;
}

void addWide(int lo, uint value) COUNTER_ADD_WIDE(counters, lo, value)

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(uVisibility)))) return;
    vec4 pos = texelFetch(uPosition, px, 0);
    float visibility = 1.0; // background: nothing to shadow (the reference's convention)
    uint tests = 0u;
    if (pos.w >= 0.5) {
        vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
        visibility = 0.0; // not reached by the light (the metrics skip these pixels)
        if (lightIlluminates(p) && dot(n, toLight(p)) > 0.0) {
            vec3 o = p + n * uRayOffset;
            int count = lightIsDirectional() ? 1 : uSampleCount;
            float unblocked = 0.0;
            for (int s = 0; s < count; ++s) {
                WatertightRay r;
                if (lightIsDirectional()) {
                    r = watertightRay(o, -uLightDirection, kInf);
                } else {
                    vec3 d = lightSamples[s].xyz - o;
                    float dist = length(d);
                    if (!(dist > 0.0)) { unblocked += 1.0; continue; } // origin on the sample
                    r = watertightRay(o, d / dist, max(0.0, dist - uRayOffset));
                }
                if (!occluded(r, tests)) unblocked += 1.0;
            }
            visibility = unblocked / float(count);
#if SHADOWLAB_INSTRUMENTATION
            atomicAdd(counters[TEMPLATE_C_PIXELS], 1u);
            addWide(TEMPLATE_C_TESTS_LO, tests);
#endif
        }
    }
    imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_INSTRUMENTATION
    imageStore(uTests, px, vec4(float(tests)));
#endif
}
