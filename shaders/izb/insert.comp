#version 450
// izb, pass 1: every lit view sample into its light-grid cell's list (a lock-free push: the cell's
// head swapped for the sample). The sample keeps the reference's ray origin x = p + n * offset, and
// the cell it went to (as an integer: a cell index as float bits could be a denormal or a NaN). A sample the light does not reach (outside a spot's cone, facing away) is
// not inserted: its visibility is 0, as the reference's.
#include "common/light.glsl"
#include "common/watertight.glsl"
#include "izb/layout.glsl"
#include "izb/grid.glsl"
#include "common/stored_float.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(std430, binding = IZB_HEAD_BINDING) buffer Head { uint head[]; };
layout(std430, binding = IZB_NEXT_BINDING) writeonly buffer Next { uint next[]; };
layout(std430, binding = IZB_SAMPLE_BINDING) writeonly buffer Samples { uvec4 samples[]; }; // x's bits, the cell
layout(std430, binding = IZB_BLOCKED_BINDING) writeonly buffer Blocked { uint blocked[]; };
layout(std430, binding = IZB_COUNTER_BINDING) buffer Counters { uint counters[]; };
layout(std430, binding = IZB_OCCUPIED_BINDING) writeonly buffer Occupied { uint occupied[]; };
uniform ivec2 uResolution;
uniform float uRayOffset;

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, uResolution))) return;
    uint s = uint(px.y) * uint(uResolution.x) + uint(px.x);
    blocked[s] = 0u;
    uint cell = IZB_NONE;
    int face = 0;
    ivec2 at = ivec2(0);
    vec4 pos = texelFetch(uPosition, px, 0);
    vec3 n = texelFetch(uNormal, px, 0).xyz;
    vec3 x = watertightOrigin(pos.xyz, n, uRayOffset);
    if (pos.w >= 0.5 && lightReaches(pos.xyz, n)) {
        if (lightIsDirectional()) {
            at = izbCellOf(0, izbOrtho(x));
            cell = izbCellIndex(0, at);
        } else {
            vec3 w = x - uLightPosition;
            if (dot(w, w) > 0.0) {
                face = izbFace(w);
                vec3 f = izbOnFace(w, face);
                at = izbCellOf(face, f.xy / f.z);
                cell = izbCellIndex(face, at);
            } else {
                cell = IZB_ON_LIGHT; // on the light: nothing lies between them, never blocked
            }
        }
    }
    samples[s] = uvec4(floatBitsToUint(storedFloat(x)), cell); // the cell an integer, never float bits
    if (cell >= IZB_ON_LIGHT) return;
    next[s] = atomicExchange(head[cell], s);
    int tilesPerSide = (uGrid + IZB_TILE - 1) / IZB_TILE;
    ivec2 tile = at / IZB_TILE;
    occupied[uint(face) * uint(tilesPerSide * tilesPerSide) + uint(tile.y * tilesPerSide + tile.x)] = 1u;
    atomicAdd(counters[IZB_C_SAMPLES], 1u);
}
