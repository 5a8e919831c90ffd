#version 450
// PSV query, one invocation per pixel: it locates the G-buffer point in the TOP tree and writes its
// visibility: 1 lit, 0 shadowed, and with PSV_TRANSPARENCY the product of (1 - opacity) of every
// frustum that contains it. Three walks of the same nodes (PSV_TRAVERSAL):
//   0 stack (Gerhards et al. 2015, Algorithm 2): intersection children wait on an explicit stack;
//     a full stack stops the pixel, written shadowed and counted.
//   1 stackless (Mora et al. 2016): an intersection child is walked first, and where a subtree
//     ends the walk jumps to its triangle's escape node (build.comp writes it), the deepest
//     ancestor it was reached from through an intersection child, and takes that node's other
//     side. No stack, so nothing to overflow.
//   2 hybrid (Mora et al. 2016): the stack walk with a short stack (PSV_HYBRID_STACK); an
//     intersection child that finds it full is walked stacklessly at once, up to its owner.
// All three visit the same nodes and decide every triangle alike, so their images are identical.
//
// Exactness. A plane value within the close-call margin of 0 is too close to call (the rounding of the plane
// and of the reference's ray test could disagree there). Such a triangle is decided by the
// reference's own ray and watertight test (psvShadows), and only the nodes that can still hold q
// are walked: at a shadow plane q goes down the frustum's negative side, since a triangle below
// the positive child lies more than the tolerance from the plane and so does its whole frustum (the
// plane passes through the light); at the capping plane, a point that is not inside all four
// planes by more than the margin goes to the ray test.
//
// Two passes (PSV_QUERY_PASS) where PSV_PLANE_WALK is set (the stack and stackless walks of opaque
// shadows): 0 walks every pixel with the plane walk (psv/plane_walk.glsl), which decides by planes
// alone and lists the pixels that meet a close call; 1 walks the listed pixels again with the exact
// walk below. Without PSV_PLANE_WALK, pass 0 runs the exact walk on every pixel.
#define PSV_NODE_ACCESS readonly restrict // the tree is complete: built by the previous dispatches
#include "common/light.glsl"
#define SCENE_POSITION_TEXELS 1 // close calls test triangles through the positions view (any scene size)
#include "common/scene.glsl"
#include "common/counters.glsl"
#include "psv/tree.glsl"
#include "common/shadow_ray.glsl"
#include "common/pixel_order.glsl"
#define PIXEL_LIST_BINDING PSV_DEFER_LIST_BINDING
#include "common/pixel_list.glsl"
#ifndef PSV_QUERY_PASS
#define PSV_QUERY_PASS 0
#endif
#ifndef PSV_PLANE_WALK
#define PSV_PLANE_WALK 0
#endif
#if PSV_QUERY_PASS == 0
layout(local_size_x = 8, local_size_y = 8) in;
#else
layout(local_size_x = PIXEL_LIST_GROUP) in;
#endif

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
uniform float uRayOffset; // world units: the reference's shadow-ray origin offset along the normal

#ifndef PSV_TRAVERSAL
#define PSV_TRAVERSAL 0
#endif
#if PSV_TRAVERSAL != 0 && PSV_TRANSPARENCY
#error "the stackless walks keep one pending side per node: x-ray shadows need the stack walk"
#endif

struct Result {
    float visibility;
    uint visited, closeCalls, stacklessWalks;
    bool overflow; // a full stack, or (stackless walks) the escape cap: written shadowed, counted
    bool capped;   // the escape cap
    bool deferred; // the plane walk met a close call: the exact walk decides the pixel
};

// A stackless walk goes down links (the tree has no cycles: a frustum is linked below nodes already
// in it) and up escapes; each node is entered at most once from an escape, so one walk takes at
// most 4n + 1 escapes. One more can only be a corrupt escape: the walk ends at its owner with
// `capped` set, and the pixel is written shadowed and counted (never a hang). The walk counts its
// escapes down from this budget, as data flow into the jump, not a branch of the node loop
// (llvmpipe pays for every branch), and not as a compare with a uniform, which cost psv's node
// loop on llvmpipe (psvReadMargins, psv/tree.glsl).
uint psvEscapeBudget() { return PSV_NODES_PER_TRIANGLE * uTriangleCount + 2u; }

// What the walk needs of the query point. The reference's ray is not kept here: it is built where
// a close call needs it, so that its nine values do not stay live through the walk (registers).
struct Query {
    vec3 q;
    float depth;      // psvDepth(q), for the depth skip
    float wedgeScale; // psvWedgeScale(q)
};

// The light triangle t lets through to q (1 - opacity, 0 for opaque shadows).
float psvTransmission(uint t) {
#if PSV_TRANSPARENCY
    return 1.0 - clamp(sceneMaterials[sceneTriangles[t].material].opacity, 0.0, 1.0);
#else
    return 0.0;
#endif
}

// Whether q is inside each of triangle t's four planes by more than psvCloseCall.
bool psvClearlyInside(Query Q, uint t) {
    uint base = PSV_NODES_PER_TRIANGLE * t + 1u;
    return psvSigned(psvPlane(base), Q.q) < -psvCloseCall && psvSigned(psvPlane(base + 1u), Q.q) < -psvCloseCall &&
           psvSigned(psvPlane(base + 2u), Q.q) < -psvCloseCall && psvSigned(psvPlane(base + 3u), Q.q) < -psvCloseCall;
}

// Whether triangle t shadows q, asked where the walk found q behind (or too close to) t's capping
// plane, after going down the negative side (or too close to) its three shadow planes. Its four
// planes decide where q is inside each by more than psvCloseCall; elsewhere the reference's ray test
// decides (the same ray, the same watertight test, so the same answer), counted in closeCalls.
// `clearly` tells which.
bool psvShadows(Query Q, uint t, out bool clearly, inout Result r) {
    clearly = psvClearlyInside(Q, t);
    if (clearly) return true;
    ++r.closeCalls;
    return watertightHit(shadowRayToLight(Q.q, uRayOffset), sceneVertex(t, 0u), sceneVertex(t, 1u), sceneVertex(t, 2u));
}

#if PSV_DEPTH_SKIP
// Mora et al. 2016: nothing in a capping node's subtree is nearer the light than q, so nothing in
// it can lie between q and the light.
#define PSV_SKIPS_DEPTH(Q, n) (Q.depth <= uintBitsToFloat(n.minDepth))
#else
#define PSV_SKIPS_DEPTH(Q, n) false
#endif
#if PSV_WEDGE
#define PSV_VISITS_INTER(Q, n, s) (n.inter != 0u && psvInWedge(s, Q.wedgeScale, uintBitsToFloat(n.wedgeOrNeg)))
#else
#define PSV_VISITS_INTER(Q, n, s) (n.inter != 0u)
#endif

// The walks below have two loops: the inner one goes from node to node and stops at a capping
// plane that q is behind or too close to; the outer one decides that triangle (psvShadows) and
// goes on. Deciding it inside the node loop would cost every node: a SIMD back end (llvmpipe)
// runs a branch's body for the whole group whenever one lane takes it.

#if PSV_TRAVERSAL != 0
// Walks the subtree entered at `node` without a stack, until it is done: false when it reached
// `owner` (the node whose intersection child it is; 0 for the whole tree) with q still lit, true
// when q is in shadow. Each node is entered once from above and, if its intersection child was
// walked first, once more from an escape (`second`), when the walk takes the side it did not take
// first. That choice is made again from the same plane value (the same code on the same operands),
// so the walk visits exactly the nodes the stack walk visits.
bool psvWalkStackless(Query Q, uint node, uint owner, inout Result r) {
    bool second = false;
    uint budget = psvEscapeBudget();
    // The next node: `side`, or where it is none the escape of `triangle`; the owner past the cap.
#define PSV_STEP(side, triangle)                                                \
    {                                                                           \
        second = (side) == 0u;                                                  \
        budget -= second ? 1u : 0u;                                             \
        bool over = budget == 0u;                                               \
        r.capped = r.capped || over;                                            \
        node = over ? owner : (second ? psvEscape(triangle) : (side));          \
    }
    while (true) {
        uint cap = 0u; // a capping node q is behind or too close to, decided outside the node loop
        while (true) {
            if (node == owner) return false;
            ++r.visited;
            PsvNode n = psvNode(node);
            float s = psvSigned(n.plane, Q.q);
            uint side; // the child on q's side of the plane (0: none)
            if (node % PSV_NODES_PER_TRIANGLE != 0u) { // shadow plane
                side = s <= psvCloseCall ? node + 1u : n.pos;
                if (!second && PSV_VISITS_INTER(Q, n, s)) { node = n.inter; continue; }
            } else { // capping plane
                if (!second && PSV_SKIPS_DEPTH(Q, n)) side = 0u;
                else if (!second && s <= psvCloseCall) { cap = node; break; }
                else side = !second && n.inter != 0u ? n.inter : n.pos;
            }
            PSV_STEP(side, (node - 1u) / PSV_NODES_PER_TRIANGLE)
        }
        // The node loop leaves only by returning or with a capping node: without one it was ended
        // from outside (rule 13), and `cap` names no triangle to decide.
        if (cap == 0u) break;
        uint t = (cap - 1u) / PSV_NODES_PER_TRIANGLE;
        bool clearly;
        if (psvShadows(Q, t, clearly, r)) { r.visibility = 0.0; return true; }
        // Lit by it: on to the subtree in front, as for a point in front of the plane. (The subtree
        // behind it lies inside its frustum and more than the tolerance behind it: not q's.)
        PsvNode n = psvNode(cap);
        PSV_STEP(n.inter != 0u ? n.inter : n.pos, t)
    }
#undef PSV_STEP
    // Reached only when the device ended the loops from outside (llvmpipe after 65,535 iterations
    // in all, docs/architecture.md rule 13): the walk did not finish, so the pixel is capped.
    r.capped = true;
    return false;
}
#endif

#if PSV_TRAVERSAL == 1
Result query(Query Q) {
    Result r = Result(1.0, 0u, 0u, 1u, false, false, false);
    psvWalkStackless(Q, psvNode(0u).pos, 0u, r);
    if (r.capped) { r.overflow = true; r.visibility = 0.0; }
    return r;
}
#else
Result query(Query Q) {
    Result r = Result(1.0, 0u, 0u, 0u, false, false, false);
#if PSV_TRAVERSAL == 2
#define PSV_STACK_ENTRIES PSV_HYBRID_STACK
    // A full stack: the node loop stops, the intersection child is walked stacklessly up to its
    // owner (in the outer loop, like a capping decision), and the stack walk goes on with `node`.
#define PSV_PUSH(owner, child) { if (sp == PSV_STACK_ENTRIES) { subtree = (child); subtreeOwner = (owner); } else stack[sp++] = (child); }
#else
#define PSV_STACK_ENTRIES PSV_STACK_SIZE
    // Pushing onto a full stack would drop a subtree that may hold the occluder: stop and report.
#define PSV_PUSH(owner, child) { if (sp == PSV_STACK_ENTRIES) { r.overflow = true; walking = false; break; } stack[sp++] = (child); }
#endif
    uint stack[PSV_STACK_ENTRIES];
    int sp = 0;
    uint node = psvNode(0u).pos;
    bool walking = true;
    while (walking) {
        uint cap = 0u;                         // a capping node q is behind or too close to
        uint subtree = 0u, subtreeOwner = 0u;  // hybrid: an intersection child the full stack left
        while (true) {
            if (node == 0u) {
                if (sp == 0) { walking = false; break; }
                node = stack[--sp];
            }
            ++r.visited;
            PsvNode n = psvNode(node);
            float s = psvSigned(n.plane, Q.q);
            if (node % PSV_NODES_PER_TRIANGLE != 0u) { // shadow plane
                uint next = s <= psvCloseCall ? node + 1u : n.pos;
                if (PSV_VISITS_INTER(Q, n, s)) {
                    if (next == 0u) next = n.inter;
                    else PSV_PUSH(node, n.inter);
                }
                node = next;
#if PSV_TRAVERSAL == 2
                if (subtree != 0u) break;
#endif
                continue;
            }
            if (PSV_SKIPS_DEPTH(Q, n)) { node = 0u; continue; }
            if (s <= psvCloseCall) { cap = node; break; }
            if (n.inter != 0u) PSV_PUSH(node, n.inter);
            node = n.pos;
#if PSV_TRAVERSAL == 2
            if (subtree != 0u) break;
#endif
        }
        // The node loop leaves with the walk done, a capping node or (hybrid) a subtree to walk
        // stacklessly; with none of these it was ended from outside (rule 13): capped.
        if (walking && cap == 0u && subtree == 0u) { r.capped = true; break; }
        if (cap != 0u) {
            uint t = (cap - 1u) / PSV_NODES_PER_TRIANGLE;
            bool clearly;
            bool shadows = psvShadows(Q, t, clearly, r);
            PsvNode n = psvNode(cap);
            if (shadows) {
                r.visibility *= psvTransmission(t);
                if (r.visibility <= PSV_OPAQUE_TRANSMISSION) { r.visibility = 0.0; break; }
#if PSV_TRANSPARENCY
                // Frusta behind this triangle (negative child) may hold q too, where q is clearly
                // inside it (elsewhere they lie more than the tolerance from q); in front ones below.
                if (clearly && n.wedgeOrNeg != 0u) PSV_PUSH(cap, n.wedgeOrNeg);
#endif
            }
            if (n.inter != 0u) PSV_PUSH(cap, n.inter);
            node = n.pos;
        }
#if PSV_TRAVERSAL == 2
        if (subtree != 0u) {
            ++r.stacklessWalks;
            if (psvWalkStackless(Q, subtree, subtreeOwner, r)) break;
        }
#endif
    }
#undef PSV_PUSH
    // Every way out of the walk that leaves `walking` set has found q shadowed (visibility 0): a
    // walk still going with light left was ended from outside (rule 13), and is capped.
    if (walking && r.visibility != 0.0) r.capped = true;
    r.overflow = r.overflow || r.capped;
    // An overflowed pixel is never reported lit: it is written shadowed and counted (a wrong dark
    // pixel is visible in the overflow view and in overflowCount(); a silent light leak is not).
    if (r.overflow) r.visibility = 0.0;
    return r;
}
#endif

#if PSV_QUERY_PASS == 0 && PSV_PLANE_WALK
#include "psv/plane_walk.glsl"
#endif

#if SHADOWLAB_STATISTICS
layout(r32f, binding = 1) writeonly uniform image2D uNodesVisited; // debug heat map
layout(r32f, binding = 2) writeonly uniform image2D uOverflow;     // 1 where the stack overflowed
shared uint sTraversed, sVisited, sVisitedMax, sOverflow, sCloseCalls, sStackless, sCapped, sDeferred;
#endif

// One pixel's query: its visibility and debug images written, its counts added. The plane walk
// leaves a pixel with a close call to the exact walk of the second pass (listed, nothing written).
void queryPixel(ivec2 px) {
    vec4 pos = texelFetch(uPosition, px, 0);
    float visibility = 1.0; // background: nothing to shadow (the reference's convention)
    Result r = Result(1.0, 0u, 0u, 0u, false, false, false);
    if (pos.w >= 0.5) {
        vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
        visibility = 0.0; // facing away from the light, or outside a spot's cone
        if (lightReaches(p, n)) {
            // The reference's ray origin: the same offset along the same (unnormalised) normal,
            // rounded alike in both passes' programs and the reference.
            vec3 q = watertightOrigin(p, n, uRayOffset);
            Query Q;
            Q.q = q;
#if PSV_DEPTH_SKIP
            Q.depth = psvDepth(Q.q);
#else
            Q.depth = 0.0;
#endif
#if PSV_WEDGE
            Q.wedgeScale = psvWedgeScale(Q.q);
#else
            Q.wedgeScale = 1.0;
#endif
#if PSV_QUERY_PASS == 0 && PSV_PLANE_WALK
            r = psvPlaneWalk(Q);
            if (r.deferred) {
                // Listed for the exact walk, which writes this pixel. A full list (one entry a
                // pixel cannot fill it) would leave it shadowed and counted.
                if (pixelListAppend(px)) {
#if SHADOWLAB_STATISTICS
                    atomicAdd(sDeferred, 1u);
#endif
                    return;
                }
                r.overflow = true;
                r.visibility = 0.0;
            }
#else
            r = query(Q);
#endif
            visibility = r.visibility;
#if SHADOWLAB_STATISTICS
            atomicAdd(sTraversed, 1u);
            atomicAdd(sVisited, r.visited);
            atomicMax(sVisitedMax, r.visited);
            if (r.overflow && !r.capped) atomicAdd(sOverflow, 1u);
            if (r.capped) atomicAdd(sCapped, 1u);
            if (r.closeCalls != 0u) atomicAdd(sCloseCalls, r.closeCalls);
            if (r.stacklessWalks != 0u) atomicAdd(sStackless, r.stacklessWalks);
#else
            // The timed pass still counts every overflowed pixel (never a silent wrong image).
            if (r.overflow && !r.capped) atomicAdd(psvCounters[PSV_C_STACK_OVERFLOW], 1u);
            if (r.capped) atomicAdd(psvCounters[PSV_C_LOOP_CAPPED], 1u);
#endif
        }
    }
#if SHADOWLAB_FAULT_PLANTED_LIT
    // Test fault (framework/gl/Shader.h): a planted regression, every 61st pixel written lit,
    // for the checks that must catch a wrong image (expectations, compare).
    if ((px.x + px.y * 7) % 61 == 0) visibility = 1.0;
#endif
    imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_STATISTICS
    imageStore(uNodesVisited, px, vec4(float(r.visited)));
    imageStore(uOverflow, px, vec4(r.overflow ? 1.0 : 0.0));
#endif
}

void main() {
    psvReadMargins();
#if SHADOWLAB_STATISTICS
    if (gl_LocalInvocationIndex == 0u) sTraversed = sVisited = sVisitedMax = sOverflow = sCloseCalls = sStackless = sCapped = sDeferred = 0u;
    barrier();
#endif
#if PSV_QUERY_PASS == 0
    ivec2 px = pixelOfInvocation();
    if (all(lessThan(px, imageSize(uVisibility)))) queryPixel(px);
#else
    ivec2 px;
    if (pixelListEntry(px)) queryPixel(px);
#endif
#if SHADOWLAB_STATISTICS
    barrier();
    if (gl_LocalInvocationIndex == 0u && (sTraversed | sDeferred) != 0u) {
        if (sDeferred != 0u) atomicAdd(psvCounters[PSV_C_DEFERRED], sDeferred);
        atomicAdd(psvCounters[PSV_C_TRAVERSED], sTraversed);
        COUNTER_ADD_WIDE(psvCounters, PSV_C_VISITED_LO, sVisited)
        atomicMax(psvCounters[PSV_C_VISITED_MAX], sVisitedMax);
        if (sOverflow != 0u) atomicAdd(psvCounters[PSV_C_STACK_OVERFLOW], sOverflow);
        if (sCloseCalls != 0u) atomicAdd(psvCounters[PSV_C_CLOSE_CALLS], sCloseCalls);
        if (sStackless != 0u) atomicAdd(psvCounters[PSV_C_STACKLESS_WALKS], sStackless);
        if (sCapped != 0u) atomicAdd(psvCounters[PSV_C_LOOP_CAPPED], sCapped);
    }
#endif
}
