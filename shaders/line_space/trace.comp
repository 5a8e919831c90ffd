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

// Entry and exit of the infinite line through box lo + [0, size]: parameters and the axes of the
// faces crossed (the slab whose entry is last / exit is first).
void slabs(vec3 lo, vec3 size, Ray r, out float tIn, out float tOut, out int inAxis, out int outAxis) {
    vec3 t0 = (lo - r.o) * r.invD, t1 = (lo + size - r.o) * r.invD;
    vec3 tmin = min(t0, t1), tmax = max(t0, t1);
    inAxis = tmin.x >= tmin.y ? (tmin.x >= tmin.z ? 0 : 2) : (tmin.y >= tmin.z ? 1 : 2);
    outAxis = tmax.x <= tmax.y ? (tmax.x <= tmax.z ? 0 : 2) : (tmax.y <= tmax.z ? 1 : 2);
    tIn = max(max(tmin.x, tmin.y), tmin.z);
    tOut = min(min(tmax.x, tmax.y), tmax.z);
}

// Child cell of point p in a node: the cell index per axis, clamped. Per component it is the
// expression the sub-face lookup used (floor((p - lo) / cell)), so one evaluation serves both the
// DDA's first cell and the sub-face of the point on any face.
ivec3 cellOf(vec3 p, vec3 lo, vec3 cellSize) {
    return clamp(ivec3(floor((p - lo) / cellSize)), ivec3(0), ivec3(LS_N - 1));
}

// Sub-face (i, j) → j × N + i on a face of `axis` (i along (axis + 1) % 3, j along (axis + 2) % 3),
// from the point's cell: selects instead of dynamic vector indexing.
uint subFace(ivec3 c, int axis) {
    return uint(axis == 0 ? c.z * LS_N + c.y : (axis == 1 ? c.x * LS_N + c.z : c.y * LS_N + c.x));
}

// Word w of node `index`'s line space, from the pool chunk that holds the node. LS_BIT_CHUNK_COUNT
// is the number of chunks the pool really uses (the host compiles per tree): with one chunk, one load.
uint lineSpaceWord(uint index, uint w) {
#if LS_BIT_CHUNK_COUNT <= 1
    return texelFetch(uLsBitsTexels0, int(index * WORDS + w)).x;
#else
    uint chunk = index / uNodesPerChunk;
    int i = int((index - chunk * uNodesPerChunk) * WORDS + w);
    if (chunk == 0u) return texelFetch(uLsBitsTexels0, i).x;
    if (chunk == 1u) return texelFetch(uLsBitsTexels1, i).x;
    if (chunk == 2u) return texelFetch(uLsBitsTexels2, i).x;
    return texelFetch(uLsBitsTexels3, i).x;
#endif
}

// End of the start region of a ray leaving a receiver of unit normal `nu` in unit direction `d`
// (twin of ls::StartRegion::end): far enough that the ray has risen `uStartCells` leaf widths
// (measured along the normal) above the receiver's tangent plane, so no shaft crossed later holds
// the leaves the receiver's own surface fills; at most `uStartMaxCells` leaf widths along the ray,
// which bounds the blockers it may miss near grazing directions. A ray below the horizon of the
// (interpolated) normal (sin <= 0) may still leave a faceted receiver unblocked, as the reference
// finds: the exact start region then takes its longest length; the distance one, which ignores
// geometry, none (the leaves the ray enters there block it).
float startRegionEnd(vec3 nu, vec3 d) {
    float sinAngle = dot(nu, d), longest = uStartMaxCells * dot(abs(d), uLeafCell);
    if (!(sinAngle > 0.0)) return LS_START_MODE == LS_START_EXACT || LS_START_MODE == LS_START_BVH ? longest : 0.0;
    return min(uStartCells * dot(abs(nu), uLeafCell) / sinAngle, longest);
}

// The axis a DDA steps along when it leaves its cell at cellEnd = min(tNext): one axis only, the
// first of a tie, as a per-axis comparison picks it; by selects (indexing a vector by a variable
// makes some compilers, llvmpipe's among them, keep the DDA's state in memory). None for a NaN
// tNext (every comparison false): the cell stays, and the walk's integer cap ends it.
bvec3 stepAxis(vec3 tNext, float cellEnd) {
    bvec3 axis = equal(tNext, vec3(cellEnd));
    return bvec3(axis.x, axis.y && !axis.x, axis.z && !axis.x && !axis.y);
}

uint leafCells = 0u, trianglesTested = 0u, nearNodes = 0u; // read by leafWalk, the near field (counters)

#if LS_START_MODE == LS_START_EXACT
WatertightRay exactRay = WatertightRay(vec3(0.0), 0.0, 2, false, vec3(0.0)); // the current ray, in the triangle test's frame
#endif

#if LS_LEAF_SPLIT > 1
// Where an occupied leaf would block: does the ray's part [ta, tb] in leaf `leaf` of a last-level node
// (`word`, `bits`: its occupancy word and its index there) cross an occupied sub-cell? A 3D DDA over
// the leaf's S³ sub-cells (S = LS_LEAF_SPLIT), whose bits the build set by the triangle–box test on
// sub-cells widened by the tree's margin, like every other box: conservative under the same
// rounding. At most 3S - 2 sub-cells are crossed; a walk that has not left by then (a NaN step)
// blocks.
bool subCellsBlock(uint word, uint bits, uint leaf, vec3 leafLo, vec3 cellSize, Ray r, float ta, float tb) {
    uvec2 m = texelFetch(uLsLeafSubTexels, int(leafRank(word, bits, leaf))).xy;
    const int S = LS_LEAF_SPLIT;
    vec3 sub = cellSize / float(S);
    ivec3 up = ivec3(greaterThanEqual(r.d, vec3(0.0))), stepDir = up * 2 - 1;
    ivec3 c = clamp(ivec3(floor((r.o + r.d * ta - leafLo) / sub)), ivec3(0), ivec3(S - 1));
    vec3 tNext = (leafLo + vec3(c + up) * sub - r.o) * r.invD;
    for (int k = 0; k < 3 * S; ++k) {
        SIMD_TICK(LS_SIMD_SUB);
        int b = (c.z * S + c.y) * S + c.x;
        if ((((b < 32 ? m.x : m.y) >> uint(b & 31)) & 1u) != 0u) return true;
        float cellEnd = min(min(tNext.x, tNext.y), tNext.z);
        if (cellEnd > tb) return false;
        bvec3 axis = stepAxis(tNext, cellEnd);
        c += ivec3(axis) * stepDir;
        if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(S)))) return false;
        tNext = mix(tNext, (leafLo + vec3(c + up) * sub - r.o) * r.invD, axis);
    }
    return true;
}
#define LEAF_BLOCKS(word, bits, leaf, c, lo, cellSize, r, ta, tb) subCellsBlock(word, bits, leaf, (lo) + vec3(c) * (cellSize), cellSize, r, ta, tb)
#else
#define LEAF_BLOCKS(word, bits, leaf, c, lo, cellSize, r, ta, tb) true
#endif

#if LS_START_MODE != LS_START_NODE || LS_LAST_LEAVES
// Does the segment [t0, t1] of the ray pass through an occupied leaf of last-level node `index`
// (distance), or hit a triangle of one (exact)? A 3D DDA over the node's N³ leaves. The occupancy
// bits are conservative (widened leaf boxes), so a blocker the segment touches is never missed;
// an occupied leaf stands for its geometry like a shaft one leaf wide, finer than the node's shaft.
// Exact: only leaves entered before tS (the start region) are tested against their triangles (the
// whole segment against each, as the reference does); an occupied leaf entered later blocks, as in
// the distance mode. One flat loop, each pass either one triangle test or one DDA step, so that
// neighbouring invocations (vector lanes in lockstep) stay together: nesting the triangle loop in
// the DDA loop measured the same on llvmpipe (within the ±10 % between runs), this form is kept for
// its single exit path.
bool leafWalk(uint index, vec3 lo, vec3 cellSize, Ray r, float t0, float t1, float tS) {
    ivec3 c = cellOf(r.o + r.d * t0, lo, cellSize);
    ivec3 up = ivec3(greaterThanEqual(r.d, vec3(0.0))), stepDir = up * 2 - 1;
    vec3 tNext = (lo + vec3(c + up) * cellSize - r.o) * r.invD;
#if SHADOWLAB_FAULT_NAN_STEP
    if (gFaultPixel) tNext = vec3(uintBitsToFloat(0x7FC00000u));
#endif
    uint base = index * OCC_WORDS;
    float tEnter = t0; // where the walk entered leaf c
    uint next = 0u, end = 0u; // the current leaf's triangles still to test (exact)
    bool step = false;        // leaf c is done: step the DDA
    // Each pass tests one triangle or visits one leaf. Every step moves the cell one leaf along one
    // axis, never back, so at most 3N - 2 leaves are visited before the cell leaves the node (one
    // more pass finds it outside); each occupied leaf adds at most its list's length of triangle
    // tests (exact). uLeafWalkCap = (3N - 1) * (1 + the longest leaf list).
    for (uint pass = 0u; pass < uLeafWalkCap; ++pass) {
#if LS_START_MODE == LS_START_EXACT
        if (next < end) {
            ++trianglesTested;
            SIMD_TICK(LS_SIMD_TRI);
            uint tri = lsLeafTri(next++);
            if (watertightHit(exactRay, sceneVertex(tri, 0u), sceneVertex(tri, 1u), sceneVertex(tri, 2u))) return true;
            continue;
        }
#endif
        if (step) {
            float cellEnd = min(min(tNext.x, tNext.y), tNext.z);
            if (cellEnd > t1) return false;
            tEnter = cellEnd;
            bvec3 axis = stepAxis(tNext, cellEnd);
            c += ivec3(axis) * stepDir;
            if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(LS_N)))) return false;
            tNext = mix(tNext, (lo + vec3(c + up) * cellSize - r.o) * r.invD, axis);
        }
        step = true;
        ++leafCells;
        SIMD_TICK(LS_SIMD_LEAF);
        uint leaf = uint((c.z * LS_N + c.y) * LS_N + c.x);
        uint word = base + (leaf >> 5u), bits = lsOcc(word);
        if (((bits >> (leaf & 31u)) & 1u) != 0u) {
#if LS_START_MODE == LS_START_EXACT
            if (tEnter >= tS) {
                if (LEAF_BLOCKS(word, bits, leaf, c, lo, cellSize, r, tEnter, min(min(min(tNext.x, tNext.y), tNext.z), t1))) return true;
                continue;
            }
            uint rank = leafRank(word, bits, leaf);
            next = lsLeafPrefix(rank);
            end = lsLeafPrefix(rank + 1u);
#else
            if (LEAF_BLOCKS(word, bits, leaf, c, lo, cellSize, r, tEnter, min(min(min(tNext.x, tNext.y), tNext.z), t1))) return true;
#endif
        }
    }
    // The cap (or a driver's own loop limit, llvmpipe's) ended the walk before it did: blocked,
    // and the pixel written shadowed.
    gCapped = true;
    return true;
}
#endif

#if LS_CULL_TRIANGLES
// Does the ray hit one of the triangles tris[first, end) of a leaf it crosses on [ta, tb]? Each
// triangle is first tested by its plane: if the ray's part in the leaf (widened by uLeafMargin) lies
// on one side of it, beyond uPlaneEps, it cannot hit the triangle here, and where else it could
// (another leaf the triangle touches) that leaf decides: tested itself before tS, occupied after.
// The plane tests of up to 32 triangles mark the candidates in a mask; the watertight test runs
// only for those, in a loop of its own, so that a SIMD group pays for it as often as its lane with
// the most candidates needs, not once per triangle (most are the receiver's own surface, which the
// ray leaves upwards). Both loops end by integer counts (32, the mask's set bits).
bool leafTrianglesHit(uint first, uint end, Ray r, float ta, float tb) {
    vec3 a = r.o + r.d * max(ta - uLeafMargin, 0.0), b = r.o + r.d * min(tb + uLeafMargin, r.tEnd);
    for (uint i = first; i < end; i += 32u) {
        uint k = min(end - i, 32u), candidates = 0u;
        for (uint j = 0u; j < k; ++j) {
            SIMD_TICK(LS_SIMD_PLANE);
            vec4 pl = lsTriPlane(lsLeafTri(i + j));
            float sa = dot(pl.xyz, a) + pl.w, sb = dot(pl.xyz, b) + pl.w;
            bool apart = (sa > uPlaneEps && sb > uPlaneEps) || (sa < -uPlaneEps && sb < -uPlaneEps);
            if (!apart) candidates |= 1u << j;
        }
        while (candidates != 0u) {
            int j = findLSB(candidates);
            candidates &= candidates - 1u;
            ++trianglesTested;
            SIMD_TICK(LS_SIMD_TRI);
            uint tri = lsLeafTri(i + uint(j));
            if (watertightHit(exactRay, sceneVertex(tri, 0u), sceneVertex(tri, 1u), sceneVertex(tri, 2u))) return true;
        }
    }
    return false;
}

// leafWalk for the exact start region with start_triangles culled: the same decisions, the work
// split by cost. The DDA steps over empty leaves in a loop of its own (a step and an occupancy
// load each), so lanes reach an occupied leaf together; there an occupied leaf entered at or after
// tS blocks, and one before it has its triangles tested (leafTrianglesHit). The cap counts passes as
// leafWalk's does: one per leaf visit (at most 3N - 1 before the cell leaves the node) and, at an
// occupied leaf, one per triangle of its list, so the walk's whole work stays within uLeafWalkCap =
// (3N - 1) * (1 + the longest list) however its loops nest (llvmpipe's iteration budget is shared by
// a vector's lanes: a walk stalled by a NaN step must not exhaust it for its neighbours).
bool leafWalkCulled(uint index, vec3 lo, vec3 cellSize, Ray r, float t0, float t1, float tS) {
    ivec3 c = cellOf(r.o + r.d * t0, lo, cellSize);
    ivec3 up = ivec3(greaterThanEqual(r.d, vec3(0.0))), stepDir = up * 2 - 1;
    vec3 tNext = (lo + vec3(c + up) * cellSize - r.o) * r.invD;
#if SHADOWLAB_FAULT_NAN_STEP
    if (gFaultPixel) tNext = vec3(uintBitsToFloat(0x7FC00000u));
#endif
    uint base = index * OCC_WORDS;
    float tEnter = t0;
    bool step = false;
    uint pass = 0u;
    while (pass < uLeafWalkCap) {
        uint word = 0u, bits = 0u, leaf = 0u;
        bool occupied = false;
        while (pass < uLeafWalkCap) {
            ++pass;
            if (step) {
                float cellEnd = min(min(tNext.x, tNext.y), tNext.z);
                if (cellEnd > t1) return false;
                tEnter = cellEnd;
                bvec3 axis = stepAxis(tNext, cellEnd);
                c += ivec3(axis) * stepDir;
                if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(LS_N)))) return false;
                tNext = mix(tNext, (lo + vec3(c + up) * cellSize - r.o) * r.invD, axis);
            }
            step = true;
            ++leafCells;
            SIMD_TICK(LS_SIMD_LEAF);
            leaf = uint((c.z * LS_N + c.y) * LS_N + c.x);
            word = base + (leaf >> 5u);
            bits = lsOcc(word);
            if (((bits >> (leaf & 31u)) & 1u) != 0u) { occupied = true; break; }
        }
        if (!occupied) break; // the cap
        float tExit = min(min(min(tNext.x, tNext.y), tNext.z), t1);
        if (tEnter >= tS) {
            if (LEAF_BLOCKS(word, bits, leaf, c, lo, cellSize, r, tEnter, tExit)) return true;
            continue;
        }
        uint rank = leafRank(word, bits, leaf);
        uint first = lsLeafPrefix(rank), end = lsLeafPrefix(rank + 1u);
        if (end - first > uLeafWalkCap - pass) break; // the cap
        pass += end - first;
        if (leafTrianglesHit(first, end, r, tEnter, tExit)) return true;
    }
    gCapped = true;
    return true;
}
#endif

// One subdivided node being walked: its children along the ray (3D DDA over the N³ cells).
struct Frame {
    uint children; // tree pool offset of its children group
    ivec3 cell;    // current child cell
    int child;     // its index in the children group, (z × N + y) × N + x
    vec3 lo, cellSize;
    vec3 tNext;    // ray parameter at which it leaves the current cell, per axis
    float t, tEnd; // current cell entered at t; the walk ends at tEnd
    bool start;    // the current cell holds the ray origin
};

#define ENTER_SKIP 0
#define ENTER_OCCLUDED 1
#define ENTER_DESCEND 2

// Set by enter(): nodes the current ray entered, shafts the pixel's rays read (counters), and the
// start node skipped on the last level (classify).
uint rayVisited = 0u, sumShafts = 0u, startNode = LS_NONE;

// Enters node `index` (on the last subdivided level if `last`): decides it, or prepares the walk
// over its children in `f`. `root`: node 0, whose start flag and segment test are decided here.
// `start`: the node holds the ray origin (the first cell of a start node's walk); a node entered
// before `tS` (the end of the start region, -inf for the paper's) is in the start region too.
int enter(uint index, bool root, bool last, bool start, float tS, Ray r, out Frame f) {
    LsNode n = lsNode(index);
    float tIn, tOut;
    int ia, oa;
    slabs(n.lo, n.size, r, tIn, tOut, ia, oa);
    if (root) {
        if (max(tIn, 0.0) > min(tOut, r.tEnd)) return ENTER_SKIP; // the segment misses the scene box
        start = tIn <= 0.0;
    }
    start = start || tIn < tS;
    ++rayVisited; // a ray that misses the scene box visits nothing
    SIMD_TICK(LS_SIMD_NODE);
    vec3 cellSize = n.size / float(LS_N);
    // Where the walk of a start-region node begins: the start region's end (geometry before it is
    // ignored), or, when the start region is tested exactly, the node's entry.
#if LS_START_MODE == LS_START_EXACT
    float tFrom = max(tIn, 0.0);
#else
    float tFrom = max(max(tIn, tS), 0.0);
#endif
    if (start && last) {
#if LS_START_MODE != LS_START_NODE
        float tTo = min(tOut, r.tEnd);
        if (tFrom > tTo) return ENTER_SKIP; // the whole node lies in the start region
#if LS_CULL_TRIANGLES
        return leafWalkCulled(index, n.lo, cellSize, r, tFrom, tTo, tS) ? ENTER_OCCLUDED : ENTER_SKIP;
#else
        return leafWalk(index, n.lo, cellSize, r, tFrom, tTo, tS) ? ENTER_OCCLUDED : ENTER_SKIP;
#endif
#else
        startNode = index; // the ray starts among this node's leaves: nothing can be said
        return ENTER_SKIP;
#endif
    }
    // The entry point's cell serves the DDA and the entry sub-face. A start node walks from the
    // end of the start region; any other node from where the line enters it (the same point unless
    // rounding puts tIn a hair below 0, where the walk then starts one cell early: a superset).
    ivec3 cIn = cellOf(r.o + r.d * (start ? tFrom : tIn), n.lo, cellSize);
    if (!start) {
        ++sumShafts;
        int fa = 2 * ia + (r.d[ia] >= 0.0 ? 0 : 1); // moving up an axis enters through its min face
        int fb = 2 * oa + (r.d[oa] >= 0.0 ? 1 : 0);
        // Entry and exit on one face: the ray only grazes the node along an edge. Such a shaft has
        // no volume and no bit; answering "non-empty" keeps the method conservative.
        bool nonEmpty = true;
        if (fa != fb) {
            // The exit is the infinite line's, even when the segment ends inside the node (a light
            // inside the scene box): the shaft holds the segment, so the answer stays conservative.
            uint sa = subFace(cIn, ia), sb = subFace(cellOf(r.o + r.d * tOut, n.lo, cellSize), oa);
            bool swap = fa > fb;
            int f0 = min(fa, fb), f1 = max(fa, fb);
            uint bit = uint(LS_PAIR_INDEX(f0, f1)) * N4 + (swap ? sb : sa) * N2 + (swap ? sa : sb);
            nonEmpty = ((lineSpaceWord(index, bit >> 5u) >> (bit & 31u)) & 1u) != 0u;
        }
        if (!nonEmpty) return ENTER_SKIP;
        if (last) { // "deep enough"
#if LS_LAST_LEAVES
            // The shaft is non-empty; the leaves the ray itself crosses decide (occupancy, one leaf
            // wide instead of the shaft's union of all lines between two sub-faces).
#if LS_CULL_TRIANGLES
            return leafWalkCulled(index, n.lo, cellSize, r, max(tIn, 0.0), min(tOut, r.tEnd), -kInf) ? ENTER_OCCLUDED : ENTER_SKIP;
#else
            return leafWalk(index, n.lo, cellSize, r, max(tIn, 0.0), min(tOut, r.tEnd), -kInf) ? ENTER_OCCLUDED : ENTER_SKIP;
#endif
#else
            return ENTER_OCCLUDED; // the shaft stands for its leaves (Algorithm 1)
#endif
        }
    }
    f.children = n.children;
    f.lo = n.lo;
    f.cellSize = cellSize;
    f.t = start ? tFrom : max(tIn, 0.0);
    f.tEnd = min(tOut, r.tEnd);
    f.start = start;
    f.cell = cIn;
    f.child = (cIn.z * LS_N + cIn.y) * LS_N + cIn.x;
    // The cell boundary ahead on each axis, with the float expression the build used for boxes.
    vec3 ahead = n.lo + vec3(cIn + ivec3(greaterThanEqual(r.d, vec3(0.0)))) * cellSize;
    f.tNext = (ahead - r.o) * r.invD;
#if SHADOWLAB_FAULT_NAN_STEP
    if (gFaultPixel) f.tNext = vec3(uintBitsToFloat(0x7FC00000u));
#endif
    return ENTER_DESCEND;
}

// Frames of the ancestors of the walked node. The walked node is at most on level d - 2 (a node
// on level d - 1 is decided on entry), so at most d - 2 ancestors' walks wait, in separate
// variables picked by level rather than an array: some compilers keep a dynamically indexed local
// array in scratch memory (llvmpipe does; with `Frame parents[LS_DEPTH]` the whole walk ran ~9×
// slower, docs/algorithms/line_space.md).
#if LS_DEPTH > 5
#error "at most 3 waiting frames: d <= 5 (ls::kMaxDepth)"
#elif LS_DEPTH <= 3
#define LS_PARENTS 1
#define PUSH(level, f) parent0 = (f)
#define POP(level, f) (f) = parent0
#elif LS_DEPTH == 4
#define LS_PARENTS 2
#define PUSH(level, f) if ((level) == 0) parent0 = (f); else parent1 = (f)
#define POP(level, f) if ((level) == 0) (f) = parent0; else (f) = parent1
#else
#define LS_PARENTS 3
#define PUSH(level, f) if ((level) == 0) parent0 = (f); else if ((level) == 1) parent1 = (f); else parent2 = (f)
#define POP(level, f) if ((level) == 0) (f) = parent0; else if ((level) == 1) (f) = parent1; else (f) = parent2
#endif

#if SHADOWLAB_STATISTICS
shared uint sPixels, sRays, sVisited, sVisitedMax, sShafts, sCells, sOccluded, sOverflow, sLeaves, sTris, sTruncated, sCapped, sNearNodes;

void addWide(int lo, uint value) COUNTER_ADD_WIDE(lsCounters, lo, value)
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
                // `cur` walks the children of the node on level `level`; its ancestors' walks wait
                // in parent0..2.
                Frame cur = Frame(0u, ivec3(0), 0, vec3(0.0), vec3(1.0), vec3(0.0), kInf, 0.0, false);
                Frame parent0 = cur, parent1 = cur, parent2 = cur; // only LS_PARENTS of them are used
                for (int s = first; s < end; ++s) {
                    Ray r;
                    r.o = o;
                    if (directional) {
                        r.d = -uLightDirection;
                        r.tEnd = kInf;
                    } else {
                        vec3 d = lightSamples[s].xyz - o;
                        float dist = length(d);
                        if (!(dist > 0.0)) { ++unblocked; continue; } // origin on the sample
                        r.d = d / dist;
                        r.tEnd = max(0.0, dist - uRayOffset);
                    }
                    // A zero component would give 0 * inf = NaN in the slab test; 1e-30 keeps it infinite.
                    vec3 safe = mix(r.d, mix(vec3(-1e-30), vec3(1e-30), greaterThanEqual(r.d, vec3(0.0))),
                                    lessThan(abs(r.d), vec3(1e-30)));
                    r.invD = 1.0 / safe;
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
                    // The walk ends as the method ends it (the ray free past the root, occluded, or
                    // an overflow) or not at all: then its cap, or the driver, stopped it.
                    bool finished = e != ENTER_DESCEND;
                    if (e == ENTER_DESCEND) {
                        cur = f;
                        int level = 0;
                        // Each pass of the inner loop visits one child cell of the walked node or
                        // leaves a finished walk. A node's DDA moves its cell one step along one axis
                        // per cell, never back, so it visits at most 3N - 2 cells before the cell
                        // leaves the node (t = inf): with the pass that leaves it, 3N - 1 passes per
                        // walked node. A ray walks each node above the last level at most once, and
                        // at most (3N - 2)^l of level l (one per cell its parent crosses): uWalkCap =
                        // (3N - 1) * min(nodes above the last level, the sum of (3N - 2)^l).
                        uint passes = 0u;
                        while (!finished && passes < uWalkCap) {
                            // Step the DDA to the next non-empty child, leaving finished walks: a
                            // loop of its own, so that neighbouring invocations (vector lanes in
                            // lockstep) reach the node test below together.
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
                                // Advance to the next cell before descending into this one. The axis
                                // and every update are selects: indexing a vector by a variable makes
                                // some compilers (llvmpipe's among them) keep the frame in memory.
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
                                // One frame per level above the last suffices by construction. Checked
                                // anyway, so a corrupt tree shows as reported overflow, never as light.
                                if (level >= LS_PARENTS) { ++overflow; blocked = true; finished = true; break; }
                                PUSH(level, cur);
                                ++level;
                                cur = f;
                            }
                        }
                    }
#if LS_START_MODE == LS_START_BVH
                    // The near field, for the rays the line space left free (most blocked rays are
                    // blocked farther out, so this order runs the BVH for fewer of them). An
                    // overflowed or capped near field could have missed its blocker: blocked, and the
                    // pixel written shadowed (overflow, cap), as in bvh_raytrace.
                    if (!blocked && finished && !gCapped) {
                        BvhTrace near = bvhTrace(bvhMakeRay(r.o, r.d, min(tS, r.tEnd)));
                        nearNodes += near.visited;
                        trianglesTested += near.tested;
                        if (near.overflow) ++overflow;
                        if (near.capped) gCapped = true;
                        blocked = near.occluded || near.overflow;
                    }
#endif
                    // A walk cut short (here or in a leaf walk) could have met a blocker further on.
                    if (!finished || gCapped) {
                        blocked = true;
                        ++cappedRays;
                    }
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
    if (gl_LocalInvocationIndex == 0u && sRays != 0u) {
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
}
