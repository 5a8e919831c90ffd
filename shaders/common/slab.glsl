// The ray–box slab test of the BVH walks (bvh_raytrace; line_space's near field through it), kept
// conservative under GLSL's arithmetic: a box the ray touches where it holds geometry is never
// dropped, so a triangle the watertight test would hit is always reached.
//
// Error bound. GLSL 4.50 section 4.7.1 gives `1.0 / d` 2.5 ULP (the reciprocal is not correctly
// rounded on GPUs: NVIDIA's MUFU.RCP, others a Newton step), i.e. a relative error up to 5u with
// u = 2^-24; `lo - o` and the product each add u. A slab parameter is therefore off by at most
// (1 + u)^2 (1 + 5u) - 1 < 7.01u relative, and a box is dropped wrongly only if the entry came out
// more than 7u too late and the exit 7u too early: widening the exit by 1 + 14u covers it, plus u
// for the widening product itself. The exit is widened by 1 + 2^-19 = 1 + 32u, twice that.
// (Ize 2013's 1 + 2·gamma_3 assumes a correctly rounded reciprocal: too little on a GPU.)

#ifndef SHADOWLAB_FAULT_LOOSE_RECIPROCAL
#define SHADOWLAB_FAULT_LOOSE_RECIPROCAL 0
#endif

const float SLAB_WIDEN = 1.0 + 1.0 / 524288.0; // 1 + 2^-19, exact in float

// 1 / d per component. A zero component would give 0 * inf = NaN in the slab test; 1e-30 keeps the
// slab infinite.
vec3 slabInverse(vec3 d) {
    vec3 safe = mix(d, mix(vec3(-1e-30), vec3(1e-30), greaterThanEqual(d, vec3(0.0))), lessThan(abs(d), vec3(1e-30)));
    vec3 inv = 1.0 / safe;
#if SHADOWLAB_FAULT_LOOSE_RECIPROCAL
    // A reciprocal 2 ULP off (within the 2.5 GLSL allows), the worst way round for one box side:
    // x smaller in magnitude (its slab parameters come out early), y and z larger (late).
    inv = uintBitsToFloat(floatBitsToUint(inv) + uvec3(-2, 2, 2));
#endif
    return inv;
}

// Whether the ray o + t·d (invD = slabInverse(d)) meets the box [lo, hi] for some t in [0, tmax];
// tnear: where it enters (for near-first ordering).
bool slabHit(vec3 lo, vec3 hi, vec3 o, vec3 invD, float tmax, out float tnear) {
    vec3 t0 = (lo - o) * invD, t1 = (hi - o) * invD;
    vec3 tmin = min(t0, t1), tmaxs = max(t0, t1);
    tnear = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
    float tfar = min(min(tmaxs.x, tmaxs.y), min(tmaxs.z, tmax)) * SLAB_WIDEN;
    return tnear <= tfar;
}
