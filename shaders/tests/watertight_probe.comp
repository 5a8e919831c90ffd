#version 450
// Tests only (tests/WatertightGLTest.cpp): each invocation shoots one ray through
// common/watertight.glsl against every triangle and writes the mask of the triangles it hits.
layout(local_size_x = 1) in;
#include "common/watertight.glsl"

layout(std430, binding = 0) readonly buffer Triangles { vec4 vertices[]; }; // 3 per triangle
layout(std430, binding = 1) readonly buffer Rays { vec4 rays[]; };          // (o, tfar), (d, 0)
layout(std430, binding = 2) writeonly buffer Hits { uint hits[]; };
uniform uint uTriangles; // at most 32

void main() {
    uint r = gl_GlobalInvocationID.x;
    WatertightRay ray = watertightRay(rays[2u * r].xyz, rays[2u * r + 1u].xyz, rays[2u * r].w);
    uint mask = 0u;
    for (uint t = 0u; t < uTriangles; ++t)
        if (watertightHit(ray, vertices[3u * t].xyz, vertices[3u * t + 1u].xyz, vertices[3u * t + 2u].xyz))
            mask |= 1u << t;
    hits[r] = mask;
}
