#version 450
// PSV query: Algorithm 2 of the paper, one invocation per pixel. It locates the G-buffer point in
// the TOP tree with an explicit stack and writes its visibility: 1 lit, 0 shadowed, and with
// PSV_TRANSPARENCY the product of (1 - opacity) of every frustum that contains it.
#define PSV_NODE_ACCESS readonly restrict // the tree is complete: built by the previous dispatches
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/counters.glsl"
#include "psv/tree.glsl"
#include "common/pixel_order.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
uniform float uRayOffset; // world units: the reference's shadow-ray origin offset along the normal

struct Result {
    float visibility;
    uint visited;
    bool overflow;
};

Result query(vec3 q) {
    Result r = Result(1.0, 0u, false);
    uint stack[PSV_STACK_SIZE];
    int sp = 0;
#if PSV_DEPTH_SKIP
    float depth = psvDepth(q);
#endif
#if PSV_WEDGE
    float wedgeScale = psvWedgeScale(q);
#endif
    // Pushing onto a full stack would drop a subtree that may hold the occluder: stop and report.
#define PSV_PUSH(node) { if (sp == PSV_STACK_SIZE) { r.overflow = true; break; } stack[sp++] = (node); }
    uint node = psvNode(0u).pos;
    while (true) {
        if (node == 0u) {
            if (sp == 0) break;
            node = stack[--sp];
        }
        ++r.visited;
        PsvNode n = psvNode(node);
        float s = psvSigned(n.plane, q);
        if (node % PSV_NODES_PER_TRIANGLE != 0u) { // shadow plane
            // Only one side can hold frusta containing q; at s == 0 both sides would do, and the
            // negative one keeps the edge shared by two triangles closed (their planes are exact
            // opposites, so q is inside at least one of them).
            uint next = s <= 0.0 ? node + 1u : n.pos;
#if PSV_WEDGE
            bool visitInter = n.inter != 0u && psvInWedge(s, wedgeScale, uintBitsToFloat(n.wedgeOrNeg));
#else
            bool visitInter = n.inter != 0u;
#endif
            if (visitInter) {
                if (next == 0u) next = n.inter;
                else PSV_PUSH(n.inter);
            }
            node = next;
            continue;
        }
        // Capping plane: q is inside the frustum's three shadow planes.
#if PSV_DEPTH_SKIP
        // Mora et al. 2016: nothing in this subtree is nearer the light than q, so nothing in it
        // can lie between q and the light.
        if (depth <= uintBitsToFloat(n.minDepth)) { node = 0u; continue; }
#endif
        if (s < 0.0) { // behind the triangle: inside its shadow frustum
#if PSV_TRANSPARENCY
            uint triangle = node / PSV_NODES_PER_TRIANGLE - 1u;
            r.visibility *= 1.0 - clamp(sceneMaterials[sceneTriangles[triangle].material].opacity, 0.0, 1.0);
            if (r.visibility <= PSV_OPAQUE_TRANSMISSION) { r.visibility = 0.0; break; }
            // Frusta behind this triangle (negative child) may hold q too; in front ones below.
            if (n.wedgeOrNeg != 0u) PSV_PUSH(n.wedgeOrNeg);
#else
            r.visibility = 0.0;
            break;
#endif
        }
        if (n.inter != 0u) PSV_PUSH(n.inter);
        node = n.pos;
    }
#undef PSV_PUSH
    // An overflowed pixel is never reported lit: it is written shadowed and counted (a wrong dark
    // pixel is visible in the overflow view and in overflowCount(); a silent light leak is not).
    if (r.overflow) r.visibility = 0.0;
    return r;
}

#if SHADOWLAB_INSTRUMENTATION
layout(r32f, binding = 1) writeonly uniform image2D uNodesVisited; // debug heat map
layout(r32f, binding = 2) writeonly uniform image2D uOverflow;     // 1 where the stack overflowed
shared uint sTraversed, sVisited, sVisitedMax, sOverflow;
#endif

void main() {
#if SHADOWLAB_INSTRUMENTATION
    if (gl_LocalInvocationIndex == 0u) sTraversed = sVisited = sVisitedMax = sOverflow = 0u;
    barrier();
#endif
    ivec2 px = pixelOfInvocation();
    if (all(lessThan(px, imageSize(uVisibility)))) {
        vec4 pos = texelFetch(uPosition, px, 0);
        float visibility = 1.0; // background: nothing to shadow (the reference's convention)
        Result r = Result(1.0, 0u, false);
        if (pos.w >= 0.5) {
            vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
            visibility = 0.0; // facing away from the light
            if (dot(n, toLight(p)) > 0.0) {
                // The reference's ray origin: the same offset along the same (unnormalised) normal.
                r = query(p + n * uRayOffset);
                visibility = r.visibility;
#if SHADOWLAB_INSTRUMENTATION
                atomicAdd(sTraversed, 1u);
                atomicAdd(sVisited, r.visited);
                atomicMax(sVisitedMax, r.visited);
                if (r.overflow) atomicAdd(sOverflow, 1u);
#else
                // Timing mode still counts every overflowed pixel (never a silent wrong image).
                if (r.overflow) atomicAdd(psvCounters[PSV_C_STACK_OVERFLOW], 1u);
#endif
            }
        }
        imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_INSTRUMENTATION
        imageStore(uNodesVisited, px, vec4(float(r.visited)));
        imageStore(uOverflow, px, vec4(r.overflow ? 1.0 : 0.0));
#endif
    }
#if SHADOWLAB_INSTRUMENTATION
    barrier();
    if (gl_LocalInvocationIndex == 0u && sTraversed != 0u) {
        atomicAdd(psvCounters[PSV_C_TRAVERSED], sTraversed);
        COUNTER_ADD_WIDE(psvCounters, PSV_C_VISITED_LO, sVisited)
        atomicMax(psvCounters[PSV_C_VISITED_MAX], sVisitedMax);
        if (sOverflow != 0u) atomicAdd(psvCounters[PSV_C_STACK_OVERFLOW], sOverflow);
    }
#endif
}
