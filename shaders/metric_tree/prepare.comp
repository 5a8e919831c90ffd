#version 450
// metric_tree build, pass 1 of 2 (one invocation per cluster): culls the cluster by its normal cone
// and writes its node: the cone (sphere) or conservative capsule-cone (capsule) seen from the light,
// the smallest light distance of its bounding volume, and empty children. insert.comp links the
// nodes into the tree afterwards; a node is private to its cluster until then.
#include "common/light.glsl"
#include "metric_tree/tree.glsl"
layout(local_size_x = 64) in;

uniform uint uClusterCount;
uniform uint uInvocationsPerRow; // 2D dispatch past 65535 groups
uniform float uDepthTolerance;   // world units subtracted from every light distance bound

// Whether every triangle of the cluster faces the light from wherever it is in the cluster's
// bounding sphere (centre c, radius R): the angle between the normal-cone axis and any direction
// to the light is then below pi/2 by more than the cone's half-angle.
bool facesLight(MtCluster c) {
    if (c.b.w <= -1.0) return false; // the normals span every direction
    vec3 centre = 0.5 * (c.a.xyz + c.b.xyz);
    float radius = 0.5 * length(c.b.xyz - c.a.xyz) + c.a.w;
    vec3 toL;
    float spread = 0.0;
    if (lightIsDirectional()) {
        toL = -uLightDirection;
    } else {
        vec3 d = uLightPosition - centre;
        float dl = length(d);
        if (dl <= radius) return false;
        toL = d / dl;
        spread = asin(radius / dl);
    }
    float halfAngle = acos(clamp(c.b.w, -1.0, 1.0));
    return mtAngle(c.axis.xyz, toL) + halfAngle + spread < 0.5 * kMtPi - 1e-4;
}

void main() {
    uint i = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (i >= uClusterCount) return;
    MtCluster c = mtClusters[i];
    MtNode n;
    n.child[0] = n.child[1] = n.child[2] = MT_NO_CHILD;
    n.overlapMin = floatBitsToUint(kMtInf);
    n.overlapMax = 0u;
    n.flags = 0u;
    n.pad = 0u;
    float r = c.a.w;
    vec3 A = c.a.xyz, B = c.b.xyz;
#if MT_NORMAL_CONE_CULLING
    // Front faces of closed meshes cast nothing the back faces do not (exact for closed meshes only).
    if (facesLight(c)) n.flags |= MT_NODE_CULLED;
#endif
    if (lightIsDirectional()) {
        n.a = vec4(mtToLightSpace(A), r);
        n.b = vec4(mtToLightSpace(B), uintBitsToFloat(MT_DELTA_PENDING));
        if (A == B) n.b.xyz = n.a.xyz; // exactly equal: the distances take the sphere path
        float depth = min(dot(A - uDepthOrigin, uLightDirection), dot(B - uDepthOrigin, uLightDirection)) - r;
        n.minDist = floatBitsToUint(max(depth - uDepthTolerance, 0.0)); // >= 0: uint order = float order
    } else {
        // The segment's point nearest the light: where the capsule looks widest (paper Fig. 6c).
        vec3 ab = B - A;
        float l2 = dot(ab, ab);
        float t = l2 > 0.0 ? clamp(dot(uLightPosition - A, ab) / l2, 0.0, 1.0) : 0.0;
        float dist = length(A + t * ab - uLightPosition);
        // Light inside: the cone is every direction. Near the sphere, asin's slope magnifies the
        // rounding of r / dist beyond uLsEps, so the bound pi / 2 is used instead.
        float alpha = dist <= r ? kMtPi : (r > 0.999 * dist ? 0.5 * kMtPi : asin(r / dist));
        vec3 a = normalize(A - uLightPosition), b = A == B ? a : normalize(B - uLightPosition);
        // An arc of nearly pi has an ill-defined great circle: cover every direction instead.
        if (dot(a, b) < -0.999) alpha = kMtPi;
        // The great circle of a very short arc is ill-defined in floats (cross(a, b) carries an
        // error of ~1e-7 / length rad): below 2e-3 rad the arc becomes its midpoint, its radius
        // grown by half its length, which holds the whole arc. Longer arcs keep their circle's
        // error under 5e-5 rad, below uLsEps.
        if (A != B && alpha < kMtPi) {
            float len = mtAngle(a, b);
            if (len < 2e-3) {
                a = b = normalize(a + b);
                alpha += 0.5 * len;
            }
        }
        // A cone of every direction needs no centre; the light at the centre would make it NaN.
        if (alpha >= kMtPi) a = b = vec3(0.0, 0.0, 1.0);
        n.a = vec4(a, alpha);
        n.b = vec4(b, uintBitsToFloat(MT_DELTA_PENDING));
        n.minDist = floatBitsToUint(max(dist - r - uDepthTolerance, 0.0)); // >= 0: uint order = float order
    }
    mtNodes[i] = n;
}
