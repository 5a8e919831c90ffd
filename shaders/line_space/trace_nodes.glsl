// line_space trace (trace.comp): a node entered and decided by its shaft, or its children's walk
// prepared (Frame, enter()), and the frames of the walks that wait above it.
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
