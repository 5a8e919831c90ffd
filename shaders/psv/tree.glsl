// The TOP tree of Partitioned Shadow Volumes (Gerhards et al. 2015): node layout, the per-triangle
// shadow frustum, and the geometric predicates shared by the build and the query.
// Needs common/scene.glsl and common/light.glsl included before it.
#include "psv/layout.glsl"
#include "common/statistics.glsl"
#include "common/shadow_volume.glsl"

// 32 bytes (std430), mirrored by PsvNodeGpu in algorithms/psv/PsvGpuLayout.h.
struct PsvNode {
    vec4 plane;       // unit normal.xyz, offset w: dot(plane.xyz, x) + plane.w; frustum inside < 0
    uint pos;         // positive child (0 = empty leaf)
    uint inter;       // intersection child
    uint wedgeOrNeg;  // shadow plane: float bits of the wedge (see psvWedge); capping: negative child
    uint minDepth;    // capping: float bits of the smallest light depth in its subtree (depth skip)
};

// The build reads child fields that other invocations are changing (coherent: no stale cached
// copies; a stale value would only cost a failed compare-and-swap). The query only reads.
#ifndef PSV_NODE_ACCESS
#define PSV_NODE_ACCESS coherent
#endif
layout(std430, binding = PSV_NODE_BINDING) PSV_NODE_ACCESS buffer PsvNodes { PsvNode psvNodes[]; };
layout(std430, binding = PSV_COUNTER_BINDING) coherent buffer PsvCounters { uint psvCounters[]; };

// The same nodes through a buffer texture (two RGBA32UI texels each): whole nodes in the query;
// in the build the planes, which nothing changes there, and the child fields and wedges, which
// other insertions change but where an older value is harmless (build.comp says why). A SIMD CPU
// back end (llvmpipe) gathers a texel fetch for its lanes at once but loads storage per lane, which
// made the query a third slower; a GPU reads both through its caches.
layout(binding = PSV_NODE_UNIT) uniform usamplerBuffer uPsvNodeTexels;
vec4 psvPlane(uint i) { return uintBitsToFloat(texelFetch(uPsvNodeTexels, int(2u * i))); }
PsvNode psvNode(uint i) {
    uvec4 t1 = texelFetch(uPsvNodeTexels, int(2u * i + 1u));
    return PsvNode(psvPlane(i), t1.x, t1.y, t1.z, t1.w);
}

uniform uint uTriangleCount;

// World units: vertices this close to a plane count as touching it (psvTolerance); a plane value
// half as close to 0 is too close for the query to call (psvCloseCall). Both are per-invocation
// values that psvReadMargins() sets at the start of each main from the sentinel node's plane (node
// 0, whose plane nothing else reads; Psv.cpp writes the tolerance there each frame), not uniforms:
// on llvmpipe, comparing with a uniform margin slowed the query's node loop, the same margin as a
// per-invocation value did not (measured: results/reference/psv_plane_walk_llvmpipe.md).
float psvTolerance = 0.0, psvCloseCall = 0.0; // set by psvReadMargins() first thing in main
void psvReadMargins() {
    psvTolerance = psvPlane(0u).w;
    psvCloseCall = 0.5 * psvTolerance;
}
uniform vec3 uDepthOrigin;  // directional light: depth is measured along the light from here

// ---- Insertion order: a keyed bijection on [0, n) ------------------------------------------------
// A 4-round Feistel network on 2h bits (the smallest even width covering n) with cycle walking, so
// the "random permutation" of the paper costs no buffer (memory stays 128 (n + 1) bytes).
// Mirrored on the CPU by psvPermute() in algorithms/psv/PsvPermutation.h.
uniform uvec4 uPermKeys;
uniform uint uPermHalfBits;

uint psvHash(uint x) { // "lowbias32" integer hash (C. Wellons)
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

uint psvFeistel(uint x) {
    uint mask = (1u << uPermHalfBits) - 1u;
    uint l = x >> uPermHalfBits, r = x & mask;
    for (int round = 0; round < 4; ++round) {
        uint f = psvHash(r ^ uPermKeys[round]) & mask;
        uint nl = r;
        r = l ^ f;
        l = nl;
    }
    return (l << uPermHalfBits) | r;
}

uint psvPermute(uint k) {
#if PSV_RANDOM_ORDER
    uint x = psvFeistel(k);
    while (x >= uTriangleCount) x = psvFeistel(x); // ends: k < n lies on x's cycle
    return x;
#else
    return k;
#endif
}

// ---- Shadow frustum of one triangle ------------------------------------------------------------
struct PsvFrustum {
    vec4 planes[4]; // three shadow planes, then the capping plane; inside negative
    int status;     // PSV_CASTER_* below
};
#define PSV_CASTER_OK 0
#define PSV_CASTER_EDGE_ON 1
#define PSV_CASTER_FACING 2
#define PSV_CASTER_OUTSIDE_CONE 3 // spot light: wholly outside its cone
#define PSV_REJECT_ALL vec4(0.0, 0.0, 0.0, 1.0) // a plane with everything outside it (+1)

// Triangle t's status as frusta.comp decided it: the minDepth field of its first node.
uint psvStoredStatus(uint t) { return texelFetch(uPsvNodeTexels, int(2u * (PSV_NODES_PER_TRIANGLE * t + 1u) + 1u)).w; }

// Triangle t's escape node (Mora et al. 2016), for the stackless walks: the deepest node on the
// path from the root to t's frustum where that path went down an intersection child (0: none).
// build.comp writes it once t is linked, in the minDepth field of t's second node (unused by a
// shadow plane), so it costs no memory.
#define PSV_ESCAPE_NODE 1u // t's escape lives in node 4t + 1 + PSV_ESCAPE_NODE
uint psvEscape(uint t) {
#if SHADOWLAB_FAULT_ESCAPE_LOOP
    // Test fault (framework/gl/Shader.h): every escape leads back into its own triangle's first
    // node, as a corrupt escape would: a walk that never ends unless its cap stops it.
    return PSV_NODES_PER_TRIANGLE * t + 1u;
#endif
    return texelFetch(uPsvNodeTexels, int(2u * (PSV_NODES_PER_TRIANGLE * t + 1u + PSV_ESCAPE_NODE) + 1u)).w;
}

// Spot light: whether a triangle lies wholly outside the cone, by its bounding sphere (centroid,
// farthest vertex) with margins that only keep more triangles. Such a triangle shadows nothing the
// spot lights: the shadow ray of a lit point runs from the apex along a ray inside the cone.
// Outside means: the angle θ to the axis exceeds the cone's half angle γ plus the sphere's angular
// radius α, tested as cos θ < cos(γ + α) with sqrt and products only (GLSL leaves acos and asin
// far less precise). γ ≤ 89° (the config's limit) and α < 90° keep γ + α below π, where cos falls.
bool psvOutsideCone(vec3 v0, vec3 v1, vec3 v2) {
    vec3 c = (v0 + v1 + v2) / 3.0;
    float r = max(length(v0 - c), max(length(v1 - c), length(v2 - c))) * (1.0 + 1e-5) + psvTolerance;
    vec3 d = c - uLightPosition;
    float dist = length(d);
    if (!(dist > r)) return false; // the sphere holds the apex
    float cosTheta = dot(d, uLightDirection) / dist;
    float sinAlpha = r / dist, cosAlpha = sqrt(max(0.0, 1.0 - sinAlpha * sinAlpha));
    float cosGamma = clamp(uLightCosCone, 0.0, 1.0), sinGamma = sqrt(max(0.0, 1.0 - cosGamma * cosGamma));
    return cosTheta < cosGamma * cosAlpha - sinGamma * sinAlpha - 1e-4;
}

PsvFrustum psvDecideFrustum(vec3 v0, vec3 v1, vec3 v2) {
    PsvFrustum f;
    f.status = PSV_CASTER_OK;
    if (uLightType == LIGHT_SPOT && psvOutsideCone(v0, v1, v2)) { f.status = PSV_CASTER_OUTSIDE_CONE; return f; }
    vec3 n = cross(v1 - v0, v2 - v0);
    float len = length(n);
    n = len > 0.0 ? n / len : vec3(0.0);
    // Signed distance of the light to the triangle's plane (directional: cosine to the light).
    vec3 toLight = lightIsDirectional() ? -uLightDirection : uLightPosition - v0;
    float side = dot(n, toLight);
    // Light (almost) in the triangle's plane: the frustum is (nearly) empty, a sliver under 1e-6
    // rad wide, and the planes' orientation would rest on rounding.
    if (!(abs(side) > 1e-6 * length(toLight))) { f.status = PSV_CASTER_EDGE_ON; return f; }
#if PSV_FRONT_FACE_CULLING
    if (side > 0.0) { f.status = PSV_CASTER_FACING; return f; }
#endif
    float flip = side < 0.0 ? 1.0 : -1.0;
    f.planes[0] = svEdgePlane(v0, v1, flip);
    f.planes[1] = svEdgePlane(v1, v2, flip);
    f.planes[2] = svEdgePlane(v2, v0, flip);
    if (f.planes[0].xyz == vec3(0.0) || f.planes[1].xyz == vec3(0.0) || f.planes[2].xyz == vec3(0.0)) {
        f.status = PSV_CASTER_EDGE_ON;
        return f;
    }
    vec3 nc = side > 0.0 ? n : -n; // the light side of the capping plane is positive
    f.planes[3] = vec4(nc, -dot(nc, v0));
    return f;
}

PsvFrustum psvFrustum(vec3 v0, vec3 v1, vec3 v2) {
    PsvFrustum f = psvDecideFrustum(v0, v1, v2);
#if SHADOWLAB_FAULT_STATUS_DISAGREES && !PSV_STATUS_WRITER
    // Test fault (framework/gl/Shader.h): any shader but frusta.comp that decides a status calls a
    // triangle frusta.comp culled a caster, as different rounding may on a GPU.
    f.status = PSV_CASTER_OK;
#endif
    return f;
}

// ---- Predicates ----------------------------------------------------------------------------------
// `precise`: the query evaluates a shared edge's plane P and its exact negation -P at the same
// code site, so s(-P) is exactly -s(P), which keeps closed meshes watertight.
float psvSigned(vec4 plane, vec3 x) {
    precise float s = dot(plane.xyz, x) + plane.w;
    return s;
}

// Where a triangle lies with respect to a plane: 1 strictly positive, -1 strictly negative, 0 it
// touches or crosses it. The tolerance only ever moves triangles to the intersection child, which
// the query may always visit, so it costs a little speed and never correctness.
int psvClassify(vec4 plane, vec3 v0, vec3 v1, vec3 v2) {
    vec3 s = vec3(psvSigned(plane, v0), psvSigned(plane, v1), psvSigned(plane, v2));
    if (all(greaterThan(s, vec3(psvTolerance)))) return 1;
    if (all(lessThan(s, vec3(-psvTolerance)))) return -1;
    return 0;
}

// Depth from the light: distance for a point light, distance along the light for a directional
// one (measured from uDepthOrigin, behind the scene, so it is positive and its float bits order).
float psvDepth(vec3 x) {
    return lightIsDirectional() ? dot(x - uDepthOrigin, uLightDirection) : length(x - uLightPosition);
}

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
vec3 psvClosestPoint(vec3 p, vec3 a, vec3 b, vec3 c) {
    vec3 ab = b - a, ac = c - a, ap = p - a;
    float d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    vec3 bp = p - b;
    float d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return b;
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + d1 / (d1 - d3) * ab;
    vec3 cp = p - c;
    float d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return c;
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + d2 / (d2 - d6) * ac;
    float va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
    float denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// Smallest depth of any point of the triangle, lowered by a relative margin so that rounding can
// only make the depth skip more conservative.
float psvTriangleMinDepth(vec3 v0, vec3 v1, vec3 v2) {
    float d = lightIsDirectional() ? min(psvDepth(v0), min(psvDepth(v1), psvDepth(v2)))
                               : length(psvClosestPoint(uLightPosition, v0, v1, v2) - uLightPosition);
    return max(0.0, d * (1.0 - 1e-5) - psvTolerance);
}

// ---- Wedge (section 3.5) -------------------------------------------------------------------------
// Point light: the wedge is the largest |sin| of the angle between the shadow plane and any ray
// from the light through the triangle; the query compares |signed distance| / distance with it.
// The paper takes the vertices' angles, but the largest angle of a triangle seen from the light
// can lie inside an edge (or inside the triangle, when it covers the plane's normal direction):
// the maximum over the spherical triangle is computed exactly below, so the test is conservative.

// Largest |n·u| over the great-circle arc a→b (unit vectors, arc shorter than π), endpoints excluded.
float psvArcMax(vec3 n, vec3 a, vec3 b) {
    vec3 g = cross(a, b);
    float gl = length(g);
    if (!(gl > 1e-12)) return 0.0; // a point-like arc: its endpoints cover it
    g /= gl;
    vec3 p = n - dot(n, g) * g;    // direction of the circle closest to n
    float pl = length(p);
    if (!(pl > 1e-12)) return 0.0; // n is normal to the circle: n·u = 0 on all of it
    p /= pl;
    bool onArc = dot(cross(a, p), g) >= 0.0 && dot(cross(p, b), g) >= 0.0;
    bool oppositeOnArc = dot(cross(a, -p), g) >= 0.0 && dot(cross(-p, b), g) >= 0.0;
    return onArc || oppositeOnArc ? pl : 0.0;
}

// Whether the unit direction u lies inside the spherical triangle abc.
bool psvInsideCone(vec3 u, vec3 a, vec3 b, vec3 c) {
    float s0 = dot(u, cross(a, b)), s1 = dot(u, cross(b, c)), s2 = dot(u, cross(c, a));
    bool sameSign = (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
    return sameSign && dot(u, a + b + c) > 0.0;
}

// What the wedge computations need of a triangle, computed once per insertion (not per node).
struct PsvWedgeTriangle {
    vec3 v0, v1, v2; // world positions (directional light)
    vec3 a, b, c;    // unit directions from the light to the vertices (point light)
    float arc;       // bound on the arc from a to any point of the triangle; 2 = unbounded
    float minDist;   // PSV_WEDGE_BOUND 1: distance from the light to the triangle, rounded down
};

PsvWedgeTriangle psvWedgeTriangle(vec3 v0, vec3 v1, vec3 v2) {
    PsvWedgeTriangle t;
    t.v0 = v0; t.v1 = v1; t.v2 = v2;
    t.a = normalize(v0 - uLightPosition);
    t.b = normalize(v1 - uLightPosition);
    t.c = normalize(v2 - uLightPosition);
    // Seen from the light, every point u of a small triangle lies within the longer of the arcs
    // a→b, a→c of vertex a (the distance to a point is convex within a hemisphere around it).
    // Arcs below 0.5 rad are at most 1.011 times their chords; larger triangles get no bound.
    float chord = max(length(t.b - t.a), length(t.c - t.a));
    t.arc = chord < 0.5 ? 1.02 * chord : 2.0;
#if PSV_WEDGE_BOUND == 1
    t.minDist = length(psvClosestPoint(uLightPosition, v0, v1, v2) - uLightPosition) * (1.0 - 1e-5) - psvTolerance;
#else
    t.minDist = 0.0;
#endif
    return t;
}

// The wedge value a triangle needs in a shadow-plane node (see the top of this section), with a
// margin so rounding only widens it. Directional light: the shadow plane contains the light
// direction, so the distance to the plane is constant along a shadow ray and the wedge is the
// largest |distance| of the vertices (exact, the distance being linear over the triangle).
float psvWedge(vec4 plane, PsvWedgeTriangle t) {
    if (lightIsDirectional())
        return max(abs(psvSigned(plane, t.v0)), max(abs(psvSigned(plane, t.v1)), abs(psvSigned(plane, t.v2)))) + psvTolerance;
    vec3 n = plane.xyz;
    float m = max(abs(dot(n, t.a)), max(abs(dot(n, t.b)), abs(dot(n, t.c))));
#if PSV_WEDGE_BOUND == 2
    // The paper's wedge: the vertices' angles only (too narrow where an edge bulges further out).
    return min(1.0, m * (1.0 + 1e-5) + 1e-6);
#elif PSV_WEDGE_BOUND == 1
    // |sin| at a point p of the triangle is |s(p)| / |p - light|: s is linear, so |s(p)| is at most
    // its largest value at a vertex, and |p - light| at least the triangle's distance. Wider than
    // the exact value by about the triangle's depth extent over its distance, never narrower.
    float s = max(abs(psvSigned(plane, t.v0)), max(abs(psvSigned(plane, t.v1)), abs(psvSigned(plane, t.v2))));
    return t.minDist > 0.0 ? min(1.0, (s + psvTolerance) * (1.0 + 1e-5) / t.minDist + 1e-6) : 1.0;
#endif
    m = max(m, max(psvArcMax(n, t.a, t.b), max(psvArcMax(n, t.b, t.c), psvArcMax(n, t.c, t.a))));
    if (psvInsideCone(n, t.a, t.b, t.c) || psvInsideCone(-n, t.a, t.b, t.c)) m = 1.0;
    return min(1.0, m * (1.0 + 1e-5) + 1e-6);
}

// A cheap bound above psvWedge(), so the build computes the exact wedge only where it can raise a
// node's value: |sin| of the angle to the plane is 1-Lipschitz on the sphere, so
// |n·u| <= |n·a| + arc(a, u) for every point u of the triangle.
float psvWedgeBound(vec4 plane, PsvWedgeTriangle t) {
#if PSV_WEDGE_BOUND != 0
    return psvWedge(plane, t); // cheap already
#endif
    if (lightIsDirectional()) return psvWedge(plane, t); // exact and cheap already
    float m = max(abs(dot(plane.xyz, t.a)), max(abs(dot(plane.xyz, t.b)), abs(dot(plane.xyz, t.c))));
    return min(1.0, (m + t.arc) * (1.0 + 1e-5) + 2e-6);
}

// The scale psvInWedge compares a query point's plane distance with: its distance to a point
// light (1 for a directional one), computed once per query point.
float psvWedgeScale(vec3 q) { return lightIsDirectional() ? 1.0 : length(q - uLightPosition); }

// Whether a query point (plane value s, psvWedgeScale `scale`) is inside a node's intersection
// wedge (same units as psvWedge).
bool psvInWedge(float s, float scale, float wedge) { return abs(s) <= wedge * scale + psvTolerance; }
