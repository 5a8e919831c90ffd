#version 450
// Positions only: each triangle's normal and material are fetched per fragment by gl_PrimitiveID
// (gbuffer.frag), so the scene keeps no per-vertex copy of them.
layout(location = 0) in vec3 aPosition;
uniform mat4 uViewProj;
out vec3 vWorld;
void main() {
    vWorld = aPosition;
    gl_Position = uViewProj * vec4(aPosition, 1.0);
}
