#version 450
#include "common/scene.glsl"
in vec3 vWorld;
uniform vec3 uCameraPosition;
// The scene's TriangleInfo (normal bits, material) per triangle: SceneGpu's view at kSceneTriangleUnit.
layout(binding = 14) uniform usamplerBuffer uSceneTriangleTexels;
layout(location = 0) out vec4 oPosition;
layout(location = 1) out vec4 oNormal;
layout(location = 2) out vec4 oAlbedo;
layout(location = 3) out uint oTriangleId;
void main() {
    // One non-indexed draw of every triangle, no geometry shader: gl_PrimitiveID is the triangle.
    uint triangle = uint(gl_PrimitiveID);
    uvec4 info = texelFetch(uSceneTriangleTexels, int(triangle));
    vec3 normal = uintBitsToFloat(info.xyz);
    // Two-sided surfaces: the stored normal faces the camera, so N·L means "the visible side is lit".
    vec3 n = dot(normal, uCameraPosition - vWorld) < 0.0 ? -normal : normal;
    oPosition = vec4(vWorld, 1.0);
    oNormal = vec4(n, 0.0);
    oAlbedo = vec4(sceneMaterials[info.w].albedo, 1.0);
    oTriangleId = triangle + 1u;
}
