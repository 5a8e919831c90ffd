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
#include "common/instrumentation.glsl"
#include "common/light.glsl"
#include "common/counters.glsl"
#include "common/watertight.glsl"
#include "bvh_raytrace/layout.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

struct BvhNode { // 64 bytes, mirrored by bvh::NodeGpu (algorithms/bvh_raytrace/BvhGpuLayout.h)
    vec3 lo0; uint child0;
    vec3 hi0; uint child1;
    vec3 lo1; uint count0;
    vec3 hi1; uint count1;
};
// Nodes and leaf-ordered triangles (3 vec4 each) are read through buffer textures over their
// buffers (BvhRaytrace binds them to BVH_NODE_UNIT, BVH_TRI_UNIT): a SIMD CPU back end (llvmpipe)
// gathers a texel fetch for all its lanes at once but loads storage buffers lane by lane; a GPU
// reads both through its caches.
layout(binding = BVH_NODE_UNIT) uniform usamplerBuffer uBvhNodeTexels;  // RGBA32UI, 4 texels per node
layout(binding = BVH_TRI_UNIT) uniform samplerBuffer uBvhTriTexels;     // RGBA32F, 3 texels per triangle
BvhNode bvhNode(uint i) {
    int t = int(4u * i);
    uvec4 a = texelFetch(uBvhNodeTexels, t), b = texelFetch(uBvhNodeTexels, t + 1);
    uvec4 c = texelFetch(uBvhNodeTexels, t + 2), d = texelFetch(uBvhNodeTexels, t + 3);
    return BvhNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w,
                   uintBitsToFloat(c.xyz), c.w, uintBitsToFloat(d.xyz), d.w);
}
vec3 bvhVertex(uint tri, int k) { return texelFetch(uBvhTriTexels, int(3u * tri) + k).xyz; }
layout(std430, binding = BVH_SAMPLE_BINDING) readonly buffer LightSamples { vec4 lightSamples[]; };
layout(std430, binding = BVH_COUNTER_BINDING) buffer BvhCounters { uint bvhCounters[]; };

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
#if SHADOWLAB_INSTRUMENTATION
layout(r32f, binding = 1) writeonly uniform image2D uNodesVisited; // debug heat map: nodes per pixel
layout(r32f, binding = 2) writeonly uniform image2D uOverflow;     // 1 where the pixel was written shadowed for a failed ray
layout(rg32ui, binding = BVH_ACCUM_UNIT) uniform uimage2D uAccum;   // between dispatches: x state (layout.glsl), y nodes visited
#else
layout(r32ui, binding = BVH_ACCUM_UNIT) uniform uimage2D uAccum;    // between dispatches: the state (layout.glsl)
#endif
uniform float uRayOffset; // world units, the reference's
uniform int uSampleCount; // entries of lightSamples (1 for point, spot and directional lights)
uniform int uSampleFirst, uSampleEnd; // the samples this dispatch traces, [first, end)
uniform uint uStepCap;    // most loop passes of one ray's traversal: nodes + 2 * leaves + 1 (see trace)

// Tests only (framework/gl/Shader.h, setShaderFaultDefines): a corrupt child link that sends the
// rays of every other pixel back into the node they are leaving, whenever they enter one inner
// child only: a walk that makes no progress, as a bad tree in memory would make it.
#ifndef SHADOWLAB_FAULT_BVH_CYCLE
#define SHADOWLAB_FAULT_BVH_CYCLE 0
#endif
#if SHADOWLAB_FAULT_BVH_CYCLE
bool gFaultPixel = false;
#endif

const float kInf = uintBitsToFloat(0x7F800000u);

struct Ray {
    vec3 o, d, invD;
    float tfar;
    WatertightRay w; // the triangle test's frame
};

Ray makeRay(vec3 o, vec3 d, float tfar) {
    Ray r;
    r.o = o, r.d = d, r.tfar = tfar;
    // A zero component would give 0 * inf = NaN in the slab test; 1e-30 keeps the slab infinite.
    vec3 safe = mix(d, mix(vec3(-1e-30), vec3(1e-30), greaterThanEqual(d, vec3(0.0))), lessThan(abs(d), vec3(1e-30)));
    r.invD = 1.0 / safe;
    r.w = watertightRay(o, d, tfar);
    return r;
}

bool hitTriangle(Ray r, uint tri) {
    return watertightHit(r.w, bvhVertex(tri, 0), bvhVertex(tri, 1), bvhVertex(tri, 2));
}

// Slab test on [0, tfar]; tnear is where the ray enters (for near-first ordering). The far end
// is widened by a few ulps (Ize 2013) so rounding never drops a box the ray grazes.
bool hitBox(vec3 lo, vec3 hi, Ray r, out float tnear) {
    vec3 t0 = (lo - r.o) * r.invD, t1 = (hi - r.o) * r.invD;
    vec3 tmin = min(t0, t1), tmax = max(t0, t1);
    tnear = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
    float tfar = min(min(tmax.x, tmax.y), min(tmax.z, r.tfar)) * 1.0000004;
    return tnear <= tfar;
}

struct Trace {
    bool occluded, overflow, capped;
    uint visited, tested;
};

// A child reference on the stack: an inner node's index, or BVH_LEAF | first << 4 | (count - 1) for
// a leaf of `count` triangles from `first` in leaf order (the builder keeps leaves <= 16 and
// first < 2^27: BvhRaytrace.cpp checks it).
const uint BVH_LEAF = 0x80000000u, NONE = 0xFFFFFFFFu;

uint childRef(uint child, uint count) { return count > 0u ? (BVH_LEAF | (child << 4u) | (count - 1u)) : child; }
bool isLeaf(uint ref) { return ref != NONE && (ref & BVH_LEAF) != 0u; }

#if BVH_SHORT_STACK
// The traversal stack's top BVH_SHORT_ENTRIES entries live in four uvec4 registers, shifted on
// every push and pop (no variable index: llvmpipe keeps a variably indexed local array in scratch
// memory); deeper entries spill to `stack`, which only a push onto a full short stack or a pop
// that refills it index. sp counts all entries.
#define BVH_SHORT_ENTRIES 16
#define STACK_SPILL max(1, BVH_STACK_SIZE - BVH_SHORT_ENTRIES)
#define PUSH(x)                                                                               \
    {                                                                                         \
        if (sp >= BVH_SHORT_ENTRIES) stack[sp - BVH_SHORT_ENTRIES] = st3.w;                   \
        st3 = uvec4(st2.w, st3.xyz), st2 = uvec4(st1.w, st2.xyz), st1 = uvec4(st0.w, st1.xyz); \
        st0 = uvec4((x), st0.xyz);                                                            \
        ++sp;                                                                                 \
    }
#define POP_INTO(v)                                                                                  \
    {                                                                                                \
        if (sp == 0) {                                                                               \
            v = NONE;                                                                                \
        } else {                                                                                     \
            v = st0.x;                                                                               \
            --sp;                                                                                    \
            uint refill_ = sp >= BVH_SHORT_ENTRIES ? stack[sp - BVH_SHORT_ENTRIES] : NONE;           \
            st0 = uvec4(st0.yzw, st1.x), st1 = uvec4(st1.yzw, st2.x), st2 = uvec4(st2.yzw, st3.x);  \
            st3 = uvec4(st3.yzw, refill_);                                                           \
        }                                                                                            \
    }
#else
#define STACK_SPILL BVH_STACK_SIZE
#define PUSH(x) stack[sp++] = (x)
#define POP_INTO(v) v = sp > 0 ? stack[--sp] : NONE
#endif

// Every pass of the three loops costs one step. In a tree a ray enters each inner node at most once
// and each leaf at most once, and each pass of the outer loop tests a leaf or ends the walk, so a
// correct walk takes at most nodes + 2 * leaves + 1 steps: uStepCap. GLSL does not promise that a
// loop ends (a GPU runs an endless one until the driver's watchdog resets it): a walk that reaches
// the cap stops with work left, and so does one that a driver's own loop limit (llvmpipe's) ends;
// either is `capped`, its ray blocked and its pixel written shadowed. The walk's progress is integer
// (node indices, the stack pointer), never a float comparison that a NaN could leave false forever:
// a NaN ray misses every box and ends at once.
Trace trace(Ray r) {
    Trace res = Trace(false, false, false, 0u, 0u);
    uint stack[STACK_SPILL];
#if BVH_SHORT_STACK
    uvec4 st0 = uvec4(NONE), st1 = uvec4(NONE), st2 = uvec4(NONE), st3 = uvec4(NONE);
#endif
    int sp = 0;
    uint node = 0u, leaf = NONE; // the inner node to visit next, and a leaf postponed for the leaf loop
    uint steps = 0u;
    while ((node != NONE || leaf != NONE) && steps < uStepCap) {
        ++steps;
        // Inner loop: descend until this ray holds a leaf (or has nothing left), so that the rays of
        // neighbouring invocations (lanes in lockstep) test their triangles together below.
        while (node != NONE && !isLeaf(node) && leaf == NONE && steps < uStepCap) {
            ++steps;
            ++res.visited;
#if SHADOWLAB_FAULT_BVH_CYCLE
            uint current = node;
#endif
            BvhNode n = bvhNode(node);
            float tn0, tn1;
            bool h0 = n.child0 != BVH_ABSENT && hitBox(n.lo0, n.hi0, r, tn0);
            bool h1 = n.child1 != BVH_ABSENT && hitBox(n.lo1, n.hi1, r, tn1);
            uint c0 = childRef(n.child0, n.count0), c1 = childRef(n.child1, n.count1);
            if (h0 && h1) {
                bool first0 = tn0 <= tn1; // near child first
                // A full stack would drop a subtree that may hold the occluder: stop and report.
                if (sp == BVH_STACK_SIZE) { res.overflow = true; return res; }
                PUSH(first0 ? c1 : c0);
                node = first0 ? c0 : c1;
            } else if (h0 || h1) {
                node = h0 ? c0 : c1;
#if SHADOWLAB_FAULT_BVH_CYCLE
                if (gFaultPixel && !isLeaf(node)) node = current;
#endif
            } else {
                POP_INTO(node);
            }
            // A leaf is postponed: its triangles are tested in the leaf loop.
            if (isLeaf(node)) { leaf = node; POP_INTO(node); }
        }
        // Leaf loop: the postponed leaf, and any leaves that come next off the stack.
        while (isLeaf(leaf) && steps < uStepCap) {
            ++steps;
            uint first = (leaf & ~BVH_LEAF) >> 4u, count = (leaf & 15u) + 1u;
            for (uint i = 0u; i < count; ++i) {
                ++res.tested;
                if (hitTriangle(r, first + i)) { res.occluded = true; return res; } // any hit ends the ray
            }
            leaf = NONE;
            if (isLeaf(node)) { leaf = node; POP_INTO(node); }
        }
    }
    res.capped = node != NONE || leaf != NONE; // work left: the cap (or the driver) ended the walk
    return res;
}

#if SHADOWLAB_INSTRUMENTATION
shared uint sPixels, sRays, sVisited, sVisitedMax, sTested, sOverflowRays, sOverflowPixels, sTruncated, sCapped;

void addWide(int lo, uint value) COUNTER_ADD_WIDE(bvhCounters, lo, value)
#endif

void main() {
#if SHADOWLAB_INSTRUMENTATION
    if (gl_LocalInvocationIndex == 0u) sPixels = sRays = sVisited = sVisitedMax = sTested = sOverflowRays = sOverflowPixels = sTruncated = sCapped = 0u;
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
            if (lightIlluminates(p) && dot(n, toLight(p)) > 0.0) {
                vec3 o = p + n * uRayOffset; // the same (unnormalised) normal as the reference
                bool directional = uLightType == LIGHT_DIRECTIONAL;
                int count = directional ? 1 : uSampleCount, first = uSampleFirst, end = directional ? 1 : uSampleEnd;
                // The state the earlier dispatches left: unblocked samples and failure flags.
                uint state = 0u;
                if (!firstDispatch) {
                    uvec4 a = imageLoad(uAccum, px);
                    state = a.x;
#if SHADOWLAB_INSTRUMENTATION
                    visitedAll = a.y;
#endif
                }
                uint unblocked = 0u, visited = 0u, tested = 0u, maxVisited = 0u, done = 0u, overflowRays = 0u, cappedRays = 0u;
                for (int s = first; s < end; ++s) {
                    Ray r;
                    if (directional) {
                        r = makeRay(o, -uLightDirection, kInf);
                    } else {
                        vec3 d = lightSamples[s].xyz - o;
                        float dist = length(d);
                        if (!(dist > 0.0)) { ++unblocked; ++done; continue; } // origin on the sample
                        r = makeRay(o, d / dist, max(0.0, dist - uRayOffset));
                    }
                    Trace t = trace(r);
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
#if SHADOWLAB_INSTRUMENTATION
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
                // Timing mode still counts every overflowed, capped or truncated pixel.
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
#if SHADOWLAB_INSTRUMENTATION
            imageStore(uNodesVisited, px, vec4(float(visitedAll)));
            imageStore(uOverflow, px, vec4(failed ? 1.0 : 0.0));
#endif
        }
    }
#if SHADOWLAB_INSTRUMENTATION
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
    }
#endif
}
