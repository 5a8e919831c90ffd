#version 450
// Tests only (tests/WatertightGLTest.cpp): for each (ray, triangle) pair, whether the watertight
// test hits the triangle (bit 0) and whether the slab test meets the triangle's bounding box
// (bit 1). A hit outside the box test would be a triangle the BVH walk never reaches.
layout(local_size_x = 64) in;
#include "common/watertight.glsl"
#include "common/slab.glsl"

layout(std430, binding = 0) readonly buffer Triangles { vec4 vertices[]; }; // 3 per pair
layout(std430, binding = 1) readonly buffer Rays { vec4 rays[]; };          // (o, tfar), (d, 0) per pair
layout(std430, binding = 2) writeonly buffer Hits { uint hits[]; };
uniform uint uPairs;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uPairs) return;
    vec3 o = rays[2u * i].xyz, d = rays[2u * i + 1u].xyz;
    float tfar = rays[2u * i].w;
    vec3 v0 = vertices[3u * i].xyz, v1 = vertices[3u * i + 1u].xyz, v2 = vertices[3u * i + 2u].xyz;
    bool triangle = watertightHit(watertightRay(o, d, tfar), v0, v1, v2);
    float tnear;
    bool box = slabHit(min(v0, min(v1, v2)), max(v0, max(v1, v2)), o, slabInverse(d), tfar, tnear);
    hits[i] = (triangle ? 1u : 0u) | (box ? 2u : 0u);
}
