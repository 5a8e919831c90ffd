#version 450
// Tests only (tests/ShadowVolumesGLTest.cpp): svClosestAlong for each (eye, a, d, v) case:
// (1 if it found a place, t).
layout(local_size_x = 1) in;
#include "shadow_volumes/closest_along.glsl"

layout(std430, binding = 0) readonly buffer Cases { vec4 cases[]; }; // eye, a, d, v per case
layout(std430, binding = 1) writeonly buffer Results { vec2 results[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    float t;
    bool found = svClosestAlong(cases[4u * i].xyz, cases[4u * i + 1u].xyz, cases[4u * i + 2u].xyz, cases[4u * i + 3u].xyz, t);
    results[i] = vec2(found ? 1.0 : 0.0, t);
}
