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
uniform int uBorder;     // 0 the faces (triangles); the faces' borders for the border pass
                         // (volume.frag, SV_BORDER_PASS): 1 their edges (lines), 2 their finite corners (points)
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

// The vertices of one primitive list: the faces as triangles, or their borders as lines or points.
// A side quad's corners are 0 v, 1 u, 2 u at infinity, 3 v at infinity; a near cap's are 0, 1, 2.
const int kQuadTriangles[6] = int[6](0, 1, 2, 0, 2, 3); // (v, u, u inf) and (v, u inf, v inf)
const int kQuadLines[8] = int[8](0, 1, 1, 2, 0, 3, 2, 3); // its four borders, the one at infinity too
const int kCapLines[6] = int[6](0, 1, 1, 2, 2, 0);
int verticesPerQuad() { return uBorder == 0 ? 6 : uBorder == 1 ? 8 : 2; }
int verticesPerCap() { return uBorder == 2 ? 3 : 6; }

void main() {
    int j = gl_VertexID % (uPass == 0 ? verticesPerQuad() : verticesPerCap());
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
        // The quad (v, u, u at infinity, v at infinity), outward for a volume whose cap walks u -> v.
        int c = uBorder == 0 ? kQuadTriangles[j] : uBorder == 1 ? kQuadLines[j] : j;
        if (c == 0) gl_Position = finite(v);
        else if (c == 1) gl_Position = finite(u);
        else if (c == 2) gl_Position = infinite(u);
        else gl_Position = infinite(v);
        vec3 toL = lightIsDirectional() ? -uLightDirection : uLightPosition - u;
        vPlane = planeThrough(u, cross(v - u, toL));
        vA = u;
        vB = v;
        vKind = SV_FACE_SIDE;
        return;
    }
    uint t = uint(gl_VertexID) / uint(verticesPerCap());
    int f = texelFetch(uFacing, int(t)).x;
    if (f == 0) { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); vPlane = kNever; return; }
    // Near cap corners 0, 1, 2 (flipped: 0, 2, 1); far cap the other way round. The border pass
    // takes the near cap's borders only: a far cap lies at infinity, beyond every test point.
    const uint kOrder[6] = uint[6](0u, 1u, 2u, 0u, 2u, 1u);
    uint k = uBorder == 0 ? kOrder[f > 0 ? j : (j + 3) % 6] : uint(uBorder == 1 ? kCapLines[j] : j);
    vec3 p = corner(t, k);
    if (j < 3 || uBorder != 0) {
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
