#version 450
// line_space: shadow rays answered from the precomputed line space alone (Keul et al. 2017,
// Algorithm 1), one invocation per pixel. No triangle is ever read. Per ray (the reference's rays:
// origin p + n * offset, towards each light sample, ending `offset` short of it):
//   * a node the ray crosses is looked up by the shaft between its entry and exit sub-faces:
//     empty → skipped whole; non-empty on the last subdivided level (d - 1) → the ray is occluded;
//     otherwise its children are visited front to back (3D DDA) and the non-empty ones recursed into;
//   * a node the ray starts in cannot use its line space (the ray crosses no shaft of it): above the
//     last level its children are visited, on the last level it is skipped (paper 4.1: the loss of
//     detail near the receiver).
// Compile-time: LS_N (branching factor), LS_DEPTH (d), LS_CLASSIFY (write per-sample results).
#include "common/light.glsl"
#include "line_space/layout.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

struct LsNode { // 32 bytes, mirrored by ls::NodeGpu (algorithms/line_space/NTree.h)
    vec3 lo; uint children;
    vec3 size; uint level;
};
layout(std430, binding = LS_NODE_BINDING) readonly buffer LsNodes { LsNode lsNodes[]; };
layout(std430, binding = LS_TREE_BINDING) readonly buffer LsTree { uint lsTree[]; };
layout(std430, binding = LS_BITS_BINDING) readonly buffer LsBits0 { uint lsBits0[]; };
layout(std430, binding = LS_BITS_BINDING_1) readonly buffer LsBits1 { uint lsBits1[]; };
layout(std430, binding = LS_BITS_BINDING_2) readonly buffer LsBits2 { uint lsBits2[]; };
layout(std430, binding = LS_BITS_BINDING_3) readonly buffer LsBits3 { uint lsBits3[]; };
layout(std430, binding = LS_SAMPLE_BINDING) readonly buffer LightSamples { vec4 lightSamples[]; };
layout(std430, binding = LS_COUNTER_BINDING) buffer LsCounters { uint lsCounters[]; };
#if LS_CLASSIFY
layout(std430, binding = LS_CLASSIFY_BINDING) buffer LsClassify { uint lsClassify[]; };
#endif

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
layout(r32f, binding = 1) writeonly uniform image2D uNodesVisited; // debug heat map: nodes per pixel
uniform float uRayOffset; // world units, the reference's
uniform int uSampleCount; // entries of lightSamples (1 for point and spot lights)
uniform uint uNodeCount;  // 0: no geometry, nothing occludes
uniform uint uNodesPerChunk; // nodes per line-space pool chunk (see layout.glsl)

const uint N2 = uint(LS_N * LS_N), N4 = N2 * N2;
const uint WORDS = uint(LS_WORDS_PER_NODE(LS_N));
const uint LS_NONE = 0xFFFFFFFFu;
const float kInf = uintBitsToFloat(0x7F800000u);

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
    tIn = tmin[inAxis];
    tOut = tmax[outAxis];
}

// Sub-face (i, j) → j × N + i of the point p on a face of `axis`.
uint subFace(vec3 p, LsNode n, int axis) {
    int u = (axis + 1) % 3, v = (axis + 2) % 3;
    vec3 cell = n.size / float(LS_N);
    int i = clamp(int(floor((p[u] - n.lo[u]) / cell[u])), 0, LS_N - 1);
    int j = clamp(int(floor((p[v] - n.lo[v]) / cell[v])), 0, LS_N - 1);
    return uint(j * LS_N + i);
}

// Word w of node `index`'s line space, from the pool chunk that holds the node.
uint lineSpaceWord(uint index, uint w) {
    uint chunk = index / uNodesPerChunk, i = (index - chunk * uNodesPerChunk) * WORDS + w;
    if (chunk == 0u) return lsBits0[i];
    if (chunk == 1u) return lsBits1[i];
    if (chunk == 2u) return lsBits2[i];
    return lsBits3[i];
}

// The line-space bit of the shaft the ray crosses node `index` through (entering at tIn through
// a face of axis ia, leaving at tOut through one of axis oa).
bool shaftNonEmpty(uint index, LsNode n, Ray r, float tIn, float tOut, int ia, int oa) {
    int fa = 2 * ia + (r.d[ia] >= 0.0 ? 0 : 1); // moving up an axis enters through its min face
    int fb = 2 * oa + (r.d[oa] >= 0.0 ? 1 : 0);
    // Entry and exit on one face: the ray only grazes the node along an edge. Such a shaft has no
    // volume and no bit; answering "non-empty" keeps the method conservative.
    if (fa == fb) return true;
    // The exit is the infinite line's, even when the segment ends inside the node (a light inside
    // the scene box): the shaft holds the segment, so the answer stays conservative.
    uint sa = subFace(r.o + r.d * tIn, n, ia), sb = subFace(r.o + r.d * tOut, n, oa);
    if (fa > fb) { int t = fa; fa = fb; fb = t; uint s = sa; sa = sb; sb = s; }
    uint bit = uint(LS_PAIR_INDEX(fa, fb)) * N4 + sa * N2 + sb;
    return ((lineSpaceWord(index, bit >> 5u) >> (bit & 31u)) & 1u) != 0u;
}

// One subdivided node being walked: its children along the ray (3D DDA over the N³ cells).
struct Frame {
    uint children; // tree pool offset of its children group
    ivec3 cell;    // current child cell
    vec3 lo, cellSize;
    vec3 tNext;    // ray parameter at which it leaves the current cell, per axis
    float t, tEnd; // current cell entered at t; the walk ends at tEnd
    bool start;    // the current cell holds the ray origin
};

#define ENTER_SKIP 0
#define ENTER_OCCLUDED 1
#define ENTER_DESCEND 2

struct Trace {
    bool occluded, overflow;
    uint visited, shafts, cells, startNode;
};

// Enters node `index` of `level`: decides it, or prepares the walk over its children in `f`.
int enter(uint index, int level, bool start, Ray r, inout Trace tr, out Frame f) {
    ++tr.visited;
    LsNode n = lsNodes[index];
    float tIn, tOut;
    int ia, oa;
    slabs(n.lo, n.size, r, tIn, tOut, ia, oa);
    if (!start) {
        ++tr.shafts;
        if (!shaftNonEmpty(index, n, r, tIn, tOut, ia, oa)) return ENTER_SKIP;
        if (level == LS_DEPTH - 1) return ENTER_OCCLUDED; // "deep enough": the shaft stands for its leaves
    } else if (level == LS_DEPTH - 1) {
        tr.startNode = index; // the ray starts among this node's leaves: nothing can be said
        return ENTER_SKIP;
    }
    f.children = n.children;
    f.lo = n.lo;
    f.cellSize = n.size / float(LS_N);
    f.t = max(tIn, 0.0);
    f.tEnd = min(tOut, r.tEnd);
    f.start = start;
    vec3 p = r.o + r.d * f.t;
    f.cell = clamp(ivec3(floor((p - n.lo) / f.cellSize)), ivec3(0), ivec3(LS_N - 1));
    // The cell boundary ahead on each axis, with the float expression the build used for boxes.
    vec3 ahead = n.lo + vec3(f.cell + ivec3(greaterThanEqual(r.d, vec3(0.0)))) * f.cellSize;
    f.tNext = (ahead - r.o) * r.invD;
    return ENTER_DESCEND;
}

Trace trace(Ray r) {
    Trace tr = Trace(false, false, 0u, 0u, 0u, LS_NONE);
    if (uNodeCount == 0u) return tr;
    LsNode root = lsNodes[0];
    float tIn, tOut;
    int ia, oa;
    slabs(root.lo, root.size, r, tIn, tOut, ia, oa);
    if (max(tIn, 0.0) > min(tOut, r.tEnd)) return tr; // the segment misses the scene box
    // `cur` walks the children of the node on level `level`; its ancestors' walks wait in `parents`.
    // Keeping the active frame out of the (dynamically indexed) array saves a copy per cell.
    Frame parents[LS_DEPTH];
    Frame cur;
    int level = 0;
    int e = enter(0u, 0, tIn <= 0.0, r, tr, cur);
    if (e == ENTER_OCCLUDED) { tr.occluded = true; return tr; }
    if (e == ENTER_SKIP) return tr;
    ivec3 stepDir = ivec3(greaterThanEqual(r.d, vec3(0.0))) * 2 - 1;
    while (true) {
        if (cur.t > cur.tEnd) { // walked past the node (or the segment's end)
            if (level == 0) break;
            cur = parents[--level];
            continue;
        }
        ivec3 cell = cur.cell;
        bool start = cur.start;
        ++tr.cells;
        // Advance to the next cell before descending into this one.
        int a = cur.tNext.x <= cur.tNext.y ? (cur.tNext.x <= cur.tNext.z ? 0 : 2) : (cur.tNext.y <= cur.tNext.z ? 1 : 2);
        float cellEnd = cur.tNext[a];
        cur.cell[a] += stepDir[a];
        cur.t = cur.cell[a] < 0 || cur.cell[a] >= LS_N ? kInf : cellEnd;
        cur.tNext[a] = (cur.lo[a] + float(cur.cell[a] + (r.d[a] >= 0.0 ? 1 : 0)) * cur.cellSize[a] - r.o[a]) * r.invD[a];
        cur.start = false;
        uint child = lsTree[cur.children + uint((cell.z * LS_N + cell.y) * LS_N + cell.x)];
        if (child == LS_EMPTY) continue; // Algorithm 1, line 8: empty children are skipped
        Frame f;
        e = enter(child, level + 1, start, r, tr, f);
        if (e == ENTER_OCCLUDED) { tr.occluded = true; break; }
        if (e == ENTER_DESCEND) {
            // One frame per level above the last: LS_DEPTH always suffices. Checked anyway, so a
            // corrupt tree shows as reported overflow, never as light.
            if (level + 1 >= LS_DEPTH) { tr.overflow = true; tr.occluded = true; break; }
            parents[level++] = cur;
            cur = f;
        }
    }
    return tr;
}

bool illuminated(vec3 p) {
    if (uLightType == LIGHT_SPOT) return dot(normalize(p - uLightPosition), uLightDirection) > uLightCosCone;
    if (uLightType == LIGHT_AREA) return dot(p - uLightPosition, uLightDirection) > 0.0;
    return true;
}

shared uint sPixels, sRays, sVisited, sVisitedMax, sShafts, sCells, sOccluded, sOverflow;

void addWide(int lo, uint value) { // 64-bit counter split over words lo, lo + 1
    uint old = atomicAdd(lsCounters[lo], value);
    if (old + value < old) atomicAdd(lsCounters[lo + 1], 1u);
}

void main() {
    if (gl_LocalInvocationIndex == 0u) sPixels = sRays = sVisited = sVisitedMax = sShafts = sCells = sOccluded = sOverflow = 0u;
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(uVisibility);
    if (all(lessThan(px, size))) {
        vec4 pos = texelFetch(uPosition, px, 0);
        float visibility = 1.0; // background: nothing to shadow (the reference's convention)
        uint visited = 0u;
#if LS_CLASSIFY
        uint stride = 1u + (uint(uSampleCount) + 31u) / 32u;
        uint base = uint(px.y * size.x + px.x) * stride;
        uint startNode = LS_NONE;
        for (uint w = 1u; w < stride; ++w) lsClassify[base + w] = 0u;
#endif
        if (pos.w >= 0.5) {
            vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
            visibility = 0.0; // unlit before occlusion (the reference writes 0; metrics skip it)
            if (illuminated(p) && dot(n, toLight(p)) > 0.0) {
                vec3 o = p + n * uRayOffset;
                bool directional = uLightType == LIGHT_DIRECTIONAL;
                int count = directional ? 1 : uSampleCount;
                uint unblocked = 0u, shafts = 0u, cells = 0u, occluded = 0u, maxVisited = 0u, overflow = 0u;
                for (int s = 0; s < count; ++s) {
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
                    Trace t = trace(r);
                    visited += t.visited;
                    shafts += t.shafts;
                    cells += t.cells;
                    maxVisited = max(maxVisited, t.visited);
                    if (t.overflow) ++overflow;
                    if (t.occluded) ++occluded;
                    else ++unblocked;
#if LS_CLASSIFY
                    // The start node depends only on the origin: every sample reports the same one.
                    if (t.startNode != LS_NONE) startNode = t.startNode;
                    if (t.occluded) lsClassify[base + 1u + uint(s) / 32u] |= 1u << uint(s & 31);
#endif
                }
                visibility = float(unblocked) / float(count);
                atomicAdd(sPixels, 1u);
                atomicAdd(sRays, uint(count));
                atomicAdd(sVisited, visited);
                atomicMax(sVisitedMax, maxVisited);
                atomicAdd(sShafts, shafts);
                atomicAdd(sCells, cells);
                atomicAdd(sOccluded, occluded);
                if (overflow != 0u) atomicAdd(sOverflow, overflow);
            }
        }
#if LS_CLASSIFY
        lsClassify[base] = startNode;
#endif
        imageStore(uVisibility, px, vec4(visibility));
        imageStore(uNodesVisited, px, vec4(float(visited)));
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u && sPixels != 0u) {
        atomicAdd(lsCounters[LS_C_PIXELS], sPixels);
        addWide(LS_C_RAYS_LO, sRays);
        addWide(LS_C_VISITED_LO, sVisited);
        atomicMax(lsCounters[LS_C_VISITED_MAX], sVisitedMax);
        addWide(LS_C_SHAFTS_LO, sShafts);
        addWide(LS_C_CELLS_LO, sCells);
        addWide(LS_C_OCCLUDED_LO, sOccluded);
        if (sOverflow != 0u) atomicAdd(lsCounters[LS_C_OVERFLOW], sOverflow);
    }
}
