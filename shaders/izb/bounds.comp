#version 450
// izb, grid_fit samples: each face's box of its lit samples this frame, as ordered words (the uint
// order of the words is the float order of the values, so atomicMin and atomicMax make the box).
#include "common/light.glsl"
#include "common/watertight.glsl"
#include "izb/layout.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(std430, binding = IZB_BOUNDS_BINDING) buffer FaceBounds { uint faceBounds[]; };
uniform ivec2 uResolution;
uniform float uRayOffset;
#define IZB_FIT_SAMPLES 0
#include "izb/grid.glsl"

uint izbOrder(float f) { uint u = floatBitsToUint(f); return (u & 0x80000000u) != 0u ? ~u : u | 0x80000000u; }

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, uResolution))) return;
    vec4 pos = texelFetch(uPosition, px, 0);
    vec3 n = texelFetch(uNormal, px, 0).xyz;
    if (!(pos.w >= 0.5 && lightReaches(pos.xyz, n))) return;
    vec3 x = watertightOrigin(pos.xyz, n, uRayOffset);
    int face = 0;
    vec2 uv;
    if (lightIsDirectional()) uv = izbOrtho(x);
    else {
        vec3 w = x - uLightPosition;
        if (!(dot(w, w) > 0.0)) return;
        face = izbFace(w);
        vec3 f = izbOnFace(w, face);
        uv = f.xy / f.z;
    }
    if (!(abs(uv.x) <= 1e30 && abs(uv.y) <= 1e30)) return; // a NaN never reaches the box
    uint b = 4u * uint(face);
    atomicMin(faceBounds[b], izbOrder(uv.x));
    atomicMin(faceBounds[b + 1u], izbOrder(uv.y));
    atomicMax(faceBounds[b + 2u], izbOrder(uv.x));
    atomicMax(faceBounds[b + 3u], izbOrder(uv.y));
}
