#version 450
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in uint aMaterial;
uniform mat4 uViewProj;
out vec3 vWorld;
flat out vec3 vNormal;
flat out uint vMaterial;
flat out uint vTriangle;
void main() {
    vWorld = aPosition;
    vNormal = aNormal;
    vMaterial = aMaterial;
    vTriangle = uint(gl_VertexID) / 3u; // non-indexed draw: three vertices per triangle
    gl_Position = uViewProj * vec4(aPosition, 1.0);
}
