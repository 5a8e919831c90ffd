#version 450
#include "common/scene.glsl"
in vec3 vWorld;
flat in vec3 vNormal;
flat in uint vMaterial;
flat in uint vTriangle;
uniform vec3 uCameraPosition;
layout(location = 0) out vec4 oPosition;
layout(location = 1) out vec4 oNormal;
layout(location = 2) out vec4 oAlbedo;
layout(location = 3) out uint oTriangleId;
void main() {
    // Two-sided surfaces: the stored normal faces the camera, so N·L means "the visible side is lit".
    vec3 n = dot(vNormal, uCameraPosition - vWorld) < 0.0 ? -vNormal : vNormal;
    oPosition = vec4(vWorld, 1.0);
    oNormal = vec4(n, 0.0);
    oAlbedo = vec4(sceneMaterials[vMaterial].albedo, 1.0);
    oTriangleId = vTriangle + 1u;
}
