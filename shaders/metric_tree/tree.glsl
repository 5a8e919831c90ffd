// metric_tree: the GPU structures (mirrored in algorithms/metric_tree/MetricTreeGpuLayout.h) and the
// light-space distances the build and the query share (mirrored in MetricTreeMath.h, which the CPU
// tree builder and the tests use).
//
// Light space. Point light: an element is an arc of unit directions from the light (a sphere's
// centre is a point-arc, a = b; a capsule's segment is the arc from a to b) and distances are angles.
// Directional light: an element is a point or a segment in the plane orthogonal to the light
// direction, coordinates (u, v, 0), and distances are Euclidean (paper section 6, "Discussion").
#include "metric_tree/layout.glsl"
#include "common/statistics.glsl"

struct MtCluster {
    vec4 a;      // world: sphere centre or capsule end A; w: radius
    vec4 b;      // world: capsule end B (= a for a sphere); w: cos of the normal cone's half-angle
    vec4 axis;   // normal cone axis (unit; also the slabs' normal); w: lower slab, dot(axis, x)
    float slabMax;
    uint first;  // first triangle in the cluster-ordered geometry
    uint count;  // triangles
    uint flags;  // MT_FLAG_*
};

struct MtNode {
    vec4 a;           // light space: first end of the centre element; w: angular radius alpha
    vec4 b;           // light space: second end (= a for a sphere); w: partitioning distance delta
    uint child[3];    // near, far, overlap: node index + 1, MT_NO_CHILD = empty
    uint minDist;     // float bits: smallest light distance of the subtree (its clusters' bounds)
    uint overlapMin;  // float bits: [min, max] light-space distance from this pivot of every
    uint overlapMax;  //   element of the overlap subtree (only meaningful when child[2] != 0)
    uint flags;       // MT_NODE_*
    uint pad;
};

#ifndef MT_NODE_ACCESS
// The build reads child fields other invocations are changing: no stale cached values.
#define MT_NODE_ACCESS coherent
#endif
layout(std430, binding = MT_CLUSTER_BINDING) readonly buffer MtClusters { MtCluster mtClusters[]; };
layout(std430, binding = MT_NODE_BINDING) MT_NODE_ACCESS buffer MtNodes { MtNode mtNodes[]; };
layout(std430, binding = MT_COUNTER_BINDING) coherent buffer MtCounters { uint mtCounters[]; };

// The nodes through a buffer texture (four RGBA32UI texels each), for reads of what the current
// dispatch does not change (the query) or changes only monotonically (the insertion; see there).
// A SIMD CPU back end (llvmpipe) gathers a texel fetch for all its lanes at once but loads a
// storage buffer lane by lane; a GPU reads both through its caches.
layout(binding = MT_NODE_UNIT) uniform usamplerBuffer uNodeTexels;
// Test faults (framework/gl/Shader.h), in the insertion only: every delta read is the sentinel, as
// a reader the final write has not reached yet would see it (the memory model allows that for a
// whole dispatch), and a NaN encoding converts to 0.0, as uintBitsToFloat may (undefined for NaNs).
vec4 mtBitsToFloat(uvec4 w) {
    vec4 f = uintBitsToFloat(w);
#if SHADOWLAB_FAULT_NAN_BITS_UNDEFINED && MT_INSERT_PASS
    for (int k = 0; k < 4; ++k)
        if ((w[k] & 0x7F800000u) == 0x7F800000u && (w[k] & 0x007FFFFFu) != 0u) f[k] = 0.0;
#endif
    return f;
}

// Node i; `deltaWord`: its b.w as stored, to be compared with MT_DELTA_PENDING as a raw word.
MtNode mtNode(uint i, out uint deltaWord) {
    int t = int(4u * i);
    uvec4 t0 = texelFetch(uNodeTexels, t), t1 = texelFetch(uNodeTexels, t + 1);
    uvec4 t2 = texelFetch(uNodeTexels, t + 2), t3 = texelFetch(uNodeTexels, t + 3);
#if SHADOWLAB_FAULT_DELTA_UNSEEN && MT_INSERT_PASS
    t1.w = MT_DELTA_PENDING;
#endif
    deltaWord = t1.w;
    MtNode n;
    n.a = mtBitsToFloat(t0);
    n.b = mtBitsToFloat(t1);
    n.child[0] = t2.x; n.child[1] = t2.y; n.child[2] = t2.z;
    n.minDist = t2.w; n.overlapMin = t3.x; n.overlapMax = t3.y; n.flags = t3.z; n.pad = t3.w;
    return n;
}
MtNode mtNode(uint i) {
    uint deltaWord;
    return mtNode(i, deltaWord);
}

const float kMtPi = 3.14159265358979;
const float kMtInf = uintBitsToFloat(0x7F800000u);

uniform float uLsEps;   // light-space margin (rad, or world units for a directional light): far
                        // above float rounding, so every bound stays conservative once rounded
uniform vec3 uLightU;   // directional light: orthonormal basis of the plane orthogonal to it
uniform vec3 uLightV;
uniform vec3 uDepthOrigin; // directional light: depth is measured along its direction from here

// Distance from the light along which shadow rays travel: an occluder of q is strictly nearer.
float mtLightDepth(vec3 x) {
    return lightIsDirectional() ? dot(x - uDepthOrigin, uLightDirection) : length(x - uLightPosition);
}

// World point -> light space.
vec3 mtToLightSpace(vec3 x) {
    if (lightIsDirectional()) return vec3(dot(x, uLightU), dot(x, uLightV), 0.0);
    return normalize(x - uLightPosition);
}

float mtAngle(vec3 u, vec3 v) { return atan(length(cross(u, v)), dot(u, v)); }

// ---- angular (point light) ----

// Whether unit direction y, on the great circle of arc a->b (normal n = cross(a, b)), lies on the
// arc. Arcs are shorter than pi (prepare.comp makes longer ones cover every direction).
bool mtOnArc(vec3 y, vec3 a, vec3 b, vec3 n) { return dot(cross(a, y), n) >= 0.0 && dot(cross(y, b), n) >= 0.0; }

// One atan per call, whatever the element: the nearer end is the one with the larger cosine, and
// where p's foot on the great circle lies on the arc that foot is nearer than either end. Capsules
// and spheres (a = b: no circle) take the same path, so a SIMD group mixing them runs it once.
// The foot lies on the arc when p is on b's side of a and on a's side of b along the circle:
// with g = a x b, (a x foot).g and (foot x b).g are, up to |g|, p.b - (a.b)(p.a) and
// p.a - (a.b)(p.b) (a, b unit), so neither the circle's normal nor the foot is needed for the test.
float mtPointArc(vec3 p, vec3 a, vec3 b) {
    float pa = dot(p, a), pb = dot(p, b);
    vec3 e = pa >= pb ? a : b;
    float y = length(cross(p, e)), x = max(pa, pb); // atan(y, x): the angle from p to e
    vec3 g = cross(a, b);
    float g2 = dot(g, g);
    if (g2 > 1e-24) {
        float ab = dot(a, b);
        if (pb - ab * pa >= 0.0 && pa - ab * pb >= 0.0) {
            float s = dot(p, g) * inversesqrt(g2); // sine of the angle from p to the circle
            // atan rather than asin: asin loses half the digits near the circle's poles.
            y = abs(s);
            x = sqrt(max(dot(p, p) - s * s, 0.0));
        }
    }
    return atan(y, x);
}

// Smallest angle between two arcs: 0 where they cross, else attained at an end of one of them
// (the distance to a great circle grows away from where the circles cross).
float mtArcArc(vec3 a1, vec3 b1, vec3 a2, vec3 b2) {
    float d = min(min(mtPointArc(a1, a2, b2), mtPointArc(b1, a2, b2)), min(mtPointArc(a2, a1, b1), mtPointArc(b2, a1, b1)));
    vec3 n1 = cross(a1, b1), n2 = cross(a2, b2);
    vec3 x = cross(n1, n2);
    float xl = length(x);
    if (xl > 1e-12 && length(n1) > 1e-12 && length(n2) > 1e-12) {
        x /= xl;
        if ((mtOnArc(x, a1, b1, n1) && mtOnArc(x, a2, b2, n2)) || (mtOnArc(-x, a1, b1, n1) && mtOnArc(-x, a2, b2, n2)))
            d = 0.0;
    }
    return d;
}

// ---- Euclidean (directional light, z = 0) ----

float mtPointSeg(vec3 p, vec3 a, vec3 b) {
    vec3 ab = b - a;
    float l2 = dot(ab, ab);
    float t = l2 > 0.0 ? clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    return length(p - (a + t * ab));
}

float mtCross2(vec2 u, vec2 v) { return u.x * v.y - u.y * v.x; }

float mtSegSeg(vec3 a1, vec3 b1, vec3 a2, vec3 b2) {
    vec2 d1 = b1.xy - a1.xy, d2 = b2.xy - a2.xy;
    float o1 = mtCross2(d1, a2.xy - a1.xy), o2 = mtCross2(d1, b2.xy - a1.xy);
    float o3 = mtCross2(d2, a1.xy - a2.xy), o4 = mtCross2(d2, b1.xy - a2.xy);
    if (((o1 < 0.0 && o2 > 0.0) || (o1 > 0.0 && o2 < 0.0)) && ((o3 < 0.0 && o4 > 0.0) || (o3 > 0.0 && o4 < 0.0)))
        return 0.0;
    return min(min(mtPointSeg(a1, a2, b2), mtPointSeg(b1, a2, b2)), min(mtPointSeg(a2, a1, b1), mtPointSeg(b2, a1, b1)));
}

// ---- what the tree uses ----

// Distance from a light-space point to an element's centre.
float mtPointDist(vec3 p, vec3 a, vec3 b) {
    if (lightIsDirectional()) return a == b ? length(p - a) : mtPointSeg(p, a, b);
    return mtPointArc(p, a, b); // a sphere (a = b) included
}

// Smallest distance between two elements' centres.
float mtMinDist(vec3 a1, vec3 b1, vec3 a2, vec3 b2) {
    if (a1 == b1) return mtPointDist(a1, a2, b2);
    if (a2 == b2) return mtPointDist(a2, a1, b1);
    return lightIsDirectional() ? mtSegSeg(a1, b1, a2, b2) : mtArcArc(a1, b1, a2, b2);
}

// Largest distance between two elements' centres: Euclidean, at a pair of ends (convexity);
// angular, pi minus the smallest distance from the antipodal element.
float mtMaxDist(vec3 a1, vec3 b1, vec3 a2, vec3 b2) {
    if (lightIsDirectional())
        return max(max(length(a1 - a2), length(a1 - b2)), max(length(b1 - a2), length(b1 - b2)));
    return kMtPi - mtMinDist(-a1, -b1, a2, b2);
}
