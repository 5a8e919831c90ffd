// Watertight ray–triangle test (Woop, Benthin & Wald 2013), shared by the shaders that test shadow
// rays against triangles (bvh_raytrace; line_space's exact start region). Like Embree's robust mode
// the reference uses, a ray through a shared edge hits one of the two triangles and never slips
// between them, so both agree with the reference ray for ray.
//
// The ray is set up once (watertightRay); vertices are permuted into its frame with swizzles and
// selects instead of indexing a vector by a variable, which some compilers (llvmpipe's among them)
// turn into memory accesses.
struct WatertightRay {
    vec3 o;
    float tfar;  // hits count on (0, tfar]
    int kz;      // dominant axis of the direction
    bool swapXY; // the direction points down kz: swap the other two axes to keep the winding
    vec3 shear;  // (dx / dz, dy / dz, 1 / dz) in the permuted frame
};

// v in the ray's frame: (v[kx], v[ky], v[kz]) with kx = (kz + 1) % 3, ky = (kx + 1) % 3, then swapped.
vec3 watertightPermute(vec3 v, int kz, bool swapXY) {
    vec3 p = kz == 0 ? v.yzx : (kz == 1 ? v.zxy : v.xyz);
    return swapXY ? p.yxz : p;
}

WatertightRay watertightRay(vec3 o, vec3 d, float tfar) {
    WatertightRay r;
    r.o = o;
    r.tfar = tfar;
    vec3 a = abs(d);
    r.kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    float dz = r.kz == 0 ? d.x : (r.kz == 1 ? d.y : d.z);
    r.swapXY = dz < 0.0;
    vec3 pd = watertightPermute(d, r.kz, r.swapXY);
    r.shear = vec3(pd.x / pd.z, pd.y / pd.z, 1.0 / pd.z);
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
// Swapping the endpoints does not change the uncontracted value: rn(rn(ab) - rn(cd)) is odd.
float watertightEdge(vec2 a, vec2 b) {
    bool swapped = a.x > b.x || (a.x == b.x && a.y > b.y);
    vec2 p = swapped ? b : a, q = swapped ? a : b;
#if SHADOWLAB_FAULT_FMA_EDGES
    // What a contracting compiler may make of it: fma(p.x, q.y, -(p.y * q.x)), the first product
    // exact. Emulated in double (exact product) because a driver's fma() may itself be unfused.
    precise float e = float(double(p.x) * double(q.y) - double(p.y * q.x));
#else
    precise float e = p.x * q.y - p.y * q.x;
#endif
    return swapped ? -e : e;
}

bool watertightHit(WatertightRay r, vec3 v0, vec3 v1, vec3 v2) {
    vec3 A = watertightPermute(v0 - r.o, r.kz, r.swapXY);
    vec3 B = watertightPermute(v1 - r.o, r.kz, r.swapXY);
    vec3 C = watertightPermute(v2 - r.o, r.kz, r.swapXY);
    // precise: a vertex two triangles share must land on the same 2D point in both
    precise float Ax = A.x - r.shear.x * A.z, Ay = A.y - r.shear.y * A.z;
    precise float Bx = B.x - r.shear.x * B.z, By = B.y - r.shear.y * B.z;
    precise float Cx = C.x - r.shear.x * C.z, Cy = C.y - r.shear.y * C.z;
    float U = watertightEdge(vec2(Cx, Cy), vec2(Bx, By));
    float V = watertightEdge(vec2(Ax, Ay), vec2(Cx, Cy));
    float W = watertightEdge(vec2(Bx, By), vec2(Ax, Ay));
    if (U == 0.0 || V == 0.0 || W == 0.0) { // on an edge in float: decide it in double
        // (products of floats are exact in double, so the sign is exact, contracted or not)
        U = float(double(Cx) * double(By) - double(Cy) * double(Bx));
        V = float(double(Ax) * double(Cy) - double(Ay) * double(Cx));
        W = float(double(Bx) * double(Ay) - double(By) * double(Ax));
    }
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
    precise float det = U + V + W; // precise: the reference's rounding, uncontracted
    if (det == 0.0) return false;
    precise float T = U * (r.shear.z * A.z) + V * (r.shear.z * B.z) + W * (r.shear.z * C.z);
    // t = T / det must lie in (0, tfar]
    return det > 0.0 ? (T > 0.0 && T <= r.tfar * det) : (T < 0.0 && T >= r.tfar * det);
}
