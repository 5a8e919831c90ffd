// Watertight ray–triangle test (Woop, Benthin & Wald 2013), shared by the shaders that test shadow
// rays against triangles (bvh_raytrace; the close calls of psv, ptsv, shadow_volumes; metric_tree,
// izb; line_space's exact start region). A ray through an edge two triangles share hits one of the
// two and never slips between them.
//
// The reference runs this very test (framework/reference/Watertight.cpp, its C++ twin), so the two
// decide every ray–triangle pair alike, ties included, on any GPU GLSL 4.50 allows: no division and
// no square root (GLSL allows 2.5 ULP for a division, more for a square root): the ray is sheared by
// multiplying through by its direction's dominant component, scaled by a power of two; `precise`
// everywhere (no fused multiply-add); every subnormal flushed to zero on both sides (a GPU may flush
// them on its own). The values are the same as Woop's times positive factors, so the signs decide
// the same way.
//
// The ray is set up once (watertightRay); vertices are permuted into its frame with swizzles and
// selects instead of indexing a vector by a variable, which some compilers (llvmpipe's among them)
// turn into memory accesses.
struct WatertightRay {
    vec3 o;
    vec3 d;     // permuted (dominant axis last) and scaled by a power of two: |d.z| in [0.5, 1)
    float tfar; // hits count on (0, tfar] along the direction as given; scaled like d
    int kz;     // dominant axis of the direction
};

#include "common/exact_float.glsl"

// v in the ray's frame: (v[kx], v[ky], v[kz]) with kx = (kz + 1) % 3, ky = (kx + 1) % 3.
vec3 watertightPermute(vec3 v, int kz) { return kz == 0 ? v.yzx : (kz == 1 ? v.zxy : v.xyz); }

// The reference's ray origin p + n * offset, rounded as framework/reference/Watertight.cpp rounds it.
vec3 watertightOrigin(vec3 p, vec3 n, float offset) {
    return vec3(exactAdd(p.x, exactMul(n.x, offset)), exactAdd(p.y, exactMul(n.y, offset)), exactAdd(p.z, exactMul(n.z, offset)));
}

WatertightRay watertightRay(vec3 o, vec3 d, float tfar) {
    WatertightRay r;
    r.o = exactFlush(o);
    vec3 a = abs(d);
    r.kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    vec3 pd = watertightPermute(exactFlush(d), r.kz);
    int e;
    frexp(pd.z, e); // pd.z = m * 2^e, |m| in [0.5, 1) (e = 0 for a zero direction)
    r.d = vec3(exactFlush(ldexp(pd.x, -e)), exactFlush(ldexp(pd.y, -e)), ldexp(pd.z, -e));
    r.tfar = tfar <= 3.40282347e38 ? ldexp(tfar, e) : tfar; // +inf (a directional light) kept: ldexp's is undefined
    return r;
}

#ifndef SHADOWLAB_FAULT_FMA_EDGES
#define SHADOWLAB_FAULT_FMA_EDGES 0
#endif

// a.x * b.y - a.y * b.x, the 2D edge function of the edge (a, b), evaluated with the endpoints in
// one canonical order: the triangle across a shared edge evaluates (b, a) and gets the exact
// negation, which the watertight argument needs. `precise` alone would give that (no contraction,
// GLSL 4.50 section 4.8.1), and keeps the value equal to the reference's (uncontracted) one; the
// canonical order keeps the two triangles consistent even where a compiler contracts anyway.
float watertightEdge(vec2 a, vec2 b) {
    bool swapped = a.x > b.x || (a.x == b.x && a.y > b.y);
    vec2 p = swapped ? b : a, q = swapped ? a : b;
#if SHADOWLAB_FAULT_FMA_EDGES
    // What a contracting compiler may make of it: fma(p.x, q.y, -(p.y * q.x)), the first product
    // exact. Emulated in double (exact product) because a driver's fma() may itself be unfused.
    float e = exactFlush(float(double(p.x) * double(q.y) - double(exactMul(p.y, q.x))));
#else
    float e = exactSub(exactMul(p.x, q.y), exactMul(p.y, q.x));
#endif
    return swapped ? -e : e;
}

// The edge value decided in double: products of floats are exact in double, so its sign is exact.
float watertightEdgeInDouble(vec2 a, vec2 b) {
    return exactFlush(float(double(a.x) * double(b.y) - double(a.y) * double(b.x)));
}

// A vertex relative to the origin, permuted, projected along the ray onto z = 0 and scaled by d.z.
vec3 watertightProject(WatertightRay r, vec3 v) {
    vec3 a = watertightPermute(exactSub(v, r.o), r.kz);
    return vec3(exactSub(exactMul(a.x, r.d.z), exactMul(r.d.x, a.z)), exactSub(exactMul(a.y, r.d.z), exactMul(r.d.y, a.z)), a.z);
}

bool watertightHit(WatertightRay r, vec3 v0, vec3 v1, vec3 v2) {
    vec3 A = watertightProject(r, v0), B = watertightProject(r, v1), C = watertightProject(r, v2);
    float U = watertightEdge(C.xy, B.xy);
    float V = watertightEdge(A.xy, C.xy);
    float W = watertightEdge(B.xy, A.xy);
    if (U == 0.0 || V == 0.0 || W == 0.0) { // on an edge in float: decide it in double
        U = watertightEdgeInDouble(C.xy, B.xy);
        V = watertightEdgeInDouble(A.xy, C.xy);
        W = watertightEdgeInDouble(B.xy, A.xy);
    }
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
    float det = exactAdd(exactAdd(U, V), W);
    float D = exactMul(det, r.d.z); // t = T / D
    if (D == 0.0) return false;
    float T = exactAdd(exactAdd(exactMul(U, A.z), exactMul(V, B.z)), exactMul(W, C.z));
    float end = exactMul(r.tfar, D);
    // t must lie in (0, tfar]
    return D > 0.0 ? (T > 0.0 && T <= end) : (T < 0.0 && T >= end);
}
