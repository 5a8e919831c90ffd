// The traversal of the scene BVH (framework/accel), run by bvh_raytrace, line_space's near field
// (start_region bvh) and shadow_volumes' close calls: Aila & Laine's while-while walk (inner nodes
// until a leaf is found, then the leaves), near child first, a fixed stack whose overflow is
// reported, any-hit early exit, the watertight triangle test. Needs common/watertight.glsl (and
// includes common/slab.glsl and common/bvh_layout.glsl). The including shader sets, before including it:
//   BVH_TRAVERSE_NODE_UNIT, BVH_TRAVERSE_TRI_UNIT  the texture units of the nodes and triangles
// and may set:
//   BVH_STACK_SIZE, BVH_SHORT_STACK                the stack (default 64 entries, in memory)
//   BVH_TICK_NODE(), BVH_TICK_TRI()                a SIMD probe tick per node and per triangle
// and sets the uniform uBvhStepCap (most loop passes of one walk: nodes + 2 * leaves + 1).
#include "common/slab.glsl"
#include "common/bvh_layout.glsl"

#ifndef SHADOWLAB_FAULT_CUT_LEAF_LOOP
#define SHADOWLAB_FAULT_CUT_LEAF_LOOP 0
#endif

#if !defined(BVH_TRAVERSE_NODE_UNIT) || !defined(BVH_TRAVERSE_TRI_UNIT)
#error "define BVH_TRAVERSE_NODE_UNIT and BVH_TRAVERSE_TRI_UNIT before including common/bvh_traverse.glsl"
#endif
#ifndef BVH_STACK_SIZE
#define BVH_STACK_SIZE 64
#endif
#ifndef BVH_SHORT_STACK
#define BVH_SHORT_STACK 0
#endif
#ifndef BVH_TICK_NODE
#define BVH_TICK_NODE()
#endif
#ifndef BVH_TICK_TRI
#define BVH_TICK_TRI()
#endif

struct BvhNode { // 64 bytes, mirrored by bvh::NodeGpu (framework/accel/BvhGpuLayout.h)
    vec3 lo0; uint child0;
    vec3 hi0; uint child1;
    vec3 lo1; uint count0;
    vec3 hi1; uint count1;
};
// Nodes and leaf-ordered triangles (3 vec4 each) are read through buffer textures over their
// buffers (the host binds them to BVH_TRAVERSE_NODE_UNIT, _TRI_UNIT: bvh::BvhGpu::bind): a SIMD CPU back end (llvmpipe)
// gathers a texel fetch for all its lanes at once but loads storage buffers lane by lane; a GPU
// reads both through its caches.
layout(binding = BVH_TRAVERSE_NODE_UNIT) uniform usamplerBuffer uBvhNodeTexels;  // RGBA32UI, 4 texels per node
layout(binding = BVH_TRAVERSE_TRI_UNIT) uniform samplerBuffer uBvhTriTexels;     // RGBA32F, 3 texels per triangle
BvhNode bvhNode(uint i) {
    int t = int(4u * i);
    uvec4 a = texelFetch(uBvhNodeTexels, t), b = texelFetch(uBvhNodeTexels, t + 1);
    uvec4 c = texelFetch(uBvhNodeTexels, t + 2), d = texelFetch(uBvhNodeTexels, t + 3);
    return BvhNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w,
                   uintBitsToFloat(c.xyz), c.w, uintBitsToFloat(d.xyz), d.w);
}
vec3 bvhVertex(uint tri, int k) { return texelFetch(uBvhTriTexels, int(3u * tri) + k).xyz; }
// Tests only (framework/gl/Shader.h, setShaderFaultDefines): a corrupt child link that sends the
// rays of every other pixel back into the node they are leaving, whenever they enter one inner
// child only: a walk that makes no progress, as a bad tree in memory would make it.
#ifndef SHADOWLAB_FAULT_BVH_CYCLE
#define SHADOWLAB_FAULT_BVH_CYCLE 0
#endif
#if SHADOWLAB_FAULT_BVH_CYCLE
bool gFaultPixel = false;
#endif

struct BvhRay {
    vec3 o, d, invD;
    float tfar;
    WatertightRay w; // the triangle test's frame
};

BvhRay bvhMakeRay(vec3 o, vec3 d, float tfar) {
    BvhRay r;
    r.o = o, r.d = d, r.tfar = tfar;
    r.invD = slabInverse(d);
    r.w = watertightRay(o, d, tfar);
    return r;
}

bool bvhHitTriangle(BvhRay r, uint tri) {
    return watertightHit(r.w, bvhVertex(tri, 0), bvhVertex(tri, 1), bvhVertex(tri, 2));
}

// Slab test on [0, tfar] (common/slab.glsl: conservative under GLSL's division error).
bool bvhHitBox(vec3 lo, vec3 hi, BvhRay r, out float tnear) { return slabHit(lo, hi, r.o, r.invD, r.tfar, tnear); }

struct BvhTrace {
    bool occluded, overflow, capped;
    uint visited, tested;
};

// A child reference on the stack: an inner node's index, or BVH_LEAF_REF | first << 4 | (count - 1) for
// a leaf of `count` triangles from `first` in leaf order (the builder keeps leaves <= 16 and
// first < 2^27: BvhRaytrace.cpp checks it).
const uint BVH_LEAF_REF = 0x80000000u, BVH_NONE = 0xFFFFFFFFu;

uint bvhChildRef(uint child, uint count) { return count > 0u ? (BVH_LEAF_REF | (child << 4u) | (count - 1u)) : child; }
bool bvhIsLeaf(uint ref) { return ref != BVH_NONE && (ref & BVH_LEAF_REF) != 0u; }

#if BVH_SHORT_STACK
// The traversal stack's top BVH_SHORT_ENTRIES entries live in four uvec4 registers, shifted on
// every push and pop (no variable index: llvmpipe keeps a variably indexed local array in scratch
// memory); deeper entries spill to `stack`, which only a push onto a full short stack or a pop
// that refills it index. sp counts all entries.
#define BVH_SHORT_ENTRIES 16
#define BVH_STACK_SPILL max(1, BVH_STACK_SIZE - BVH_SHORT_ENTRIES)
#define BVH_PUSH(x)                                                                               \
    {                                                                                         \
        if (sp >= BVH_SHORT_ENTRIES) stack[sp - BVH_SHORT_ENTRIES] = st3.w;                   \
        st3 = uvec4(st2.w, st3.xyz), st2 = uvec4(st1.w, st2.xyz), st1 = uvec4(st0.w, st1.xyz); \
        st0 = uvec4((x), st0.xyz);                                                            \
        ++sp;                                                                                 \
    }
#define BVH_POP_INTO(v)                                                                                  \
    {                                                                                                \
        if (sp == 0) {                                                                               \
            v = BVH_NONE;                                                                                \
        } else {                                                                                     \
            v = st0.x;                                                                               \
            --sp;                                                                                    \
            uint refill_ = sp >= BVH_SHORT_ENTRIES ? stack[sp - BVH_SHORT_ENTRIES] : BVH_NONE;           \
            st0 = uvec4(st0.yzw, st1.x), st1 = uvec4(st1.yzw, st2.x), st2 = uvec4(st2.yzw, st3.x);  \
            st3 = uvec4(st3.yzw, refill_);                                                           \
        }                                                                                            \
    }
#else
#define BVH_STACK_SPILL BVH_STACK_SIZE
#define BVH_PUSH(x) stack[sp++] = (x)
#define BVH_POP_INTO(v) v = sp > 0 ? stack[--sp] : BVH_NONE
#endif

uniform uint uBvhStepCap; // most loop passes of one ray's traversal: nodes + 2 * leaves + 1 (see bvhTrace)

// Every pass of the three loops costs one step. In a tree a ray enters each inner node at most once
// and each leaf at most once, and each pass of the outer loop tests a leaf or ends the walk, so a
// correct walk takes at most nodes + 2 * leaves + 1 steps: uBvhStepCap. GLSL does not promise that a
// loop ends (a GPU runs an endless one until the driver's watchdog resets it): a walk that reaches
// the cap stops with work left, and so does one that a driver's own loop limit (llvmpipe's) ends;
// either is `capped`, its ray blocked and its pixel written shadowed. The walk's progress is integer
// (node indices, the stack pointer), never a float comparison that a NaN could leave false forever:
// a NaN ray misses every box and ends at once.
BvhTrace bvhTrace(BvhRay r) {
    BvhTrace res = BvhTrace(false, false, false, 0u, 0u);
    uint stack[BVH_STACK_SPILL];
#if BVH_SHORT_STACK
    uvec4 st0 = uvec4(BVH_NONE), st1 = uvec4(BVH_NONE), st2 = uvec4(BVH_NONE), st3 = uvec4(BVH_NONE);
#endif
    int sp = 0;
    uint node = 0u, leaf = BVH_NONE; // the inner node to visit next, and a leaf postponed for the leaf loop
    uint steps = 0u;
    while ((node != BVH_NONE || leaf != BVH_NONE) && steps < uBvhStepCap) {
        ++steps;
        // Inner loop: descend until this ray holds a leaf (or has nothing left), so that the rays of
        // neighbouring invocations (lanes in lockstep) test their triangles together below.
        while (node != BVH_NONE && !bvhIsLeaf(node) && leaf == BVH_NONE && steps < uBvhStepCap) {
            ++steps;
            ++res.visited;
            BVH_TICK_NODE();
#if SHADOWLAB_FAULT_BVH_CYCLE
            uint current = node;
#endif
            BvhNode n = bvhNode(node);
            float tn0, tn1;
            bool h0 = n.child0 != BVH_ABSENT && bvhHitBox(n.lo0, n.hi0, r, tn0);
            bool h1 = n.child1 != BVH_ABSENT && bvhHitBox(n.lo1, n.hi1, r, tn1);
            uint c0 = bvhChildRef(n.child0, n.count0), c1 = bvhChildRef(n.child1, n.count1);
            if (h0 && h1) {
                bool first0 = tn0 <= tn1; // near child first
                // A full stack would drop a subtree that may hold the occluder: stop and report.
                if (sp == BVH_STACK_SIZE) { res.overflow = true; return res; }
                BVH_PUSH(first0 ? c1 : c0);
                node = first0 ? c0 : c1;
            } else if (h0 || h1) {
                node = h0 ? c0 : c1;
#if SHADOWLAB_FAULT_BVH_CYCLE
                if (gFaultPixel && !bvhIsLeaf(node)) node = current;
#endif
            } else {
                BVH_POP_INTO(node);
            }
            // A leaf is postponed: its triangles are tested in the leaf loop.
            if (bvhIsLeaf(node)) { leaf = node; BVH_POP_INTO(node); }
        }
        // Leaf loop: the postponed leaf, and any leaves that come next off the stack.
        while (bvhIsLeaf(leaf) && steps < uBvhStepCap) {
            ++steps;
            uint first = (leaf & ~BVH_LEAF_REF) >> 4u, count = (leaf & 15u) + 1u;
            uint i = 0u;
            for (; i < count; ++i) {
#if SHADOWLAB_FAULT_CUT_LEAF_LOOP
                if (i == 1u) break; // what a driver's loop limit does: the loop just ends
#endif
                ++res.tested;
                BVH_TICK_TRI();
                if (bvhHitTriangle(r, first + i)) { res.occluded = true; return res; } // any hit ends the ray
            }
            // A leaf left untested (a driver's loop limit ended the loop) may hold the occluder.
            if (i < count) { res.capped = true; return res; }
            leaf = BVH_NONE;
            if (bvhIsLeaf(node)) { leaf = node; BVH_POP_INTO(node); }
        }
    }
    res.capped = node != BVH_NONE || leaf != BVH_NONE; // work left: the cap (or the driver) ended the walk
    return res;
}
