#version 450
// Tests only (tests/LightReachesGLTest.cpp): lightReaches(p, n) per case, as every exact
// algorithm decides which pixels the light reaches; and, for comparison, the decision as it was
// made before (normalize() and cos, whose rounding GLSL leaves to the implementation).
layout(local_size_x = 64) in;
#include "common/light.glsl"

layout(std430, binding = 0) readonly buffer Cases { vec4 cases[]; }; // p, n per case
layout(std430, binding = 1) writeonly buffer Decisions { uvec2 decisions[]; }; // now, before
uniform uint uCases;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uCases) return;
    vec3 p = cases[2u * i].xyz, n = cases[2u * i + 1u].xyz;
    bool before = dot(n, toLight(p)) > 0.0 &&
                  (uLightType != LIGHT_SPOT || dot(normalize(p - uLightPosition), uLightDirection) > uLightCosCone);
    decisions[i] = uvec2(lightReaches(p, n) ? 1u : 0u, before ? 1u : 0u);
}
