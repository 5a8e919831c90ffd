#version 450
// bvh_raytrace: one invocation per pixel traces the reference's shadow rays (EmbreeTracer.h: origin
// p + n * offset, unit direction to each light sample, tfar = distance - offset) through a BVH built
// on the CPU: Aila & Laine's while-while traversal (inner nodes until a leaf is found, then the
// leaves), near child first, a fixed stack whose overflow is reported, any-hit early exit.
// Triangles are read in leaf order (no index indirection). Visibility = fraction of unblocked samples.
// One dispatch traces the samples [uSampleFirst, uSampleEnd) of every pixel (at most
// samples_per_dispatch of them, so that no dispatch runs into a GPU driver's watchdog); a light with
// more samples takes several dispatches, which carry each pixel's state in the accumulation image
// (layout.glsl), and the last one writes visibility: the image a single dispatch would write.
#include "bvh_raytrace/layout.glsl"
#define SIMD_PROBE_SECTIONS BVH_SIMD_SECTIONS
#include "common/simd_probe.glsl"
#include "common/statistics.glsl"
#include "common/light.glsl"
#include "common/counters.glsl"
#include "common/shadow_ray.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

#define BVH_TICK_NODE() SIMD_TICK(BVH_SIMD_NODE)
#define BVH_TICK_TRI() SIMD_TICK(BVH_SIMD_TRI)
#define BVH_TRAVERSE_NODE_UNIT BVH_NODE_UNIT
#define BVH_TRAVERSE_TRI_UNIT BVH_TRI_UNIT
#include "common/bvh_traverse.glsl"
layout(std430, binding = BVH_SAMPLE_BINDING) readonly buffer LightSamples { vec4 lightSamples[]; };
layout(std430, binding = BVH_COUNTER_BINDING) buffer BvhCounters { uint bvhCounters[]; };

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
#if SHADOWLAB_STATISTICS
layout(r32f, binding = 1) writeonly uniform image2D uNodesVisited; // debug heat map: nodes per pixel
layout(r32f, binding = 2) writeonly uniform image2D uOverflow;     // 1 where the pixel was written shadowed for a failed ray
layout(rg32ui, binding = BVH_ACCUM_UNIT) uniform uimage2D uAccum;   // between dispatches: x state (layout.glsl), y nodes visited
#else
layout(r32ui, binding = BVH_ACCUM_UNIT) uniform uimage2D uAccum;    // between dispatches: the state (layout.glsl)
#endif
uniform float uRayOffset; // world units, the reference's
uniform int uSampleCount; // entries of lightSamples (1 for point, spot and directional lights)
uniform int uSampleFirst, uSampleEnd; // the samples this dispatch traces, [first, end)

const float kInf = uintBitsToFloat(0x7F800000u);


#if SHADOWLAB_STATISTICS
shared uint sPixels, sRays, sVisited, sVisitedMax, sTested, sOverflowRays, sOverflowPixels, sTruncated, sCapped;

void addWide(int lo, uint value) COUNTER_ADD_WIDE(bvhCounters, lo, value)
#endif

void main() {
#if SHADOWLAB_STATISTICS
    if (gl_LocalInvocationIndex == 0u) sPixels = sRays = sVisited = sVisitedMax = sTested = sOverflowRays = sOverflowPixels = sTruncated = sCapped = 0u;
    SIMD_PROBE_ENTER();
    barrier();
#endif
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
#if SHADOWLAB_FAULT_BVH_CYCLE
    gFaultPixel = ((px.x + px.y) & 1) == 0;
#endif
    bool firstDispatch = uSampleFirst == 0, lastDispatch = uSampleEnd >= uSampleCount;
    if (all(lessThan(px, imageSize(uVisibility)))) {
        vec4 pos = texelFetch(uPosition, px, 0);
        float visibility = 1.0; // background: nothing to shadow (the reference's convention)
        uint visitedAll = 0u;   // nodes fetched by this pixel's rays, this dispatch and the earlier ones
        bool failed = false;    // a ray could not be traced to its end: the pixel is written shadowed
        if (pos.w >= 0.5) {
            vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
            visibility = 0.0; // unlit before occlusion (the reference writes 0; metrics skip it)
            if (lightReaches(p, n)) {
                vec3 o = watertightOrigin(p, n, uRayOffset); // the reference's, bit for bit
                bool directional = uLightType == LIGHT_DIRECTIONAL;
                int count = directional ? 1 : uSampleCount, first = uSampleFirst, end = directional ? 1 : uSampleEnd;
                // The state the earlier dispatches left: unblocked samples and failure flags.
                uint state = 0u;
                if (!firstDispatch) {
                    uvec4 a = imageLoad(uAccum, px);
                    state = a.x;
#if SHADOWLAB_STATISTICS
                    visitedAll = a.y;
#endif
                }
                uint unblocked = 0u, visited = 0u, tested = 0u, maxVisited = 0u, done = 0u, overflowRays = 0u, cappedRays = 0u;
                for (int s = first; s < end; ++s) {
                    BvhRay r;
                    if (directional) {
                        r = bvhMakeRay(o, -uLightDirection, kInf);
                    } else {
                        vec3 d;
                        float tfar;
                        shadowRayTo(o, lightSamples[s].xyz, uRayOffset, d, tfar);
                        if (d == vec3(0.0)) { ++unblocked; ++done; continue; } // origin on the sample
                        r = bvhMakeRay(o, d, tfar);
                    }
                    BvhTrace t = bvhTrace(r);
                    visited += t.visited;
                    tested += t.tested;
                    maxVisited = max(maxVisited, t.visited);
                    if (t.overflow) ++overflowRays;
                    else if (t.capped) ++cappedRays;
                    else if (!t.occluded) ++unblocked;
                    ++done;
                }
                visitedAll += visited;
                // Fewer samples done than taken: llvmpipe's code generator (gallivm) stops the loops of
                // an invocation after a fixed budget of iterations, silently. Treated like an overflow.
                if (done != uint(end - first)) state |= BVH_ACC_TRUNCATED;
                // An overflowed or capped ray counts as blocked, and its pixel is written fully
                // shadowed, so a stack too small or a walk that cannot end shows as dark pixels and in
                // overflowCount(), never as light.
                if (overflowRays > 0u) state |= BVH_ACC_OVERFLOW;
                if (cappedRays > 0u) state |= BVH_ACC_CAPPED;
                state += unblocked;
                bool truncated = (state & BVH_ACC_TRUNCATED) != 0u, capped = (state & BVH_ACC_CAPPED) != 0u;
                failed = (state & ~BVH_ACC_COUNT_MASK) != 0u;
                if (lastDispatch) visibility = failed ? 0.0 : float(state & BVH_ACC_COUNT_MASK) / float(count);
                else imageStore(uAccum, px, uvec4(state, visitedAll, 0u, 0u));
                // Per ray: every dispatch adds its own; per pixel: the last one, from the state.
#if SHADOWLAB_STATISTICS
                atomicAdd(sRays, uint(end - first));
                atomicAdd(sVisited, visited);
                atomicMax(sVisitedMax, maxVisited);
                atomicAdd(sTested, tested);
                if (overflowRays > 0u) atomicAdd(sOverflowRays, overflowRays);
                if (lastDispatch) {
                    atomicAdd(sPixels, 1u);
                    if (truncated) atomicAdd(sTruncated, 1u);
                    else if (capped) atomicAdd(sCapped, 1u);
                    else if (failed) atomicAdd(sOverflowPixels, 1u);
                }
#else
                // The timed pass still counts every overflowed, capped or truncated pixel.
                if (overflowRays > 0u) atomicAdd(bvhCounters[BVH_C_OVERFLOW_RAYS], overflowRays);
                if (lastDispatch && failed) {
                    if (truncated) atomicAdd(bvhCounters[BVH_C_TRUNCATED_PIXELS], 1u);
                    else if (capped) atomicAdd(bvhCounters[BVH_C_CAPPED_PIXELS], 1u);
                    else atomicAdd(bvhCounters[BVH_C_OVERFLOW_PIXELS], 1u);
                }
#endif
            }
        }
        if (lastDispatch) {
            imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_STATISTICS
            imageStore(uNodesVisited, px, vec4(float(visitedAll)));
            imageStore(uOverflow, px, vec4(failed ? 1.0 : 0.0));
#endif
        }
    }
#if SHADOWLAB_STATISTICS
    barrier();
    if (gl_LocalInvocationIndex == 0u && sRays != 0u) {
        if (sPixels != 0u) atomicAdd(bvhCounters[BVH_C_PIXELS], sPixels);
        addWide(BVH_C_RAYS_LO, sRays);
        addWide(BVH_C_VISITED_LO, sVisited);
        atomicMax(bvhCounters[BVH_C_VISITED_MAX], sVisitedMax);
        addWide(BVH_C_TRIS_LO, sTested);
        if (sTruncated != 0u) atomicAdd(bvhCounters[BVH_C_TRUNCATED_PIXELS], sTruncated);
        if (sCapped != 0u) atomicAdd(bvhCounters[BVH_C_CAPPED_PIXELS], sCapped);
        if (sOverflowRays != 0u) atomicAdd(bvhCounters[BVH_C_OVERFLOW_RAYS], sOverflowRays);
        if (sOverflowPixels != 0u) atomicAdd(bvhCounters[BVH_C_OVERFLOW_PIXELS], sOverflowPixels);
        SIMD_PROBE_FLUSH(addWide, bvhCounters, BVH_C_SIMD_BASE, BVH_C_SIMD_WIDTH);
    }
#endif
}
