#version 450
// shadow_volumes, pass 1: which way each triangle's shadow volume is wound, decided once here and
// read by both the silhouette pass and the caps (a decision shared between shaders is made by one
// of them: docs/architecture.md, rule 4). +1: the triangle faces the light and bounds its volume as
// wound; -1: it faces away and bounds it flipped (every triangle casts, open meshes and soups
// included); 0: no volume (SV_LIGHT_FACING_ONLY, the classic closed-mesh setting, for triangles
// facing away). A triangle whose plane holds the light (side exactly 0) has a flat volume, which
// holds no point off that plane: it gets none (0). Its faces do not cancel when the light lies
// inside the triangle (ninth probe: the faces around it, all in its plane, left 198 pixels behind
// it counted as shadowed).
#include "common/light.glsl"
#include "common/scene.glsl"
#include "shadow_volumes/layout.glsl"
layout(local_size_x = 64) in;
uniform uint uInvocationsPerRow;
layout(std430, binding = SV_FACING_BINDING) writeonly buffer Facing { int facing[]; };
uniform uint uTriangleCount;

void main() {
    uint t = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x; // rows: ShaderProgram::dispatchLinear
    if (t >= uTriangleCount) return;
    vec3 a = sceneVertex(t, 0u), b = sceneVertex(t, 1u), c = sceneVertex(t, 2u);
    vec3 n = cross(b - a, c - a);
    float side = lightIsDirectional() ? -dot(n, uLightDirection) : dot(n, uLightPosition - a);
#if SV_LIGHT_FACING_ONLY
    facing[t] = side > 0.0 ? 1 : 0;
#else
    facing[t] = side > 0.0 ? 1 : (side < 0.0 ? -1 : 0);
#endif
}
