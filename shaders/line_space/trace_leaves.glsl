// line_space trace (trace.comp): the walks over a last-level node's leaves: occupancy, split
// leaves' sub-cells, and the exact start region's triangles (all of them, or culled by their planes).
uint leafCells = 0u, trianglesTested = 0u, nearNodes = 0u; // read by leafWalk, the near field (counters)

#if LS_START_MODE == LS_START_EXACT
WatertightRay exactRay = WatertightRay(vec3(0.0), vec3(0.0), 0.0, 2); // the current ray, in the triangle test's frame
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
