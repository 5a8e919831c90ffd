// The view-sample cluster hierarchy of Sintorn et al. 2014: buffers, cluster keys, node bounds and
// the shadow-volume predicates shared by every ptsv stage.
// Needs common/scene.glsl and common/light.glsl included before it.
#include "ptsv/layout.glsl"
#include "common/statistics.glsl"

layout(std430, binding = PTSV_MASK_BINDING) coherent buffer PtsvMasks { uint ptsvMasks[]; };
layout(std430, binding = PTSV_AABB_BINDING) buffer PtsvBounds { float ptsvBounds[]; };
// A sample slot: q's bits in xyz and the cluster key in w, so a leaf test reads one texel per slot.
layout(std430, binding = PTSV_SAMPLE_BINDING) buffer PtsvSamples { uvec4 ptsvSamples[]; };
layout(std430, binding = PTSV_SHADOW_BINDING) buffer PtsvShadow { uint ptsvShadow[]; };
layout(std430, binding = PTSV_PLANE_BINDING) buffer PtsvPlanes { vec4 ptsvPlanes[]; };
layout(std430, binding = PTSV_JOB_BINDING) buffer PtsvJobs { uvec2 ptsvJobs[]; };
layout(std430, binding = PTSV_COUNTER_BINDING) coherent buffer PtsvCounters { uint ptsvCounters[]; };
layout(std430, binding = PTSV_HEAT_BINDING) buffer PtsvHeat { uint ptsvHeat[]; };
layout(std430, binding = PTSV_JOB_ITER_BINDING) buffer PtsvJobIterations { uint ptsvJobIterations[]; };

// Hierarchy shape (algorithms/ptsv/PtsvLayout.h computes it on the host).
uniform ivec2 uResolution;
uniform int uTile;
uniform int uTilesX;
uniform int uSlices;
uniform float uSliceLog;
uniform int uKeyBits;
uniform int uLevels;
uniform uint uKeyBit[32];
uniform uint uMaskOffset[PTSV_MAX_LEVELS + 1];
uniform uint uNodeOffset[PTSV_MAX_LEVELS + 2];
// Camera: view matrix, near plane, tan of the half field of view in x and y.
uniform mat4 uView;
uniform float uNear;
uniform vec2 uTanHalf;

// ---- Cluster keys ------------------------------------------------------------------------------
// The loops run to the constant PTSV_MAX_KEY_BITS so the compiler can unroll them: llvmpipe counts
// every iteration of a non-unrolled loop against its per-invocation cap (see traverse.comp).
uint ptsvKey(uvec3 c) {
    uint k = 0u;
    for (int i = 0; i < PTSV_MAX_KEY_BITS; ++i) {
        uint e = uKeyBit[i];
        if (i < uKeyBits) k |= ((c[e & 3u] >> (e >> 2)) & 1u) << uint(i);
    }
    return k;
}

// Cluster-coordinate range [lo, hi) of node `id` at `depth` (its key prefix; the low bits are free).
void ptsvNodeRange(uint id, int depth, out uvec3 lo, out uvec3 hi) {
    lo = uvec3(0u);
    uvec3 freeBits = uvec3(0u);
    int low = 5 * (uLevels - depth);
    for (int i = 0; i < PTSV_MAX_KEY_BITS; ++i) {
        uint e = uKeyBit[i];
        if (i >= uKeyBits) continue;
        if (i < low) freeBits[e & 3u] += 1u; // Morton: a coordinate's free bits are its lowest
        else lo[e & 3u] |= ((id >> uint(i - low)) & 1u) << (e >> 2);
    }
    hi = lo + (uvec3(1u) << freeBits);
}

int ptsvSlice(float viewDepth) {
    float z = floor(log(viewDepth / uNear) / uSliceLog);
    return int(clamp(z, 0.0, float(uSlices - 1)));
}

uint ptsvTileSamples() { return uint(uTile * uTile); }

// ---- Shadow volume predicates --------------------------------------------------------------------
// `precise`: a shared edge's plane P and its exact negation -P are evaluated at the same code site,
// so s(-P) is exactly -s(P): a point on a closed mesh's edge is inside one of the two volumes.
float ptsvSigned(vec4 plane, vec3 x) {
    precise float s = dot(plane.xyz, x) + plane.w;
    return s;
}

// A plane read back as a GPU that flushes denormal inputs would (GLSL 4.50 section 4.7.1 allows it):
// SHADOWLAB_FAULT_FLUSH_DENORMALS (tests only, framework/gl/Shader.h) forces that on every read.
vec4 ptsvFlushDenormals(vec4 p) {
#if SHADOWLAB_FAULT_FLUSH_DENORMALS
    bvec4 denormal = equal(floatBitsToUint(p) & 0x7F800000u, uvec4(0u));
    return vec4(denormal.x ? 0.0 : p.x, denormal.y ? 0.0 : p.y, denormal.z ? 0.0 : p.z, denormal.w ? 0.0 : p.w);
#else
    return p;
#endif
}

#if PTSV_TEXEL_READS
// The traversal reads what earlier passes wrote through buffer textures (Ptsv binds the views to
// the PTSV_*_UNIT units): a SIMD CPU back end (llvmpipe) gathers texel fetches for all its lanes at
// once but loads storage buffers lane by lane; a GPU reads both through its caches.
layout(binding = PTSV_BOUNDS_UNIT) uniform samplerBuffer uPtsvBoundsTexels;
layout(binding = PTSV_SAMPLE_UNIT) uniform usamplerBuffer uPtsvSampleTexels;
layout(binding = PTSV_PLANE_UNIT) uniform samplerBuffer uPtsvPlaneTexels;
layout(binding = PTSV_MASK_UNIT) uniform usamplerBuffer uPtsvMaskTexels;
layout(binding = PTSV_SHADOW_UNIT) uniform usamplerBuffer uPtsvShadowTexels; // resolve.comp only
uint ptsvShadowAt(uint slot) { return texelFetch(uPtsvShadowTexels, int(slot)).x; }
// A child mask as the hierarchy built it, or with bits that trivial accepts have cleared since
// (atomicAnd on the storage buffer): a fetch may miss those clears, which only sends the
// traversal into a subtree whose samples are already shadowed.
uint ptsvMaskAt(uint word) { return texelFetch(uPtsvMaskTexels, int(word)).x; }
vec4 ptsvPlane(uint triangle, uint i) {
    return ptsvFlushDenormals(texelFetch(uPtsvPlaneTexels, int(PTSV_PLANES_PER_TRIANGLE * triangle + i)));
}
uvec4 ptsvSlotAt(uint slot) { return texelFetch(uPtsvSampleTexels, int(slot)); }
void ptsvBoxAt(uint node, out vec3 bmin, out vec3 bmax) {
    bmin = texelFetch(uPtsvBoundsTexels, int(2u * node)).xyz;
    bmax = texelFetch(uPtsvBoundsTexels, int(2u * node + 1u)).xyz;
}
#else
vec4 ptsvPlane(uint triangle, uint i) { return ptsvFlushDenormals(ptsvPlanes[PTSV_PLANES_PER_TRIANGLE * triangle + i]); }
uint ptsvMaskAt(uint word) { return ptsvMasks[word]; }
uint ptsvShadowAt(uint slot) { return ptsvShadow[slot]; }
uvec4 ptsvSlotAt(uint slot) { return ptsvSamples[slot]; }
void ptsvBoxAt(uint node, out vec3 bmin, out vec3 bmax) {
    uint b = 6u * node;
    bmin = vec3(ptsvBounds[b], ptsvBounds[b + 1u], ptsvBounds[b + 2u]);
    bmax = vec3(ptsvBounds[b + 3u], ptsvBounds[b + 4u], ptsvBounds[b + 5u]);
}
#endif
vec3 ptsvSampleAt(uint slot) { return uintBitsToFloat(ptsvSlotAt(slot).xyz); }
uint ptsvKeyAt(uint slot) { return ptsvSlotAt(slot).w; }

// Written as float(status) by setup.comp: an exact small integer, never a denormal.
uint ptsvStatus(uint triangle) { return uint(ptsvPlane(triangle, 7u).x); }

// Smallest and largest value of a plane over a world-space box (the n- and p-vertices).
vec2 ptsvBoxRange(vec4 plane, vec3 bmin, vec3 bmax) {
    vec3 nv = mix(bmax, bmin, greaterThanEqual(plane.xyz, vec3(0.0)));
    vec3 pv = mix(bmin, bmax, greaterThanEqual(plane.xyz, vec3(0.0)));
    return vec2(dot(plane.xyz, nv), dot(plane.xyz, pv)) + plane.w;
}

// Smallest and largest value of a view-space plane over an implicit node: the frustum segment
// {(X d, Y d, -d)} for X, Y in a tile range and d in a depth range. For a fixed d the value is
// linear in (X, Y), so its extremes over the segment lie at its corners.
vec2 ptsvFrustumRange(vec4 plane, vec2 xr, vec2 yr, vec2 dr) {
    float gmin = min(plane.x * xr.x, plane.x * xr.y) + min(plane.y * yr.x, plane.y * yr.y) - plane.z;
    float gmax = max(plane.x * xr.x, plane.x * xr.y) + max(plane.y * yr.x, plane.y * yr.y) - plane.z;
    return vec2(min(dr.x * gmin, dr.y * gmin), max(dr.x * gmax, dr.y * gmax)) + plane.w;
}

// View-space extent of the implicit node: tan-scaled x and y ranges and the depth range, padded so
// that rounding of the key computation can never leave a sample outside its node.
void ptsvImplicitExtent(uint id, int depth, out vec2 xr, out vec2 yr, out vec2 dr) {
    uvec3 lo, hi;
    ptsvNodeRange(id, depth, lo, hi);
    vec2 px = vec2(min(ivec2(lo.x, hi.x) * uTile, ivec2(uResolution.x)));
    vec2 py = vec2(min(ivec2(lo.y, hi.y) * uTile, ivec2(uResolution.y)));
    xr = (2.0 * px / float(uResolution.x) - 1.0) * uTanHalf.x;
    yr = (2.0 * py / float(uResolution.y) - 1.0) * uTanHalf.y;
    float d0 = uNear * exp(float(lo.z) * uSliceLog), d1 = uNear * exp(float(min(hi.z, uint(uSlices))) * uSliceLog);
    dr = vec2(d0 * (1.0 - 1e-4), d1 * (1.0 + 1e-4));
}
