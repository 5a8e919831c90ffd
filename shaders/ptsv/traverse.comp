#version 450
// Traversal (paper 2 and Algorithm 1): a workgroup walks each of its jobs' shadow volume down the
// hierarchy, testing the 32 children of a node at once: outside any plane → rejected; inside all
// four → trivially accepted (its bit is cleared in the node's mask, resolve.comp shadows its
// samples); otherwise the additional culling planes may still reject it; else it is intersected
// and visited in turn. At the leaf level the invocations test the tile's samples (test-and-set).
//
// PTSV_PASS 1: jobs are triangles, from the root. With PTSV_TWO_PASS a node reached at depth
//              uSplitDepth is pushed as a (triangle, node) job instead of being visited (paper 2.2);
//              when the job list is full it is visited here instead (counted, never dropped).
// PTSV_PASS 2: jobs are the pushed pairs, continued from their node.
//
// PTSV_BALLOT 1: the workgroup is one subgroup of PTSV_LANES invocations (the driver's subgroup
//   width, read on the host) and votes are ARB_shader_ballot words, with no shared memory and no
//   barrier at all (a barrier anywhere in the shader costs llvmpipe 1.7x: it then runs every
//   workgroup as coroutines). The lane is gl_SubGroupInvocationARB, the bit ballots use. At entry
//   a ballot must hold exactly lanes 0 .. PTSV_LANES - 1 (gl_SubGroupSizeARB is only the largest
//   size a subgroup may have, ARB_shader_ballot section 7.4: radeonsi reports 64 and may run
//   compute in wave32): a workgroup that is not one whole subgroup (a driver free to pick
//   SIMD8/16/32, a wave32/wave64 choice) runs none of its jobs and counts itself in
//   PTSV_C_SUBGROUP_MISMATCH and its invocations run the batch's jobs alone, one job each, with no
//   vote (the frame stays exact, only slower); the host then recompiles with shared-memory votes
//   for the following frames.
//   GL does not promise that lanes reconverge after divergent code (classify(), `if (LEADER)`), so
//   every vote checks who took part: each ballot of b comes with the ballot of !b, and a lane
//   missing from both is a lane missing from the vote. A lane that sees a vote miss someone
//   goes alone for the rest of its workgroup's batch (gAlone, sticky): it classifies every node's
//   children itself (the per-invocation loop), tests every sample of a leaf, pushes its own jobs,
//   and never votes again; it counts PTSV_C_VOTE_RECOVERED. A broadcast carries its sender's lane,
//   and one that did not come from lane 0 is taken as "not pushed" (the subtree is finished here)
//   and sends the lane alone too. Sticky, because a lane that walked on alone may stand at another
//   node than the others: a later ballot that every lane answers would still mix the verdicts of
//   two nodes, and nothing in it could tell. The voting lanes then miss the lone ones in their
//   next ballot and go alone as well. Each lane walks a complete path: never a missing shadow.
// PTSV_BALLOT 0: PTSV_LANES invocations (32 unless forced), votes through shared memory and a
//   barrier.
// PTSV_LANES up to 32: each invocation tests 32 / PTSV_LANES children of a node. PTSV_LANES 64
//   (AMD's waves): two invocations per child, one testing volume planes 0-1 and culling plane 4,
//   the other planes 2-3 and culling planes 5-6; the halves' 64-bit ballots are combined, so every
//   lane of the wave works.
//
// PTSV_PER_INVOCATION 1 (traversal = invocation): every invocation runs one job of its own, testing
//   a node's existing children one after another with its own stack; no votes, no shared memory,
//   no barrier, and nothing that depends on the subgroup width. On narrow subgroups (llvmpipe's 8
//   lanes need 4 rounds per node, most of them on children that do not exist) it is the faster
//   way; the images are the same.
// PTSV_PACKET 1 (traversal = packet, with PTSV_PER_INVOCATION): in pass one the invocations of a
//   subgroup, each with its own triangle, walk the union of their paths together (traversePacket).
//
// The paper runs persistent threads, each warp taking jobs from a queue until it is empty; llvmpipe
// caps the loop iterations of one invocation at 65535 in total, so here a workgroup takes a fixed
// batch of PTSV_JOBS_PER_GROUP consecutive jobs and the hardware scheduler hands out the batches;
// a job cut short by such a cap is detected (a loop left without its exit condition) and reported.
#if (PTSV_BALLOT && !PTSV_PER_INVOCATION) || PTSV_PACKET
#extension GL_ARB_shader_ballot : require
#extension GL_ARB_gpu_shader_int64 : require
#endif
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/counters.glsl"
#include "common/list_push.glsl"
#include "common/loop_fault.glsl"
#define PTSV_TEXEL_READS 1
#include "ptsv/ptsv.glsl"
#include "common/shadow_ray.glsl"
#if PTSV_PER_INVOCATION
// Every invocation walks a job of its own: no votes, and no subgroup width to depend on.
layout(local_size_x = PTSV_INVOCATION_GROUP) in;
#define lane 0u
#define LEADER true
#define SAMPLE_STEP 1u
#else
layout(local_size_x = PTSV_LANES) in;
#if PTSV_BALLOT
#define lane gl_SubGroupInvocationARB // the bit of this invocation in a ballot
#else
#define lane gl_LocalInvocationIndex
#endif
#define LEADER (lane == 0u)
#define SAMPLE_STEP uint(PTSV_LANES)
#if PTSV_LANES != 4 && PTSV_LANES != 8 && PTSV_LANES != 16 && PTSV_LANES != 32 && PTSV_LANES != 64
#error "PTSV_LANES must be 4, 8, 16, 32 or 64"
#endif
#endif
#define ROUNDS (PTSV_LANES == 64 ? 1u : 32u / uint(PTSV_LANES)) // children tested by each invocation per node

uniform uint uTriangleCount;
uniform int uSplitDepth;    // depth of the nodes pushed by pass one (1 .. levels)
uniform uint uJobCapacity;  // entries of the job list
uniform float uTolerance;   // world units: plane values this close to 0 count as touching
uniform float uImplicitPad; // world units: how far a sample's q may lie outside its implicit node
uniform mat4 uInvView;      // view → world (implicit bounds test in view space)
uniform float uRayOffset;   // world units: the reference's shadow-ray origin offset (q is offset already)
uniform float uCloseCall;   // world units: a sample's plane value this small is too close to call

// ---- Votes ---------------------------------------------------------------------------------------
#if !PTSV_PER_INVOCATION // (a per-invocation job votes with no one)
#if !PTSV_BALLOT
// Three slots: slot i % 3 is written in vote i, read after its barrier, and cleared by invocation 0
// after the barrier of vote i + 1 (when every invocation has read it), two votes before its reuse.
// A vote holds up to three ballots of 64 bits (two words each).
shared uint sVote[3][6];
shared uint sBroadcast;
uint voteSeq = 0u;
#endif

#if PTSV_BALLOT
// Every lane of the workgroup: lanes 0 .. PTSV_LANES - 1 of one subgroup (checked in main()).
const uint64_t kAllLanes = PTSV_LANES == 64 ? ~0ul : (1ul << uint(PTSV_LANES % 64)) - 1ul;
// Test faults (framework/gl/Shader.h): lane 1 missing from every vote, as a lane that had not
// reconverged would be; a broadcast that arrives from lane 1, as if lane 0 had not been there.
#if SHADOWLAB_FAULT_VOTE_DROPS_LANE
const uint64_t kFaultDropped = 2ul;
#else
const uint64_t kFaultDropped = 0ul;
#endif
bool gVoteMissedLane = false; // a vote of the current node did not hear from every lane
bool gAlone = false;          // this lane votes no more: it walks, tests and pushes alone (see the top)
#define ALONE gAlone
// Test fault: the odd lanes miss the first vote of the workgroup (the even lanes hear everyone)
// and classify that node alone conservatively, every existing child intersected (a verdict as
// exact as any, only slower): from then on the two halves walk different nodes, as lanes that had
// not reconverged, or whose lone verdicts differed from the voted ones, would.
#if SHADOWLAB_FAULT_SPLIT_LANES
bool gFaultSplitDone = false;
#endif

// ballotARB(b), and whether every lane took part: a lane absent from the ballot of b (its bit
// lost if b was true) is absent from the ballot of !b as well only if it missed them, since each
// lane present sets its bit in exactly one of the two.
uint64_t checkedBallot(bool b) {
    uint64_t yes = ballotARB(b) & ~kFaultDropped, no = ballotARB(!b) & ~kFaultDropped;
    if ((yes | no) != kAllLanes) gVoteMissedLane = true;
    return yes;
}
#endif

// Ballots of a, b and c over the workgroup, 64 bits each as (low, high) words: bit `lane`.
void vote3(bool a, bool b, bool c, out uvec2 A, out uvec2 B, out uvec2 C) {
#if PTSV_BALLOT
    A = unpackUint2x32(checkedBallot(a));
    B = unpackUint2x32(checkedBallot(b));
    C = unpackUint2x32(checkedBallot(c));
#else
    uint slot = voteSeq % 3u, w = lane >> 5u, bit = 1u << (lane & 31u);
    if (a) atomicOr(sVote[slot][w], bit);
    if (b) atomicOr(sVote[slot][2u + w], bit);
    if (c) atomicOr(sVote[slot][4u + w], bit);
    barrier();
    A = uvec2(sVote[slot][0], sVote[slot][1]);
    B = uvec2(sVote[slot][2], sVote[slot][3]);
    C = uvec2(sVote[slot][4], sVote[slot][5]);
    if (lane == 0u) sVote[(slot + 2u) % 3u] = uint[6](0u, 0u, 0u, 0u, 0u, 0u);
    ++voteSeq;
#endif
}

// Bit `lane` of x: a, bit `lane` of y: b, over a workgroup of at most 32 invocations.
uvec2 vote2(bool a, bool b) {
#if PTSV_BALLOT
    return uvec2(unpackUint2x32(checkedBallot(a)).x, unpackUint2x32(checkedBallot(b)).x);
#else
    uvec2 A, B, C;
    vote3(a, b, false, A, B, C);
    return uvec2(A.x, B.x);
#endif
}

// A value invocation 0 computed, for every invocation; `fallback` where it cannot be had (a
// ballot broadcast that did not come from lane 0, see the top).
uint broadcast(uint v, uint fallback) {
#if PTSV_BALLOT
    // The sender's lane travels with the value, in the same operation.
#if SHADOWLAB_FAULT_BROADCAST_MISSES_LEADER
    uvec2 r = readInvocationARB(uvec2(lane, v), 1u);
#else
    uvec2 r = readFirstInvocationARB(uvec2(lane, v));
#endif
    if (r.x == 0u) return r.y;
    atomicAdd(ptsvCounters[PTSV_C_VOTE_RECOVERED], 1u);
    gAlone = true;
    return fallback;
#else
    if (lane == 0u) sBroadcast = v;
    barrier();
    uint r = sBroadcast;
    barrier();
    return r;
#endif
}

#endif // !PTSV_PER_INVOCATION
#ifndef ALONE
#define ALONE false // shared-memory votes hear every invocation (a barrier), one job per invocation none
#endif

// ---- One job -------------------------------------------------------------------------------------
const vec4 kZero7[7] = vec4[7](vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
vec4 gPlane[7] = kZero7; // world space: edges 0..2, triangle plane 3, culling planes 4..6
vec4 gView[7] = kZero7;  // the same in view space (implicit bounds)
uint gTriangle = 0u;
uint gTests = 0u, gCloseCalls = 0u, gNodeTests = 0u, gLeafVisits = 0u, gAccepted = 0u, gIterations = 0u;
uint gIterMax = 0u, gIterSum = 0u, gJobs = 0u; // this batch's jobs, added up once at the workgroup's end
bool gTruncated = false; // a loop ended without its exit condition: the driver's iteration cap

// Classifies child `childId` at `depth` against the volume: x = rejected, y = trivially accepted.
bvec2 classify(uint childId, int depth) {
    // Written out plane by plane, with no array and no loop: an indexed array or a loop with an
    // early exit here made llvmpipe's code about 20 % slower on the peer scene (same work).
#if PTSV_EXPLICIT_BOUNDS
    vec3 bmin, bmax;
    ptsvBoxAt(uNodeOffset[depth] + childId, bmin, bmax);
    float pad = uTolerance;
#define PTSV_RANGE(i) ptsvBoxRange(gPlane[i], bmin, bmax)
#else
    vec2 xr, yr, dr;
    ptsvImplicitExtent(childId, depth, xr, yr, dr);
    float pad = uTolerance + uImplicitPad;
#define PTSV_RANGE(i) ptsvFrustumRange(gView[i], xr, yr, dr)
#endif
    vec2 r0 = PTSV_RANGE(0), r1 = PTSV_RANGE(1), r2 = PTSV_RANGE(2), r3 = PTSV_RANGE(3);
    bool rejected = max(max(r0.x, r1.x), max(r2.x, r3.x)) > pad;
    bool accepted = max(max(r0.y, r1.y), max(r2.y, r3.y)) < -pad;
#if PTSV_CULLING_PLANES
    // Only where the four planes decide nothing, as in the paper.
    if (!rejected && !accepted)
        rejected = max(max(PTSV_RANGE(4).x, PTSV_RANGE(5).x), PTSV_RANGE(6).x) > pad;
#endif
#undef PTSV_RANGE
    return bvec2(rejected, accepted && !rejected);
}

#if PTSV_LANES == 64
// Half of classify(): volume planes 2 side, 2 side + 1 and the culling planes 4 (side 0) or 5, 6
// (side 1), unconditionally (visit() applies them where the four planes decide nothing).
// x = rejected by one of its volume planes, y = inside both, z = rejected by a culling plane.
bvec3 classifyHalf(uint childId, int depth, uint side) {
#if PTSV_EXPLICIT_BOUNDS
    vec3 bmin, bmax;
    ptsvBoxAt(uNodeOffset[depth] + childId, bmin, bmax);
    float pad = uTolerance;
#define PTSV_RANGE(i) ptsvBoxRange(gPlane[i], bmin, bmax)
#else
    vec2 xr, yr, dr;
    ptsvImplicitExtent(childId, depth, xr, yr, dr);
    float pad = uTolerance + uImplicitPad;
#define PTSV_RANGE(i) ptsvFrustumRange(gView[i], xr, yr, dr)
#endif
    bool rejected = false, accepted = true, culled = false;
    for (int k = 0; k < 2; ++k) {
        vec2 r = PTSV_RANGE(int(2u * side) + k);
        rejected = rejected || r.x > pad;
        accepted = accepted && r.y < -pad;
    }
#if PTSV_CULLING_PLANES
    for (int i = side == 0u ? 4 : 5; i < (side == 0u ? 5 : 7); ++i) culled = culled || PTSV_RANGE(i).x > pad;
#endif
#undef PTSV_RANGE
    return bvec3(rejected, accepted, culled);
}
#endif

// A walk cut short (rule 13) leaves its pixels shadowed: the children of node (depth, id) it had
// still to visit are marked accepted in that node's mask, so resolve.comp shadows their samples.
// (It is counted in PTSV_C_TRUNCATED, an overflow.)
void shadowUnvisited(int depth, uint id, uint children) {
    if (children != 0u) atomicAnd(ptsvMasks[uMaskOffset[depth] + id], ~children);
}

// Where sample q lies against the current triangle's shadow volume, by its four planes: 1 inside,
// 0 outside, 2 too close to call (one plane value within uCloseCall of 0, where the rounding of
// the plane and of the reference's ray test could disagree).
uint volumeSide(vec3 q) {
    vec4 v = vec4(ptsvSigned(gPlane[0], q), ptsvSigned(gPlane[1], q), ptsvSigned(gPlane[2], q), ptsvSigned(gPlane[3], q));
    if (any(greaterThan(v, vec4(uCloseCall)))) return 0u;
    return all(lessThan(v, vec4(-uCloseCall))) ? 1u : 2u;
}

// Tests the samples of cluster `key`'s tile against the volume and marks the shadowed ones. A
// sample too close to call is decided by the reference's ray test, outside the sample loop: a SIMD
// back end (llvmpipe) runs a branch's body for the whole group, so inside it would cost every test.
void testSamples(uint key) {
    ++gIterations;
    uvec3 lo, hi;
    ptsvNodeRange(key, uLevels, lo, hi);
    uint first = (lo.y * uint(uTilesX) + lo.x) * ptsvTileSamples();
    // A lane alone tests every sample; voting lanes share them out.
    uint step = ALONE ? 1u : SAMPLE_STEP;
    uint s = ALONE ? 0u : lane;
    while (s < ptsvTileSamples()) {
        FAULT_LOOP_STEP()
        uint closeSlot = 0xFFFFFFFFu;
        vec3 closeQ = vec3(0.0);
        for (; s < ptsvTileSamples(); s += step) {
            FAULT_LOOP_STEP()
            uvec4 slot = ptsvSlotAt(first + s); // q and key in one fetch
            uint k = slot.w;
#if PTSV_LEAF_CLUSTER_ONLY
            if (k != key) continue;
#else
            if (k >= PTSV_KEY_AWAY) continue;
#endif
            ++gTests;
#if PTSV_HEAT_MAP
            atomicAdd(ptsvHeat[first + s], 1u);
#endif
            vec3 q = uintBitsToFloat(slot.xyz);
            uint side = volumeSide(q);
            if (side == 1u) ptsvShadow[first + s] = 1u;
            if (side == 2u) { closeSlot = first + s; closeQ = q; s += step; break; }
        }
        if (closeSlot == 0xFFFFFFFFu) break;
        ++gCloseCalls;
        if (watertightHit(shadowRayToLight(closeQ, uRayOffset), sceneVertex(gTriangle, 0u), sceneVertex(gTriangle, 1u),
                          sceneVertex(gTriangle, 2u)))
            ptsvShadow[closeSlot] = 1u;
    }
    if (s < ptsvTileSamples()) { // cut short: the whole cluster shadowed
        gTruncated = true;
        shadowUnvisited(uLevels - 1, key >> 5u, 1u << (key & 31u));
    }
    if (LEADER) ++gLeafVisits;
}

// The existing children of node (depth, id) in `mask`, classified one after another by this
// invocation alone: x = intersected, y = trivially accepted.
uvec2 classifyAlone(int depth, uint id, uint mask, bool live) {
    uvec2 v = uvec2(0u);
    // The existing children in turn (about 9 of 32 on the peer scene).
    for (uint m = mask; m != 0u; m &= m - 1u) {
        uint c = uint(findLSB(m));
        if (!live) continue; // inside the loop: faster on llvmpipe than around the call (packets)
        bvec2 r = classify(id * 32u + c, depth + 1);
        ++gNodeTests;
        if (!r.x) v |= (r.y ? uvec2(0u, 1u) : uvec2(1u, 0u)) << c;
    }
    return v;
}

// Tests the children of node (depth, id); returns the intersected ones, clears the accepted ones.
// `live` false (a packet lane whose own volume missed the node, one job per invocation only): none.
uint visit(int depth, uint id, bool live) {
    ++gIterations;
    uint maskIndex = uMaskOffset[depth] + id;
    uint mask = ptsvMaskAt(maskIndex);
    uvec2 v = uvec2(0u);
    bool clearsAlone = false; // this lane clears the accepted children itself (not only the leader)
#if PTSV_BALLOT && !PTSV_PER_INVOCATION
    gVoteMissedLane = false;
#endif
#if PTSV_PER_INVOCATION
    v = classifyAlone(depth, id, mask, live);
#else
    if (ALONE) {
        v = classifyAlone(depth, id, mask, true);
    } else {
#if PTSV_LANES == 64
    uint c = lane & 31u, side = lane >> 5u;
    bool exists = ((mask >> c) & 1u) != 0u;
    bvec3 r = exists ? classifyHalf(id * 32u + c, depth + 1, side) : bvec3(true, false, false);
    if (exists && side == 0u) ++gNodeTests;
    uvec2 R, A, C;
    vote3(r.x, r.y, r.z, R, A, C);
    // classify() of the whole child: rejected by a volume plane, or by a culling plane where the
    // volume planes decide nothing; accepted inside all four and not rejected.
    uint rejected4 = R.x | R.y, accepted4 = A.x & A.y;
    uint rejected = rejected4 | ((C.x | C.y) & ~accepted4);
    uint accepted = accepted4 & ~rejected4;
    v = uvec2(mask & ~rejected & ~accepted, mask & accepted);
#else
    for (uint round = 0u; round < ROUNDS; ++round) {
        uint c = round * uint(PTSV_LANES) + lane;
        bool exists = ((mask >> c) & 1u) != 0u;
        bvec2 r = exists ? classify(id * 32u + c, depth + 1) : bvec2(true, false);
        if (exists) ++gNodeTests;
        v |= vote2(!r.x && !r.y, r.y) << (round * uint(PTSV_LANES));
    }
#endif
#if PTSV_BALLOT
    bool faultSplit = false;
#if SHADOWLAB_FAULT_SPLIT_LANES
    faultSplit = !gFaultSplitDone && (lane & 1u) == 1u;
    gFaultSplitDone = true;
#endif
    if (gVoteMissedLane || faultSplit) { // the votes cannot be trusted: this lane decides alone, from now on
        v = faultSplit ? uvec2(mask, 0u) : classifyAlone(depth, id, mask, true);
        atomicAdd(ptsvCounters[PTSV_C_VOTE_RECOVERED], 1u);
        gAlone = true;
    }
#endif
    }
#endif
#if PTSV_BALLOT && !PTSV_PER_INVOCATION
    // With ballots every lane that accepts a child clears it: after a recovery the lanes' verdicts
    // may differ (each is exact), and a lane that accepted a node does not test its samples.
    clearsAlone = true;
#endif
    if (v.y != 0u && (LEADER || clearsAlone)) {
        atomicAnd(ptsvMasks[maskIndex], ~v.y);
        if (LEADER) gAccepted += uint(bitCount(v.y));
    }
#if PTSV_PER_INVOCATION && PTSV_PASS == 1 && PTSV_TWO_PASS
    // Children at the split depth become jobs here, with one atomic for all of them; those a full
    // list leaves out are returned, and the walk visits them itself.
    if (depth + 1 == uSplitDepth && v.x != 0u) {
        uint slot;
        LIST_RESERVE(ptsvCounters[PTSV_C_JOBS_PUSHED], uint(bitCount(v.x)), uJobCapacity, slot);
        uint kept = 0u;
        for (uint m = v.x; m != 0u; m &= m - 1u, ++slot) {
            uint c = uint(findLSB(m));
            if (slot < uJobCapacity) ptsvJobs[slot] = uvec2(gTriangle, id * 32u + c);
            else kept |= 1u << c;
        }
        if (kept != 0u) atomicAdd(ptsvCounters[PTSV_C_JOB_OVERFLOW], uint(bitCount(kept)));
        v.x = kept;
    }
#endif
    return v.x;
}

// Depth-first walk below node (depth, id). Entry d of the stack holds the intersected children
// still to visit of the node on the path at depth d; every invocation of a job keeps the same stack.
void traverse(int depth, uint id) {
    uint stackMask[PTSV_MAX_LEVELS];
    int top = depth;
    uint node = id; // visited at depth top; node ids are key prefixes, so its parent is node >> 5
    stackMask[top] = visit(depth, id, true);
    while (true) {
        FAULT_LOOP_STEP()
        while (top >= depth && stackMask[top] == 0u) { // deepest level with children left
            --top;
            node >>= 5u;
        }
        if (top < depth) break;
        int c = findLSB(stackMask[top]);
        stackMask[top] &= stackMask[top] - 1u;
        uint childId = node * 32u + uint(c);
        int childDepth = top + 1;
#if PTSV_PASS == 1 && PTSV_TWO_PASS && !PTSV_PER_INVOCATION
        if (childDepth == uSplitDepth) {
            uint slot = 0u;
            bool alone = ALONE; // a lane alone pushes its own jobs (the leader may push them too)
            if (LEADER || alone) {
                LIST_RESERVE(ptsvCounters[PTSV_C_JOBS_PUSHED], 1u, uJobCapacity, slot);
                if (slot < uJobCapacity) ptsvJobs[slot] = uvec2(gTriangle, childId);
                else atomicAdd(ptsvCounters[PTSV_C_JOB_OVERFLOW], 1u);
            }
            if (!alone) slot = broadcast(slot, uJobCapacity);
            if (slot < uJobCapacity) continue; // pass two finishes it
            // The list is full: finish this subtree here, exactly as the one-pass traversal would.
        }
#endif
        if (childDepth == uLevels) {
            testSamples(childId);
            continue;
        }
        top = childDepth;
        node = childId;
        stackMask[top] = visit(childDepth, childId, true);
    }
    if (top >= depth) { // cut short: every subtree still on the stack shadowed
        gTruncated = true;
        for (int d = top; d >= depth; --d, node >>= 5u) shadowUnvisited(d, node, stackMask[d]);
    }
}

#if PTSV_PACKET && PTSV_PASS == 1
// Pass one as packets (traversal = packet): the invocations of a subgroup, each with a triangle of
// its own (consecutive triangles: neighbours in the mesh, whose volumes take the same paths), walk
// the hierarchy together. At a node every lane classifies the children for its own triangle, only
// where its own volume reached the node; the packet then visits the union of the children its
// lanes intersect. The lanes stay on one node, so the child loop has one length for all of them.

// OR of x over the subgroup (every invocation must call it: its lanes read each other's x).
uint orLanes(uint x) {
    uint u = 0u;
    for (uint l = 0u; l < gl_SubGroupSizeARB; ++l) u |= readInvocationARB(x, l);
    return u;
}

// The packet's depth-first walk from the root; `live`: this lane has a triangle.
void traversePacket(bool live) {
    uint own[PTSV_MAX_LEVELS], any[PTSV_MAX_LEVELS]; // this lane's children left; the packet's
    int top = 0;
    uint node = 0u;
    // A lane classifies only where its own volume reached (visit()'s `live`).
    own[0] = visit(0, 0u, live);
    any[0] = orLanes(own[0]);
    while (true) {
        FAULT_LOOP_STEP()
        while (top >= 0 && any[top] == 0u) {
            --top;
            node >>= 5u;
        }
        if (top < 0) break;
        int c = findLSB(any[top]);
        any[top] &= any[top] - 1u;
        bool mine = ((own[top] >> uint(c)) & 1u) != 0u;
        own[top] &= ~(1u << uint(c));
        uint childId = node * 32u + uint(c);
        int childDepth = top + 1;
        if (childDepth == uLevels) {
            if (mine) testSamples(childId);
            continue;
        }
        top = childDepth;
        node = childId;
        own[top] = visit(childDepth, childId, mine);
        any[top] = orLanes(own[top]);
    }
    if (top >= 0) { // cut short: this lane's subtrees still on the stack shadowed
        gTruncated = true;
        for (int d = top; d >= 0; --d, node >>= 5u) shadowUnvisited(d, node, own[d]);
    }
}
#endif

void loadTriangle(uint t) {
    gTriangle = t;
#if PTSV_PASS == 2
    uint planes = uSplitDepth == uLevels ? 4u : 7u; // a cluster's samples need the volume's planes only
#else
    const uint planes = 7u;
#endif
    for (uint i = 0u; i < planes; ++i) {
        gPlane[i] = ptsvPlane(t, i);
#if !PTSV_EXPLICIT_BOUNDS
        gView[i] = gPlane[i] * uInvView; // row vector: the plane's values carry over to view space
#endif
    }
}

// Per job: the Figure 7 statistics (invocation 0 speaks for the workgroup), summed over the batch
// and added with three atomics per workgroup at its end, not per job; compiled out in the timed pass.
void finishJob(uint job) {
#if SHADOWLAB_STATISTICS
    if (!LEADER) return;
#if PTSV_JOB_ITERATIONS
    ptsvJobIterations[PTSV_PASS == 1 ? job : uTriangleCount + job] = gIterations;
#endif
    gIterMax = max(gIterMax, gIterations);
    gIterSum += gIterations;
    ++gJobs;
#endif // SHADOWLAB_STATISTICS
}

// Job `job` from the start (pass one: a triangle from the root) or from its node (pass two).
void runJob(uint job) {
    gIterations = 0u;
#if PTSV_PASS == 1
    if (ptsvStatus(job) != PTSV_CASTER_OK) return;
    loadTriangle(job);
    traverse(0, 0u);
#else
    uvec2 pair = ptsvJobs[job];
    loadTriangle(pair.x);
    if (uSplitDepth == uLevels) testSamples(pair.y); // the job is a leaf cluster
    else traverse(uSplitDepth, pair.y);
#endif
    finishJob(job);
}

void main() {
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
#if PTSV_PASS == 1
    uint count = uTriangleCount;
#else
    uint count = min(ptsvCounters[PTSV_C_JOBS_PUSHED], uJobCapacity);
#endif
#if PTSV_PACKET && PTSV_PASS == 1
    // Every invocation of a subgroup takes part in its packet's walk, with a triangle or without.
    uint job = group * uint(PTSV_INVOCATION_GROUP) + gl_LocalInvocationIndex;
    bool live = job < count && ptsvStatus(job) == PTSV_CASTER_OK;
    if (live) loadTriangle(job);
    gIterations = 0u;
    traversePacket(live);
    if (live) finishJob(job);
#elif PTSV_PER_INVOCATION
    // One job per invocation (2D grid past 65535 groups).
    uint job = group * uint(PTSV_INVOCATION_GROUP) + gl_LocalInvocationIndex;
    if (job < count) runJob(job);
#else
    // Each workgroup takes PTSV_JOBS_PER_GROUP consecutive jobs (2D grid past 65535 groups).
#if PTSV_BALLOT
    // Ballots only see one subgroup: the workgroup must be exactly one, its lanes 0 .. PTSV_LANES - 1
    // (see the top). Checked here, before any divergent code, with the ballot itself.
#if SHADOWLAB_FAULT_SUBGROUP_MISMATCH
    const bool mismatch = true; // test fault: as a driver that split the workgroup
#else
    bool mismatch = ballotARB(true) != kAllLanes;
#endif
    if (mismatch) {
        // Not one whole subgroup: every invocation runs jobs of the batch alone (no vote).
        if (gl_LocalInvocationIndex == 0u) atomicAdd(ptsvCounters[PTSV_C_SUBGROUP_MISMATCH], 1u);
        gAlone = true;
        for (uint k = gl_LocalInvocationIndex; k < uint(PTSV_JOBS_PER_GROUP); k += uint(PTSV_LANES)) {
            uint job = group * uint(PTSV_JOBS_PER_GROUP) + k;
            if (job >= count) break;
            runJob(job);
        }
    } else
#else
    if (lane == 0u) sVote[0] = sVote[1] = sVote[2] = uint[6](0u, 0u, 0u, 0u, 0u, 0u);
    barrier();
#endif
    for (uint k = 0u; k < uint(PTSV_JOBS_PER_GROUP); ++k) {
        uint job = group * uint(PTSV_JOBS_PER_GROUP) + k;
        if (job >= count) break; // the same for the whole workgroup
        runJob(job);
    }
#endif
    // Totals (no barrier: one atomic per invocation that has something to add). Truncation is
    // an error, counted in both modes.
    if (gTruncated) atomicAdd(ptsvCounters[PTSV_C_TRUNCATED], 1u);
#if SHADOWLAB_STATISTICS
    if (gTests != 0u) COUNTER_ADD_WIDE(ptsvCounters, PTSV_C_TESTS_LO, gTests)
    if (gNodeTests != 0u) COUNTER_ADD_WIDE(ptsvCounters, PTSV_C_NODE_TESTS_LO, gNodeTests)
    if (gCloseCalls != 0u) atomicAdd(ptsvCounters[PTSV_C_CLOSE_CALLS], gCloseCalls);
    if (LEADER) {
        if (gAccepted != 0u) atomicAdd(ptsvCounters[PTSV_C_ACCEPTED], gAccepted);
        if (gLeafVisits != 0u) atomicAdd(ptsvCounters[PTSV_C_LEAF_VISITS], gLeafVisits);
        if (gJobs != 0u) { // the batch's per-job statistics, three atomics per workgroup
#if PTSV_PASS == 1
            atomicMax(ptsvCounters[PTSV_C_ITER_MAX_1], gIterMax);
            atomicAdd(ptsvCounters[PTSV_C_ITER_SUM_1], gIterSum);
            atomicAdd(ptsvCounters[PTSV_C_JOBS_1], gJobs);
#else
            atomicMax(ptsvCounters[PTSV_C_ITER_MAX_2], gIterMax);
            atomicAdd(ptsvCounters[PTSV_C_ITER_SUM_2], gIterSum);
#endif
        }
    }
#endif
}
