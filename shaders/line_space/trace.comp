#version 450
// line_space: shadow rays answered from the precomputed line space alone (Keul et al. 2017,
// Algorithm 1), one invocation per pixel. No triangle is read outside the start region (and none at
// all with LS_START_NODE or LS_START_DISTANCE). Per ray (the reference's rays:
// origin p + n * offset, towards each light sample, ending `offset` short of it):
//   * a node the ray crosses is looked up by the shaft between its entry and exit sub-faces:
//     empty → skipped whole; non-empty on the last subdivided level (d - 1) → the ray is occluded;
//     otherwise its children are visited front to back (3D DDA) and the non-empty ones recursed into;
//   * a node of the start region cannot use its line space: its shaft holds the part of the ray next
//     to the receiver, whose own surface fills the leaves there. Above the last level its children
//     are visited. On the last level, by LS_START_MODE:
//       LS_START_NODE (the paper's Algorithm 1: the start region is the node holding the origin):
//         skipped (paper 4.1: the loss of detail near the receiver);
//       LS_START_DISTANCE (the start region ends at tS, from the receiver's normal and the leaf
//         size, see startRegionEnd): geometry before tS ignored, its leaves walked from tS with the
//         node's occupancy mask (an occupied leaf blocks);
//       LS_START_EXACT (the same region, no geometry ignored): its occupied leaves' triangles are
//         tested exactly against the ray (a hybrid: the start region exact, the rest line space);
//         with LS_CULL_TRIANGLES ruled out by their planes first;
//       LS_START_BVH (the distance region's walk, and the segment before tS traced exactly through
//         bvh_raytrace's BVH: nothing ignored).
//   * a non-empty shaft of a last-level node ("deep enough") blocks the ray (Algorithm 1), or with
//     LS_LAST_LEAVES the leaves the ray crosses in that node decide, by the node's occupancy mask;
//     with LS_LEAF_SPLIT > 1 an occupied leaf's sub-cells decide in its place.
// Compile-time: LS_N (branching factor), LS_DEPTH (d), LS_CLASSIFY (write per-sample results),
// LS_BIT_CHUNK_COUNT (storage blocks the line-space pool spans), LS_START_MODE, LS_LAST_LEAVES,
// LS_LEAF_SPLIT, LS_CULL_TRIANGLES, SHADOWLAB_SIMD_PROBE.
//
// One dispatch traces the samples [uSampleFirst, uSampleEnd) of every pixel (at most
// samples_per_dispatch of them, so that no dispatch runs into a GPU driver's watchdog); a light with
// more samples takes several dispatches, which carry each pixel's state in the accumulation image
// (layout.glsl), and the last one writes visibility: the image a single dispatch would write.
//
// Every loop is bounded by an integer count derived from the structure (uWalkCap, uLeafWalkCap):
// the DDAs end by float comparisons (t > tEnd, cellEnd > t1) and by the cell leaving the node, and a
// NaN step would leave the comparison false and the cell where it is forever (every comparison with
// a NaN is false). GLSL does not promise that a loop ends; a GPU runs an endless one until its
// driver's watchdog resets the device. A ray whose walk reaches its cap is blocked and its pixel
// written shadowed and counted (LS_C_CAPPED, overflowCount()), never lit by mistake.
#include "line_space/layout.glsl"
#define SIMD_PROBE_SECTIONS LS_SIMD_SECTIONS
#include "common/simd_probe.glsl"
#include "common/statistics.glsl"
#include "common/light.glsl"
#include "common/counters.glsl"
#define LS_START_NODE 0
#define LS_START_DISTANCE 1
#define LS_START_EXACT 2
#define LS_START_BVH 3
// (Includes expand once, whatever #if surrounds them: each file is included where every mode that
// reads it sees it.)
#if LS_START_MODE == LS_START_EXACT || LS_START_MODE == LS_START_BVH
#include "common/watertight.glsl"
#endif
#if LS_START_MODE == LS_START_EXACT
#define SCENE_POSITION_TEXELS 1
#include "common/scene.glsl"
#endif
#if LS_START_MODE == LS_START_BVH
// The near field: the segment before the start region's end, traced exactly through the scene's
// BVH (framework/accel, common/bvh_traverse.glsl; any hit ends it); the line space walks from the
// region's end as LS_START_DISTANCE does, so nothing is ignored.
#define BVH_TRAVERSE_NODE_UNIT LS_BVH_NODE_UNIT
#define BVH_TRAVERSE_TRI_UNIT LS_BVH_TRI_UNIT
#define BVH_TICK_NODE() SIMD_TICK(LS_SIMD_NEAR_NODE)
#define BVH_TICK_TRI() SIMD_TICK(LS_SIMD_NEAR_TRI)
#include "common/bvh_traverse.glsl"
#endif
layout(local_size_x = 8, local_size_y = 8) in;

struct LsNode { // 32 bytes, mirrored by ls::NodeGpu (algorithms/line_space/NTree.h)
    vec3 lo; uint children;
    vec3 size; uint level;
};
// The pools are read through buffer textures over their buffers (LineSpace binds them to the
// LS_*_UNIT units, layout.glsl), and the exact start region's vertices through the scene's
// (SCENE_POSITION_TEXELS): a SIMD CPU back end (llvmpipe) gathers a texel fetch for all its lanes
// at once but loads storage buffers lane by lane; a GPU reads both through its caches.
layout(binding = LS_NODE_UNIT) uniform usamplerBuffer uLsNodeTexels; // RGBA32UI, 2 texels per node
layout(binding = LS_TREE_UNIT) uniform usamplerBuffer uLsTreeTexels; // R32UI, one texel per word (likewise below)
layout(binding = LS_BITS_UNIT) uniform usamplerBuffer uLsBitsTexels0;
#if LS_BIT_CHUNK_COUNT > 1
layout(binding = LS_BITS_UNIT + 1) uniform usamplerBuffer uLsBitsTexels1;
layout(binding = LS_BITS_UNIT + 2) uniform usamplerBuffer uLsBitsTexels2;
layout(binding = LS_BITS_UNIT + 3) uniform usamplerBuffer uLsBitsTexels3;
#endif
#if LS_START_MODE != LS_START_NODE || LS_LAST_LEAVES
layout(binding = LS_OCC_UNIT) uniform usamplerBuffer uLsOccTexels;
uint lsOcc(uint word) { return texelFetch(uLsOccTexels, int(word)).x; }
#endif
#ifndef LS_LEAF_SPLIT
#define LS_LEAF_SPLIT 1
#endif
#if LS_START_MODE == LS_START_EXACT || LS_LEAF_SPLIT > 1
// Per node and occupancy word the number of the occupied leaves before it (ls::LeafLists): an
// occupied leaf's rank, by which its list and its sub-cells are found.
layout(binding = LS_LEAF_RANK_UNIT) uniform usamplerBuffer uLsLeafRankTexels;
uint lsLeafRank(uint word) { return texelFetch(uLsLeafRankTexels, int(word)).x; }
// The rank of occupied leaf `leaf` of a last-level node whose occupancy word `word` holds `bits`:
// the occupied leaves before its word, plus those below it in the word.
uint leafRank(uint word, uint bits, uint leaf) { return lsLeafRank(word) + uint(bitCount(bits & ((1u << (leaf & 31u)) - 1u))); }
#endif
#if LS_LEAF_SPLIT > 1
layout(binding = LS_LEAF_SUB_UNIT) uniform usamplerBuffer uLsLeafSubTexels; // per occupied leaf: its sub-cells' bits
#endif
#if LS_START_MODE == LS_START_EXACT
// The leaf lists (ls::LeafLists): per occupied leaf the start of its triangles (plus one end), the
// triangles (scene indices, vertices from the scene's positions).
layout(binding = LS_LEAF_PREFIX_UNIT) uniform usamplerBuffer uLsLeafPrefixTexels;
layout(binding = LS_LEAF_TRIS_UNIT) uniform usamplerBuffer uLsLeafTrisTexels;
uint lsLeafPrefix(uint leaf) { return texelFetch(uLsLeafPrefixTexels, int(leaf)).x; }
uint lsLeafTri(uint i) { return texelFetch(uLsLeafTrisTexels, int(i)).x; }
#if LS_CULL_TRIANGLES
layout(binding = LS_TRI_PLANE_UNIT) uniform samplerBuffer uLsTriPlaneTexels; // per scene triangle: unit normal, offset
vec4 lsTriPlane(uint tri) { return texelFetch(uLsTriPlaneTexels, int(tri)); }
#endif
#endif
LsNode lsNode(uint i) {
    uvec4 a = texelFetch(uLsNodeTexels, int(2u * i)), b = texelFetch(uLsNodeTexels, int(2u * i + 1u));
    return LsNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w);
}
uint lsTree(uint i) { return texelFetch(uLsTreeTexels, int(i)).x; }
layout(std430, binding = LS_SAMPLE_BINDING) readonly buffer LightSamples { vec4 lightSamples[]; };
layout(std430, binding = LS_COUNTER_BINDING) buffer LsCounters { uint lsCounters[]; };
#if LS_CLASSIFY
layout(std430, binding = LS_CLASSIFY_BINDING) buffer LsClassify { uint lsClassify[]; };
#endif

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
#if SHADOWLAB_STATISTICS
layout(r32f, binding = 1) writeonly uniform image2D uNodesVisited; // debug heat map: nodes per pixel
layout(r32f, binding = 2) writeonly uniform image2D uLoopCapped;   // 1 where a loop cap wrote the pixel shadowed
layout(rg32ui, binding = LS_ACCUM_UNIT) uniform uimage2D uAccum;   // between dispatches: x state (layout.glsl), y nodes visited
#else
layout(r32ui, binding = LS_ACCUM_UNIT) uniform uimage2D uAccum;    // between dispatches: the state (layout.glsl)
#endif
uniform float uRayOffset; // world units, the reference's
uniform int uSampleCount; // entries of lightSamples (1 for point, spot and directional lights)
uniform int uSampleFirst, uSampleEnd; // the samples this dispatch traces, [first, end)
// Most passes of one ray's walk over the tree (main) and of one leaf walk (leafWalk); LineSpace.cpp
// derives them from the tree, the reasoning is at each loop.
uniform uint uWalkCap, uLeafWalkCap;
uniform uint uNodeCount;  // 0: no geometry, nothing occludes
uniform uint uNodesPerChunk; // nodes per line-space pool chunk (see layout.glsl)
uniform vec3 uLeafCell;      // world size of a leaf cell (level d)
uniform float uStartCells;   // start_cells
uniform float uStartMaxCells; // start_max_cells
uniform float uPlaneEps;      // start_triangles culled: plane distances within this are too close to call
uniform float uLeafMargin;    // start_triangles culled: the ray's part in a leaf, widened by this (world units)

#ifndef LS_CULL_TRIANGLES
#define LS_CULL_TRIANGLES 0
#endif
#ifndef LS_BIT_CHUNK_COUNT
#define LS_BIT_CHUNK_COUNT LS_BIT_CHUNKS
#endif
const uint N2 = uint(LS_N * LS_N), N4 = N2 * N2;
const uint WORDS = uint(LS_WORDS_PER_NODE(LS_N));
const uint OCC_WORDS = uint(LS_OCC_WORDS_PER_NODE(LS_N));
const uint LS_NONE = 0xFFFFFFFFu;
const float kInf = uintBitsToFloat(0x7F800000u);

// Set when a leaf walk reaches its cap (read per ray in main).
bool gCapped = false;

// Tests only (framework/gl/Shader.h, setShaderFaultDefines): the DDA steps of every other pixel are
// NaN, as an overflowing or degenerate ray might make them on a GPU: no walk of those rays makes
// progress.
#ifndef SHADOWLAB_FAULT_NAN_STEP
#define SHADOWLAB_FAULT_NAN_STEP 0
#endif
#if SHADOWLAB_FAULT_NAN_STEP
bool gFaultPixel = false;
#endif

struct Ray {
    vec3 o, d, invD;
    float tEnd; // the segment is [0, tEnd]
};

#include "line_space/trace_cells.glsl"
#include "line_space/trace_leaves.glsl"
#include "line_space/trace_nodes.glsl"

#if SHADOWLAB_STATISTICS
shared uint sPixels, sRays, sVisited, sVisitedMax, sShafts, sCells, sOccluded, sOverflow, sLeaves, sTris, sTruncated, sCapped, sNearNodes;

void addWide(int lo, uint value) COUNTER_ADD_WIDE(lsCounters, lo, value)
#endif

// The ray from origin `o` towards light sample `s` (the light's direction when directional), ending
// `uRayOffset` short of the sample; false when the origin is on the sample (nothing to trace).
bool sampleRay(vec3 o, int s, bool directional, out Ray r) {
    r.o = o;
    if (directional) {
        r.d = -uLightDirection;
        r.tEnd = kInf;
    } else {
        vec3 d = lightSamples[s].xyz - o;
        float dist = length(d);
        if (!(dist > 0.0)) return false;
        r.d = d / dist;
        r.tEnd = max(0.0, dist - uRayOffset);
    }
    // A zero component would give 0 * inf = NaN in the slab test; 1e-30 keeps it infinite.
    vec3 safe = mix(r.d, mix(vec3(-1e-30), vec3(1e-30), greaterThanEqual(r.d, vec3(0.0))), lessThan(abs(r.d), vec3(1e-30)));
    r.invD = 1.0 / safe;
    return true;
}

// `cur` walks the children of the node on level `level`; its ancestors' walks wait in parent0..2
// (only LS_PARENTS of them are used). Per invocation, set once and reused by every ray: each ray's
// walk sets `cur` before reading it and pushes a parent before popping it.
Frame cur = Frame(0u, ivec3(0), 0, vec3(0.0), vec3(1.0), vec3(0.0), kInf, 0.0, false);
Frame parent0 = cur, parent1 = cur, parent2 = cur;

// One ray's walk through the tree from the root, then (LS_START_BVH) the near field: true when
// something blocks it. The walk ends as the method ends it (the ray free past the root, occluded,
// or an overflow) or not at all: then its cap, or the driver, stopped it, and the ray counts as
// blocked (`cut`: a walk cut short here or in a leaf walk could have met a blocker further on).
// `cells` and `overflow` add up the pixel's DDA steps and overflows.
bool rayBlocked(Ray r, vec3 nu, inout uint cells, inout uint overflow, out bool cut) {
    ivec3 up = ivec3(greaterThanEqual(r.d, vec3(0.0))), stepDir = up * 2 - 1;
    ivec3 childStep = stepDir * ivec3(1, LS_N, LS_N * LS_N);
    rayVisited = 0u;
    gCapped = false;
    bool blocked = false;
#if LS_START_MODE != LS_START_NODE
    float tS = startRegionEnd(nu, r.d);
#if LS_START_MODE == LS_START_EXACT
    exactRay = watertightRay(r.o, r.d, r.tEnd);
#endif
#else
    float tS = -kInf;
#endif
    Frame f;
    int e = uNodeCount == 0u ? ENTER_SKIP : enter(0u, true, LS_DEPTH == 1, false, tS, r, f);
    if (e == ENTER_OCCLUDED) blocked = true;
    bool finished = e != ENTER_DESCEND;
    if (e == ENTER_DESCEND) {
        cur = f;
        int level = 0;
        // Each pass of the inner loop visits one child cell of the walked node or leaves a finished
        // walk. A node's DDA moves its cell one step along one axis per cell, never back, so it
        // visits at most 3N - 2 cells before the cell leaves the node (t = inf): with the pass that
        // leaves it, 3N - 1 passes per walked node. A ray walks each node above the last level at
        // most once, and at most (3N - 2)^l of level l (one per cell its parent crosses): uWalkCap =
        // (3N - 1) * min(nodes above the last level, the sum of (3N - 2)^l).
        uint passes = 0u;
        while (!finished && passes < uWalkCap) {
            // Step the DDA to the next non-empty child, leaving finished walks: a loop of its own,
            // so that neighbouring invocations (vector lanes in lockstep) reach the node test below
            // together.
            uint node = LS_NONE;
            bool nodeStart = false;
            while (passes < uWalkCap) {
                ++passes;
                if (cur.t > cur.tEnd) { // walked past the node (or the segment's end)
                    if (level == 0) { finished = true; break; } // past the root: the ray is free
                    --level;
                    POP(level, cur);
                    continue;
                }
                ++cells;
                SIMD_TICK(LS_SIMD_WALK);
                int cell = cur.child;
                nodeStart = cur.start;
                // Advance to the next cell before descending into this one. The axis and every
                // update are selects: indexing a vector by a variable makes some compilers
                // (llvmpipe's among them) keep the frame in memory.
                float cellEnd = min(min(cur.tNext.x, cur.tNext.y), cur.tNext.z);
                bvec3 axis = stepAxis(cur.tNext, cellEnd);
                ivec3 m = ivec3(axis);
                cur.cell += m * stepDir;
                cur.child += m.x * childStep.x + m.y * childStep.y + m.z * childStep.z;
                bool outside = any(lessThan(cur.cell, ivec3(0))) || any(greaterThanEqual(cur.cell, ivec3(LS_N)));
                cur.t = outside ? kInf : cellEnd;
                vec3 ahead = cur.lo + vec3(cur.cell + up) * cur.cellSize;
                cur.tNext = mix(cur.tNext, (ahead - r.o) * r.invD, axis);
                cur.start = false;
                uint child = lsTree(cur.children + uint(cell));
                if (child != LS_EMPTY) { node = child; break; } // Algorithm 1, line 8: empty children are skipped
            }
            if (node == LS_NONE) break; // walked past the root (finished), or the cap
            e = enter(node, false, level + 1 == LS_DEPTH - 1, nodeStart, tS, r, f);
            if (e == ENTER_OCCLUDED) { blocked = true; finished = true; break; }
            if (e == ENTER_DESCEND) {
                // One frame per level above the last suffices by construction. Checked anyway, so a
                // corrupt tree shows as reported overflow, never as light.
                if (level >= LS_PARENTS) { ++overflow; blocked = true; finished = true; break; }
                PUSH(level, cur);
                ++level;
                cur = f;
            }
        }
    }
#if LS_START_MODE == LS_START_BVH
    // The near field, for the rays the line space left free (most blocked rays are blocked farther
    // out, so this order runs the BVH for fewer of them). An overflowed or capped near field could
    // have missed its blocker: blocked, and the pixel written shadowed (overflow, cap), as in
    // bvh_raytrace.
    if (!blocked && finished && !gCapped) {
        BvhTrace near = bvhTrace(bvhMakeRay(r.o, r.d, min(tS, r.tEnd)));
        nearNodes += near.visited;
        trianglesTested += near.tested;
        if (near.overflow) ++overflow;
        if (near.capped) gCapped = true;
        blocked = near.occluded || near.overflow;
    }
#endif
    cut = !finished || gCapped;
    return blocked || cut;
}

#if SHADOWLAB_STATISTICS
// The workgroup's sums into the counters, once per workgroup (after the barrier in main).
void flushWorkgroupCounters() {
    if (sPixels != 0u) atomicAdd(lsCounters[LS_C_PIXELS], sPixels);
    addWide(LS_C_RAYS_LO, sRays);
    addWide(LS_C_VISITED_LO, sVisited);
    atomicMax(lsCounters[LS_C_VISITED_MAX], sVisitedMax);
    addWide(LS_C_SHAFTS_LO, sShafts);
    addWide(LS_C_CELLS_LO, sCells);
    addWide(LS_C_LEAVES_LO, sLeaves);
    addWide(LS_C_TRIS_LO, sTris);
    addWide(LS_C_NEAR_NODES_LO, sNearNodes);
    addWide(LS_C_OCCLUDED_LO, sOccluded);
    if (sOverflow != 0u) atomicAdd(lsCounters[LS_C_OVERFLOW], sOverflow);
    if (sTruncated != 0u) atomicAdd(lsCounters[LS_C_TRUNCATED], sTruncated);
    if (sCapped != 0u) atomicAdd(lsCounters[LS_C_CAPPED], sCapped);
    SIMD_PROBE_FLUSH(addWide, lsCounters, LS_C_SIMD_BASE, LS_C_SIMD_WIDTH);
}
#endif

void main() {
#if SHADOWLAB_STATISTICS
    if (gl_LocalInvocationIndex == 0u) sPixels = sRays = sVisited = sVisitedMax = sShafts = sCells = sOccluded = sOverflow = sLeaves = sTris = sTruncated = sCapped = sNearNodes = 0u;
    SIMD_PROBE_ENTER();
    barrier();
#endif
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
#if SHADOWLAB_FAULT_NAN_STEP
    gFaultPixel = ((px.x + px.y) & 1) == 0;
#endif
    bool firstDispatch = uSampleFirst == 0, lastDispatch = uSampleEnd >= uSampleCount;
    ivec2 size = imageSize(uVisibility);
    if (all(lessThan(px, size))) {
        vec4 pos = texelFetch(uPosition, px, 0);
        float visibility = 1.0; // background: nothing to shadow (the reference's convention)
        uint visitedAll = 0u;   // nodes entered by this pixel's rays, this dispatch and the earlier ones
        bool failed = false;    // a loop was cut short: the pixel is written shadowed
#if LS_CLASSIFY
        uint stride = 1u + (uint(uSampleCount) + 31u) / 32u;
        uint base = uint(px.y * size.x + px.x) * stride;
        uint pixelStartNode = LS_NONE;
        if (firstDispatch)
            for (uint w = 1u; w < stride; ++w) lsClassify[base + w] = 0u;
#endif
        if (pos.w >= 0.5) {
            vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
            visibility = 0.0; // unlit before occlusion (the reference writes 0; metrics skip it)
            if (lightReaches(p, n)) {
                vec3 o = p + n * uRayOffset;
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
                uint unblocked = 0u, visited = 0u, cells = 0u, occluded = 0u, maxVisited = 0u, overflow = 0u, cappedRays = 0u;
                sumShafts = 0u;
                leafCells = 0u;
                trianglesTested = 0u;
                nearNodes = 0u;
                vec3 nu = normalize(n);
#if LS_CLASSIFY
                startNode = LS_NONE;
#endif
                for (int s = first; s < end; ++s) {
                    Ray r;
                    if (!sampleRay(o, s, directional, r)) { ++unblocked; continue; } // origin on the sample
                    bool cut;
                    bool blocked = rayBlocked(r, nu, cells, overflow, cut);
                    if (cut) ++cappedRays;
                    visited += rayVisited;
                    maxVisited = max(maxVisited, rayVisited);
                    if (blocked) {
                        ++occluded;
#if LS_CLASSIFY
                        lsClassify[base + 1u + uint(s) / 32u] |= 1u << uint(s & 31);
#endif
                    } else {
                        ++unblocked;
                    }
                }
                uint shafts = sumShafts;
                visitedAll += visited;
#if LS_CLASSIFY
                // The start node depends only on the origin: every sample reports the same one.
                if (startNode != LS_NONE) pixelStartNode = startNode;
#endif
                // Every sample's iteration ends counted as unblocked or occluded. Fewer means the loop
                // was cut short: llvmpipe's code generator (gallivm) stops the loops of an invocation
                // after a fixed budget of iterations, silently, and a sample never traced would count
                // as lit. Such a pixel is written shadowed and reported (overflowCount()), like an
                // overflow, never as light; so is one with a ray whose walk reached its cap.
                if (unblocked + occluded != uint(end - first)) state |= LS_ACC_TRUNCATED;
                if (cappedRays > 0u) state |= LS_ACC_CAPPED;
                state += unblocked;
                bool truncated = (state & LS_ACC_TRUNCATED) != 0u;
                failed = (state & ~LS_ACC_COUNT_MASK) != 0u;
                if (lastDispatch) visibility = failed ? 0.0 : float(state & LS_ACC_COUNT_MASK) / float(count);
                else imageStore(uAccum, px, uvec4(state, visitedAll, 0u, 0u));
#if LS_CLASSIFY
                if (lastDispatch && failed)
                    for (uint w = 1u; w < stride; ++w) lsClassify[base + w] = 0xFFFFFFFFu; // every sample blocked
#endif
                // Per ray: every dispatch adds its own; per pixel: the last one, from the state.
#if SHADOWLAB_STATISTICS
                atomicAdd(sRays, uint(end - first));
                atomicAdd(sVisited, visited);
                atomicMax(sVisitedMax, maxVisited);
                atomicAdd(sShafts, shafts);
                atomicAdd(sCells, cells);
                atomicAdd(sLeaves, leafCells);
                atomicAdd(sTris, trianglesTested);
                atomicAdd(sNearNodes, nearNodes);
                atomicAdd(sOccluded, occluded);
                if (overflow != 0u) atomicAdd(sOverflow, overflow);
                if (lastDispatch) {
                    atomicAdd(sPixels, 1u);
                    if (truncated) atomicAdd(sTruncated, 1u);
                    else if (failed) atomicAdd(sCapped, 1u);
                }
#else
                // The timed pass still counts every overflowed, capped or truncated pixel.
                if (overflow != 0u) atomicAdd(lsCounters[LS_C_OVERFLOW], overflow);
                if (lastDispatch && failed) atomicAdd(lsCounters[truncated ? LS_C_TRUNCATED : LS_C_CAPPED], 1u);
#endif
            }
        }
#if LS_CLASSIFY
        if (firstDispatch || pixelStartNode != LS_NONE) lsClassify[base] = pixelStartNode;
#endif
        if (lastDispatch) {
            imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_STATISTICS
            imageStore(uNodesVisited, px, vec4(float(visitedAll)));
            imageStore(uLoopCapped, px, vec4(failed ? 1.0 : 0.0));
#endif
        }
    }
#if SHADOWLAB_STATISTICS
    barrier();
    if (gl_LocalInvocationIndex == 0u && sRays != 0u) flushWorkgroupCounters();
#endif
}
