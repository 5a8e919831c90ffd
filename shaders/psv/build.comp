#version 450
// PSV build, pass 2 of 2: Algorithm 1 of the paper. Invocation k merges triangle perm(k) into the
// TOP tree: it filters the triangle down from the root and replaces the empty leaf it reaches by
// its own frustum's first node, with a compare-and-swap on the leaf's child field. A failed CAS
// returns the frustum another invocation linked there first; the descent simply goes on from it,
// so concurrent insertions never lose a triangle and never wait for each other (lock-free).
// The nodes themselves were written by frusta.comp, before this dispatch.
#include "common/light.glsl"
#define SCENE_POSITION_TEXELS 1
#include "common/scene.glsl"
#include "psv/tree.glsl"
layout(local_size_x = 64) in;

uniform uint uInvocationsPerRow; // gl_NumWorkGroups.x * 64: 2D dispatch past 65535 groups

#define SLOT_POS 0u
#define SLOT_INTER 1u
#define SLOT_NEG 2u // capping nodes only: a shadow plane's negative child is its index + 1

// A node's child fields (pos, inter, wedgeOrNeg, minDepth) as this invocation sees them, through the
// buffer texture: other invocations change them during the dispatch, and a texel fetch may return
// an older value. A child field only ever goes from 0 to its final value (one successful
// compare-and-swap), so an older value is 0, which only makes the compare-and-swap below fail and
// return the current child; a wedge only grows, so an older one only costs an atomicMax in vain.
// Nothing older than this frame's frusta.comp is seen: its barrier includes texture fetches.
uvec4 psvFields(uint node) { return texelFetch(uPsvNodeTexels, int(2u * node + 1u)); }

uint psvChild(uvec4 fields, uint slot) { return slot == SLOT_POS ? fields.x : (slot == SLOT_INTER ? fields.y : fields.z); }

uint psvLinkChild(uint node, uint slot, uint child) {
    if (slot == SLOT_POS) return atomicCompSwap(psvNodes[node].pos, 0u, child);
    if (slot == SLOT_INTER) return atomicCompSwap(psvNodes[node].inter, 0u, child);
    return atomicCompSwap(psvNodes[node].wedgeOrNeg, 0u, child);
}

// Merges triangle t; returns the counter its outcome adds to (PSV_C_*), and the nodes it tested.
uint insertTriangle(uint t, out uint tested) {
    tested = 0u;
    // The status frusta.comp decided and stored: never decided again here (see frusta.comp).
    uint status = psvStoredStatus(t);
    if (status == uint(PSV_CASTER_EDGE_ON)) return PSV_C_CULLED_EDGE_ON;
    if (status == uint(PSV_CASTER_FACING)) return PSV_C_CULLED_FACING;
    if (status == uint(PSV_CASTER_OUTSIDE_CONE)) return PSV_C_CULLED_CONE;
    if (status != uint(PSV_CASTER_OK)) return PSV_C_BUILD_ERRORS;
    vec3 v0 = sceneVertex(t, 0u), v1 = sceneVertex(t, 1u), v2 = sceneVertex(t, 2u);
    uint root = PSV_NODES_PER_TRIANGLE * t + 1u;
    uint nodeCount = PSV_NODES_PER_TRIANGLE * uTriangleCount + 1u;
#if PSV_DEPTH_SKIP
    uint depthBits = floatBitsToUint(psvTriangleMinDepth(v0, v1, v2));
#endif
#if PSV_WEDGE
    PsvWedgeTriangle wedgeTriangle = psvWedgeTriangle(v0, v1, v2);
#endif
    uint node = 0u, slot = SLOT_POS; // the sentinel's `pos` holds the root
    // The stackless walks' escape: the last node whose intersection child this descent took. A
    // child field is set once, so the path this thread walks is the path to its frustum for good.
    uint escape = 0u;
    bool linked = false;
    uvec4 fields = psvFields(0u);
    while (true) {
        if (slot == SLOT_INTER) escape = node;
        uint child = psvChild(fields, slot);
        if (child == 0u) {
            child = psvLinkChild(node, slot, root);
            if (child == 0u) { linked = true; break; } // the escape is stored below, out of the loop
        }
        // Every link points at the first node of a frustum; anything else is a corrupt tree.
        if (child >= nodeCount || child % PSV_NODES_PER_TRIANGLE != 1u) return PSV_C_BUILD_ERRORS;
        node = child;
        bool widen = false; // a shadow plane the triangle straddles: its wedge may have to grow
        vec4 plane;
        while (true) { // down the frustum's own nodes until a child field has to be followed
            // A frustum adds at most 4 levels, so a longer descent can only be a cycle.
            if (++tested > nodeCount) return PSV_C_BUILD_ERRORS;
            plane = psvPlane(node); // written by frusta.comp: fixed here
            int c = psvClassify(plane, v0, v1, v2);
            if (node % PSV_NODES_PER_TRIANGLE != 0u) { // shadow plane
                if (c < 0) { ++node; continue; }
                widen = c == 0;
                slot = c == 0 ? SLOT_INTER : SLOT_POS;
                break;
            }
#if !PSV_TRANSPARENCY
            // Strictly behind an opaque caster inside its frustum: this triangle's own frustum lies
            // inside that one, and the opaque query never visits a capping node's negative child.
            if (c < 0) return PSV_C_CULLED_OCCLUDED;
#endif
#if PSV_DEPTH_SKIP
            atomicMin(psvNodes[node].minDepth, depthBits);
#endif
            slot = c > 0 ? SLOT_POS : (c == 0 ? SLOT_INTER : SLOT_NEG);
            break;
        }
        fields = psvFields(node); // one fetch per node left: its wedge and the child to follow
#if PSV_WEDGE
        // Non-negative floats order like their bit patterns: an integer max suffices.
        if (widen && psvWedgeBound(plane, wedgeTriangle) > uintBitsToFloat(fields.z))
            atomicMax(psvNodes[node].wedgeOrNeg, floatBitsToUint(psvWedge(plane, wedgeTriangle)));
#endif
    }
    // A loop the device ended from outside (rule 13) linked nothing: an error, counted.
    if (!linked) return PSV_C_BUILD_ERRORS;
    // Read by the query only, after this dispatch (nothing in the build reads it). A store inside
    // the descent loop would cost every step on a SIMD back end, whichever lanes take it.
    psvNodes[root + PSV_ESCAPE_NODE].minDepth = escape;
    return PSV_C_INSERTED;
}

#if PSV_C_INSERTED != 0 || PSV_C_CULLED_FACING != 1 || PSV_C_CULLED_EDGE_ON != 2 || PSV_C_CULLED_OCCLUDED != 3 || PSV_C_BUILD_ERRORS != 4
#error "sOutcomes below is indexed by the outcome counters, which must be words 0..4"
#endif
#if SHADOWLAB_STATISTICS
shared uint sOutcomes[5]; // PSV_C_INSERTED .. PSV_C_BUILD_ERRORS
shared uint sTestedMax, sCone;
#endif

void main() {
    psvReadMargins();
#if SHADOWLAB_STATISTICS
    // Counters are summed per work group first: one global atomic per group and outcome.
    if (gl_LocalInvocationIndex < 5u) sOutcomes[gl_LocalInvocationIndex] = 0u;
    if (gl_LocalInvocationIndex == 0u) sTestedMax = sCone = 0u;
    barrier();
#endif
    uint k = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (k < uTriangleCount) {
        uint tested;
        uint outcome = insertTriangle(psvPermute(k), tested);
#if SHADOWLAB_STATISTICS
        if (outcome == PSV_C_CULLED_CONE) atomicAdd(sCone, 1u);
        else atomicAdd(sOutcomes[outcome], 1u);
        atomicMax(sTestedMax, tested);
#else
        // The timed pass: only errors are counted (they must stay 0 and are reported in both modes).
        if (outcome == PSV_C_BUILD_ERRORS) atomicAdd(psvCounters[PSV_C_BUILD_ERRORS], 1u);
#endif
    }
#if SHADOWLAB_STATISTICS
    barrier();
    if (gl_LocalInvocationIndex < 5u && sOutcomes[gl_LocalInvocationIndex] != 0u)
        atomicAdd(psvCounters[gl_LocalInvocationIndex], sOutcomes[gl_LocalInvocationIndex]);
    if (gl_LocalInvocationIndex == 0u) atomicMax(psvCounters[PSV_C_INSERT_DEPTH_MAX], sTestedMax);
    if (gl_LocalInvocationIndex == 0u && sCone != 0u) atomicAdd(psvCounters[PSV_C_CULLED_CONE], sCone);
#endif
}
