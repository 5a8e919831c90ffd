#version 450
// shadow_volumes, the volume pass: the shadow volumes' faces, from the scene's posed positions.
// uPass 0 draws the silhouette quads (6 vertices per instance, one instance per record of
// silhouettes.comp); uPass 1 the caps (6 vertices per triangle: the triangle itself, wound
// outwards, and its projection to infinity, wound the other way). A vertex at infinity is the
// homogeneous direction away from the light (w = 0): with depth clamping on, nothing is cut by the
// far plane, so the volumes need no far plane of their own.
// Both passes are this one program, so a vertex shared by a quad and a cap is computed by the same
// code from the same floats (and `invariant` keeps the compiler from computing it two ways).
#include "common/light.glsl"
#include "shadow_volumes/layout.glsl"

layout(binding = SV_POSITION_UNIT) uniform samplerBuffer uScenePositionTexels;
layout(binding = SV_FACING_UNIT) uniform isamplerBuffer uFacing;
layout(binding = SV_RECORDS_UNIT) uniform usamplerBuffer uRecords;
layout(binding = SV_SIDES_UNIT) uniform usamplerBuffer uSides;
uniform mat4 uViewProj;
uniform int uPass;       // 0 silhouette quads, 1 caps
uniform uint uCapacity;  // records the list holds

invariant gl_Position;
flat out vec4 vPlane;    // the face's plane (unit normal, world units): close calls
flat out uint vTriangle; // the cap's triangle, ~0 for every other face
flat out vec3 vA, vB, vC; // a near cap's corners; a side quad's edge (vA, vB) from the light's side
flat out int vKind;       // SV_FACE_SIDE, SV_FACE_NEAR_CAP or SV_FACE_FAR_CAP

vec3 corner(uint t, uint k) { return texelFetch(uScenePositionTexels, int(3u * t + k)).xyz; }
vec4 finite(vec3 p) { return uViewProj * vec4(p, 1.0); }
vec4 infinite(vec3 p) { return uViewProj * vec4(lightIsDirectional() ? uLightDirection : p - uLightPosition, 0.0); }
vec4 planeThrough(vec3 p, vec3 n) {
    float l = length(n);
    n = l > 0.0 ? n / l : vec3(0.0);
    return vec4(n, -dot(n, p));
}
const vec4 kNever = vec4(0.0, 0.0, 0.0, 1.0); // a plane no point is close to

void main() {
    int j = gl_VertexID % 6;
    vTriangle = ~0u;
    vA = vB = vC = vec3(0.0);
    vKind = SV_FACE_FAR_CAP;
    if (uPass == 0) {
        if (uint(gl_InstanceID) >= uCapacity) { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); vPlane = kNever; return; }
        uint record = texelFetch(uRecords, gl_InstanceID).x;
        uint side = texelFetch(uSides, int(record >> 1)).x;
        uint t = side >> 3, k = (side >> 1) & 3u;
        vec3 u = corner(t, k), v = corner(t, (k + 1u) % 3u);
        if ((record & 1u) != 0u) { vec3 w = u; u = v; v = w; }
        // The quad (v, u, u at infinity, v at infinity), outward for a volume whose cap walks u -> v,
        // as two triangles: (v, u, u inf) and (v, u inf, v inf).
        if (j == 0 || j == 3) gl_Position = finite(v);
        else if (j == 1) gl_Position = finite(u);
        else if (j == 2 || j == 4) gl_Position = infinite(u);
        else gl_Position = infinite(v);
        vec3 toL = lightIsDirectional() ? -uLightDirection : uLightPosition - u;
        vPlane = planeThrough(u, cross(v - u, toL));
        vA = u;
        vB = v;
        vKind = SV_FACE_SIDE;
        return;
    }
    uint t = uint(gl_VertexID) / 6u;
    int f = texelFetch(uFacing, int(t)).x;
    if (f == 0) { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); vPlane = kNever; return; }
    // Near cap corners 0, 1, 2 (flipped: 0, 2, 1); far cap the other way round.
    const uint kOrder[6] = uint[6](0u, 1u, 2u, 0u, 2u, 1u);
    uint k = kOrder[f > 0 ? j : (j + 3) % 6];
    vec3 p = corner(t, k);
    if (j < 3) {
        gl_Position = finite(p);
        vec3 a = corner(t, 0u), b = corner(t, 1u), c = corner(t, 2u);
        vPlane = planeThrough(a, cross(b - a, c - a));
        vTriangle = t;
        vA = a;
        vB = b;
        vC = c;
        vKind = SV_FACE_NEAR_CAP;
    } else {
        gl_Position = infinite(p);
        vPlane = kNever;
    }
}
