#version 450
// template: one invocation per pixel casts the reference's shadow rays (origin p + n * offset, one
// per light sample) against every triangle, in the order setScene() uploaded, and stops at the first
// hit. O(pixels × triangles): a correct baseline for small scenes and a starting point to copy.
// It follows the GPU-portability checklist (docs/architecture.md): one dispatch traces the samples
// [uSampleFirst, uSampleEnd) of every pixel (at most samples_per_dispatch), so that no dispatch runs
// into a driver's watchdog at any light.samples; a light with more takes several dispatches, which
// carry each pixel's count in the accumulation image, and the last writes visibility. Every loop is
// bounded by a count (triangles, samples), so nothing here can overflow or run away.
#include "common/statistics.glsl"
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/shadow_ray.glsl"
#include "common/counters.glsl"
#include "template/layout.glsl"
layout(local_size_x = TEMPLATE_GROUP_SIDE, local_size_y = TEMPLATE_GROUP_SIDE) in;

layout(std430, binding = TEMPLATE_ORDER_BINDING) readonly buffer Order { uint order[]; };
layout(std430, binding = TEMPLATE_SAMPLE_BINDING) readonly buffer LightSamples { vec4 lightSamples[]; };
layout(std430, binding = TEMPLATE_COUNTER_BINDING) buffer Counters { uint counters[]; };

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
#if SHADOWLAB_STATISTICS // statistics: compiled out in the timed pass
layout(r32f, binding = 1) writeonly uniform image2D uTests; // debug view: triangle tests per pixel
layout(rg32ui, binding = TEMPLATE_ACCUM_UNIT) uniform uimage2D uAccum; // between dispatches: x unblocked, y tests
#else
layout(r32ui, binding = TEMPLATE_ACCUM_UNIT) uniform uimage2D uAccum;  // between dispatches: unblocked samples
#endif
uniform float uRayOffset;    // world units, the reference's
uniform int uSampleCount;    // light samples (1 for point and spot lights)
uniform int uSampleFirst, uSampleEnd; // the samples this dispatch traces, [first, end)
uniform uint uTriangleCount;

const float kInf = uintBitsToFloat(0x7F800000u);

// Any hit ends the ray; `tests` counts the triangles tested. A loop that stops short of its count
// without a hit was ended from outside (llvmpipe ends a shader invocation's loops after 65,535
// iterations in all: docs/architecture.md, rule 13): counted, and the ray taken as blocked, so the
// pixel is never lit by mistake.
bool occluded(WatertightRay r, inout uint tests) {
    uint i = 0u;
    for (; i < uTriangleCount; ++i) {
        ++tests;
        uint t = order[i];
        if (watertightHit(r, sceneVertex(t, 0u), sceneVertex(t, 1u), sceneVertex(t, 2u))) return true;
    }
    if (i < uTriangleCount) {
        atomicAdd(counters[TEMPLATE_C_CUT_LOOPS], 1u);
        return true;
    }
    return false;
}

void addWide(int lo, uint value) COUNTER_ADD_WIDE(counters, lo, value)

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(uVisibility)))) return;
    bool firstDispatch = uSampleFirst == 0, lastDispatch = uSampleEnd >= uSampleCount;
    vec4 pos = texelFetch(uPosition, px, 0);
    float visibility = 1.0; // background: nothing to shadow (the reference's convention)
    uint tests = 0u, testsAll = 0u; // this dispatch's triangle tests; with the earlier ones'
    if (pos.w >= 0.5) {
        vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
        visibility = 0.0; // not reached by the light (the metrics skip these pixels)
        if (lightReaches(p, n)) {
            vec3 o = watertightOrigin(p, n, uRayOffset); // the reference's, bit for bit
            bool directional = lightIsDirectional();
            int count = directional ? 1 : uSampleCount, end = directional ? 1 : uSampleEnd;
            uint unblocked = 0u; // samples the earlier dispatches found unblocked, then this one's
            if (!firstDispatch) {
                uvec4 a = imageLoad(uAccum, px);
                unblocked = a.x;
                testsAll = a.y; // 0 in the timed pass (R32UI reads y as 0)
            }
            for (int s = uSampleFirst; s < end; ++s) {
                WatertightRay r;
                if (directional) {
                    r = watertightRay(o, -uLightDirection, kInf);
                } else {
                    vec3 d;
                    float tfar;
                    shadowRayTo(o, lightSamples[s].xyz, uRayOffset, d, tfar);
                    if (d == vec3(0.0)) { ++unblocked; continue; } // origin on the sample
                    r = watertightRay(o, d, tfar);
                }
                if (!occluded(r, tests)) ++unblocked;
            }
            testsAll += tests;
            if (lastDispatch) visibility = float(unblocked) / float(count);
            else imageStore(uAccum, px, uvec4(unblocked, testsAll, 0u, 0u));
#if SHADOWLAB_STATISTICS
            if (lastDispatch) atomicAdd(counters[TEMPLATE_C_PIXELS], 1u);
            addWide(TEMPLATE_C_TESTS_LO, tests);
#endif
        }
    }
    if (!lastDispatch) return;
    imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_STATISTICS
    imageStore(uTests, px, vec4(float(testsAll)));
#endif
}
