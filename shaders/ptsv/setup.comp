#version 450
// Triangle setup (paper 2): the four planes of each triangle's shadow volume (three edge planes,
// bit-identical up to negation for triangles sharing an edge, and the triangle plane, biased away
// from the light when front faces cast too) and the three additional culling planes through the
// light and each vertex (Figure 4). Inside the volume is negative.
#include "common/light.glsl"
#include "common/scene.glsl"
#include "ptsv/ptsv.glsl"
#include "common/shadow_volume.glsl"
layout(local_size_x = 64) in;

uniform uint uTriangleCount;
uniform uint uInvocationsPerRow; // 2D dispatch past 65535 groups
uniform float uPlaneBias;        // world units the triangle plane moves away from the light

// Additional culling plane at vertex v between edge planes a and b (both contain v and the light):
// the half vector of their normals, made orthogonal to the direction towards the light, is the
// normal of a plane through the light and v that has the whole wedge, hence the whole volume, on
// its negative side. Unstable for slivers (normals nearly opposite): then a null plane, never culling.
vec4 ptsvCullingPlane(vec4 a, vec4 b, vec3 v) {
    vec3 toL = lightIsDirectional() ? -uLightDirection : uLightPosition - v;
    float tl = length(toL);
    vec3 h = a.xyz + b.xyz;
    if (!(tl > 0.0) || length(h) < 1e-3) return vec4(0.0);
    toL /= tl;
    h -= dot(h, toL) * toL;
    float hl = length(h);
    if (hl < 1e-3) return vec4(0.0);
    h /= hl;
    return vec4(h, -dot(h, v));
}

void main() {
    uint t = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (t >= uTriangleCount) return;
    uint base = PTSV_PLANES_PER_TRIANGLE * t;
    vec3 v0 = sceneVertex(t, 0u), v1 = sceneVertex(t, 1u), v2 = sceneVertex(t, 2u);
    vec3 n = cross(v1 - v0, v2 - v0);
    float len = length(n);
    n = len > 0.0 ? n / len : vec3(0.0);
    vec3 toL = lightIsDirectional() ? -uLightDirection : uLightPosition - v0;
    float side = dot(n, toL);
    uint status = PTSV_CASTER_OK;
    // Light (almost) in the triangle's plane: the volume is a sliver under 1e-6 rad wide, and the
    // planes' orientation would rest on rounding.
    if (!(abs(side) > 1e-6 * length(toL))) status = PTSV_CASTER_EDGE_ON;
#if PTSV_FRONT_FACE_CULLING
    else if (side > 0.0) status = PTSV_CASTER_FACING;
#endif
    vec4 e0 = vec4(0.0), e1 = vec4(0.0), e2 = vec4(0.0), cap = vec4(0.0);
    if (status == PTSV_CASTER_OK) {
        float flip = side < 0.0 ? 1.0 : -1.0;
        e0 = svEdgePlane(v0, v1, flip);
        e1 = svEdgePlane(v1, v2, flip);
        e2 = svEdgePlane(v2, v0, flip);
        if (e0.xyz == vec3(0.0) || e1.xyz == vec3(0.0) || e2.xyz == vec3(0.0)) status = PTSV_CASTER_EDGE_ON;
        vec3 nc = side > 0.0 ? n : -n; // the light side of the triangle plane is positive
        cap = vec4(nc, -dot(nc, v0));
#if !PTSV_FRONT_FACE_CULLING
        // Paper 2: with front faces casting, a sample on a lit triangle lies on that triangle's own
        // plane; the bias keeps rounding from shadowing it (the ray offset does too, see the docs).
        cap.w += uPlaneBias;
#endif
    }
    if (status == PTSV_CASTER_OK) {
        ptsvPlanes[base + 0u] = e0;
        ptsvPlanes[base + 1u] = e1;
        ptsvPlanes[base + 2u] = e2;
        ptsvPlanes[base + 3u] = cap;
        ptsvPlanes[base + 4u] = ptsvCullingPlane(e2, e0, v0); // planes meeting at v0: edges v2v0, v0v1
        ptsvPlanes[base + 5u] = ptsvCullingPlane(e0, e1, v1);
        ptsvPlanes[base + 6u] = ptsvCullingPlane(e1, e2, v2);
    } else {
        // A culled triangle's planes are written too, rejecting everything (every value +1): the
        // buffer is never cleared, so unwritten planes would be a previous frame's or undefined
        // (GL leaves new storage uninitialised), and a traversal that read them through a wrong
        // status would cast their shadow. The status test comes first; these make it not matter.
        for (uint i = 0u; i < 7u; ++i) ptsvPlanes[base + i] = PTSV_REJECT_ALL;
#if SHADOWLAB_STATISTICS
        atomicAdd(ptsvCounters[status == PTSV_CASTER_FACING ? PTSV_C_CULLED_FACING : PTSV_C_CULLED_EDGE_ON], 1u);
#endif
    }
    // The status as a small integer value (0.0, 1.0, 2.0: exact, and normal numbers), not as the
    // bit pattern uintBitsToFloat(1u): that is a denormal, which GLSL 4.50 section 4.7.1 lets any
    // read flush to 0 (= PTSV_CASTER_OK).
    ptsvPlanes[base + 7u] = vec4(float(status), 0.0, 0.0, 0.0);
}
