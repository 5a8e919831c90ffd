// line_space trace (trace.comp): the geometry of one node's cells along a ray: slab entry and exit,
// the child cell of a point, sub-faces, line-space words, the start region's end, DDA steps.
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
