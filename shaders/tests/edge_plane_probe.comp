#version 450
// Tests only (tests/ShadowPlaneGLTest.cpp): svEdgePlane for each edge (a, b), as psv and ptsv
// compute their shadow planes.
layout(local_size_x = 64) in;
#include "common/light.glsl"
#include "common/shadow_volume.glsl"

layout(std430, binding = 0) readonly buffer Edges { vec4 ends[]; }; // a, b per edge
layout(std430, binding = 1) writeonly buffer Planes { vec4 planes[]; };
uniform uint uEdges;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uEdges) return;
    planes[i] = svEdgePlane(ends[2u * i].xyz, ends[2u * i + 1u].xyz, 1.0);
}
