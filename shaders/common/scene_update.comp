#version 450
// Poses the scene's moving parts: each moving triangle is re-transformed from its object-space copy
// by its part's matrix, its winding flipped back under a mirroring matrix and its normal recomputed,
// exactly as poseTriangle() (framework/scene/Motion.cpp) does on the CPU. Static triangles are not
// touched. The buffers are SceneGpu's (framework/render/SceneGpu.cpp).
layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer ScenePositions { float positions[]; };  // 9 floats per triangle
struct TriangleInfo { vec3 normal; uint material; };
layout(std430, binding = 1) buffer SceneTriangles { TriangleInfo triangles[]; };
layout(std430, binding = 3) readonly buffer Local { vec4 local[]; };               // 3 per moving triangle
layout(std430, binding = 4) readonly buffer MovingIndex { uvec2 movingIndex[]; };  // (triangle, part)
layout(std430, binding = 5) readonly buffer Transforms { mat4 transforms[]; };     // 1 per part

uniform uint uCount;
uniform uint uInvocationsPerRow;

void main() {
    uint i = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (i >= uCount) return;
    uint triangle = movingIndex[i].x;
    mat4 m = transforms[movingIndex[i].y];
    vec3 v[3];
    for (uint k = 0u; k < 3u; ++k) v[k] = (m * vec4(local[3u * i + k].xyz, 1.0)).xyz;
    if (determinant(mat3(m)) < 0.0) {
        vec3 t = v[1];
        v[1] = v[2];
        v[2] = t;
    }
    vec3 n = cross(v[1] - v[0], v[2] - v[0]);
    float len = length(n);
    n = len > 0.0 ? n / len : vec3(0.0, 1.0, 0.0);
    for (uint k = 0u; k < 3u; ++k) {
        uint b = 9u * triangle + 3u * k;
        positions[b] = v[k].x;
        positions[b + 1u] = v[k].y;
        positions[b + 2u] = v[k].z;
    }
    triangles[triangle].normal = n;
}
