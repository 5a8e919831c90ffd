#version 450
// shadow_volumes, the depth pass: the depth buffer the volumes are tested against is the G-buffer's,
// moved to the test point (test_point.glsl) and at least SV_NUDGE_ULPS steps of the float nearer
// than the G-buffer's own depth. The nudge is what makes a lit point's own triangle count as in
// front of it: that triangle is the near cap of its own volume, rasterised at the very depth the
// G-buffer stored, so without it the depth test would toss a coin on every lit pixel.
#include "shadow_volumes/layout.glsl"
#include "shadow_volumes/test_point.glsl"
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(binding = SV_DEPTH_UNIT) uniform sampler2D uDepth;
uniform mat4 uViewProj;
uniform float uRayOffset;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    float d = texelFetch(uDepth, px, 0).r;
    vec4 pos = texelFetch(uPosition, px, 0);
    if (pos.w < 0.5) { gl_FragDepth = d; return; }
    vec3 q = svTestPoint(pos.xyz, texelFetch(uNormal, px, 0).xyz, uRayOffset);
    vec4 c = uViewProj * vec4(q, 1.0);
    float dq = 0.5 * (c.z / c.w) + 0.5;
    // d > 0 on every point past the near plane; the bit step keeps to normal floats.
    float nudged = d > 1e-30 ? uintBitsToFloat(floatBitsToUint(d) - uint(SV_NUDGE_ULPS)) : 0.0;
    gl_FragDepth = dq < nudged ? max(dq, 0.0) : nudged; // a NaN dq compares false: the nudge
}
