// Scene buffers shared by every algorithm (bound by SceneGpu::bindStorage(); layouts mirrored in
// framework/render/SceneGpu.cpp).
layout(std430, binding = 0) readonly buffer ScenePositions { float scenePositions[]; }; // 9 floats per triangle
struct TriangleInfo { vec3 normal; uint material; };
layout(std430, binding = 1) readonly buffer SceneTriangles { TriangleInfo sceneTriangles[]; };
struct MaterialInfo { vec3 albedo; float opacity; };
layout(std430, binding = 2) readonly buffer SceneMaterials { MaterialInfo sceneMaterials[]; };

#if SCENE_POSITION_TEXELS
// The same floats through a buffer texture (bound by SceneGpu::bindStorage to unit kScenePositionUnit):
// one gathered fetch per vertex instead of three per-lane storage loads on a SIMD CPU back end.
layout(binding = 15) uniform samplerBuffer uScenePositionTexels;
vec3 sceneVertex(uint triangle, uint k) { return texelFetch(uScenePositionTexels, int(3u * triangle + k)).xyz; }
#else
vec3 sceneVertex(uint triangle, uint k) {
    uint b = 9u * triangle + 3u * k;
    return vec3(scenePositions[b], scenePositions[b + 1u], scenePositions[b + 2u]);
}
#endif
