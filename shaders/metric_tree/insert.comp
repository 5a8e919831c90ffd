#version 450
// metric_tree build, pass 2 of 2 (one invocation per cluster, paper section 5.3): each cluster's
// node is filtered down the ternary metric tree from the root and linked at the empty leaf it
// reaches, with a compare-and-swap; a failed CAS returns the node another invocation linked there
// first and the descent goes on from it, so concurrent insertions neither wait nor lose a cluster.
// The pivot order is the cluster order (shuffled at preprocessing with random_order) as the
// scheduler interleaves it. The partitioning distance starts at the scene's angular radius
// (uDelta0) and is halved at every near step.
//
// A node's delta is the one field written while others read it, so it has exactly two states:
// MT_DELTA_PENDING (prepare.comp, a previous dispatch) and its final value, written once, after
// the CAS that links the node. A reader that finds the node linked but its delta still pending
// (not yet written, or not yet visible to it) files the element under the overlap child, which
// is correct for any delta: the query visits an overlap child wherever the point's distance lies
// inside [overlapMin, overlapMax], and the element's [dMin, dMax] widens that interval. So no
// reader ever compares against a delta that is not the node's final one, on any memory model.
#include "common/light.glsl"
#define MT_INSERT_PASS 1 // (test faults: tree.glsl)
#include "metric_tree/tree.glsl"
layout(local_size_x = 64) in;

uniform uint uClusterCount;
uniform uint uInvocationsPerRow;
uniform float uDelta0;

uint mtLink(uint node, uint slot, uint child) {
    if (node == 0xFFFFFFFFu) return atomicCompSwap(mtCounters[MT_C_ROOT], MT_NO_CHILD, child);
    if (slot == MT_CHILD_NEAR) return atomicCompSwap(mtNodes[node].child[0], MT_NO_CHILD, child);
    if (slot == MT_CHILD_FAR) return atomicCompSwap(mtNodes[node].child[1], MT_NO_CHILD, child);
    return atomicCompSwap(mtNodes[node].child[2], MT_NO_CHILD, child);
}

// Inserts cluster i; returns the counter its outcome adds to and the nodes it crossed.
uint insertCluster(uint i, out uint crossed) {
    crossed = 0u;
    MtNode me = mtNodes[i];
    if ((me.flags & MT_NODE_CULLED) != 0u) return MT_C_CULLED;
    vec3 a = me.a.xyz, b = me.b.xyz;
    float alpha = me.a.w, delta = uDelta0;
    uint node = 0xFFFFFFFFu, slot = 0u; // the root pointer
    uint child = mtCounters[MT_C_ROOT];
    while (true) {
        // `child` comes from the node's texels (below), which may be older than the node: a child
        // field only goes from 0 to its final value, so an older one is 0 and only makes the CAS
        // fail (it returns the current child); delta is pending or final (see the top); the light
        // distance and the overlap interval only shrink or grow, so an older value only costs an
        // atomic in vain. Nothing older than prepare.comp is seen: its barrier covers fetches.
        if (child == MT_NO_CHILD) {
            child = mtLink(node, slot, i + 1u);
            if (child == MT_NO_CHILD) {
                mtNodes[i].b.w = delta; // linked: the one write of its final delta
                return MT_C_INSERTED;
            }
        }
        if (child > uClusterCount || ++crossed > uClusterCount) return MT_C_BUILD_ERRORS;
        node = child - 1u;
        uint deltaWord;
        MtNode n = mtNode(node, deltaWord);
#if MT_DEPTH_SKIP
        // Non-negative floats order like their bits. The bound only ever decreases, so a value read
        // earlier is never below the current one: skipping the atomic when it is not smaller is
        // safe, and keeps every insertion from hammering the root's cache line.
        if (me.minDist < n.minDist) atomicMin(mtNodes[node].minDist, me.minDist);
#endif
        // Bounds on the distance from the pivot's centre to any point of this element, widened by
        // uLsEps so that they hold once rounded.
        float dMin = mtMinDist(n.a.xyz, n.b.xyz, a, b) - alpha - uLsEps;
        float dMax = alpha >= kMtPi ? kMtInf : mtMaxDist(n.a.xyz, n.b.xyz, a, b) + alpha + uLsEps;
        bool pending = deltaWord == MT_DELTA_PENDING; // the raw word, never a float round trip
        if (!pending && dMax <= n.b.w) {
            slot = MT_CHILD_NEAR;
            delta *= 0.5;
        } else if (!pending && dMin > n.b.w) {
            slot = MT_CHILD_FAR;
        } else {
            slot = MT_CHILD_OVERLAP;
#if MT_OVERLAP_INTERVAL
            // Only widening atomics, for the same reason (the interval only ever grows).
            uint lo = floatBitsToUint(max(dMin, 0.0)), hi = floatBitsToUint(dMax);
            if (lo < n.overlapMin) atomicMin(mtNodes[node].overlapMin, lo);
            if (hi > n.overlapMax) atomicMax(mtNodes[node].overlapMax, hi);
#endif
        }
        child = n.child[slot];
    }
    return MT_C_BUILD_ERRORS; // not reached
}

#if SHADOWLAB_STATISTICS
shared uint sOutcomes[4]; // MT_C_INSERTED, MT_C_CULLED, MT_C_BUILD_ERRORS at words 1..3
shared uint sCrossedMax;
#endif

void main() {
#if SHADOWLAB_STATISTICS
    if (gl_LocalInvocationIndex < 4u) sOutcomes[gl_LocalInvocationIndex] = 0u;
    if (gl_LocalInvocationIndex == 0u) sCrossedMax = 0u;
    barrier();
#endif
    uint i = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (i < uClusterCount) {
        uint crossed;
        uint outcome = insertCluster(i, crossed);
#if SHADOWLAB_STATISTICS
        atomicAdd(sOutcomes[outcome], 1u);
        atomicMax(sCrossedMax, crossed);
#else
        // The timed pass: only errors are counted (they must stay 0 and are reported in both modes).
        if (outcome == MT_C_BUILD_ERRORS) atomicAdd(mtCounters[MT_C_BUILD_ERRORS], 1u);
#endif
    }
#if SHADOWLAB_STATISTICS
    barrier();
    if (gl_LocalInvocationIndex >= 1u && gl_LocalInvocationIndex < 4u && sOutcomes[gl_LocalInvocationIndex] != 0u)
        atomicAdd(mtCounters[gl_LocalInvocationIndex], sOutcomes[gl_LocalInvocationIndex]);
    if (gl_LocalInvocationIndex == 0u) atomicMax(mtCounters[MT_C_INSERT_DEPTH_MAX], sCrossedMax);
#endif
}
