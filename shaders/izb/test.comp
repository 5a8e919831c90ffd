#version 450
// izb, pass 3: one workgroup per job (a triangle and a tile of cells), one invocation per cell: if
// the triangle's projection may touch the cell (conservatively), every sample listed in the cell is
// tested against the triangle with the reference's own ray and watertight test, and marked blocked
// on a hit. The walk stops at walk_cap samples: a longer list is capped, its cell flagged, and its
// samples written shadowed and counted; a walk ended from outside likewise (rule 13).
#include "common/statistics.glsl"
#include "common/light.glsl"
#include "common/scene.glsl"
#include "common/shadow_ray.glsl"
#include "common/counters.glsl"
#include "izb/layout.glsl"
#include "izb/grid.glsl"
#include "izb/footprint.glsl"
layout(local_size_x = IZB_TILE, local_size_y = IZB_TILE) in;
layout(std430, binding = IZB_HEAD_BINDING) readonly buffer Head { uint head[]; };
layout(std430, binding = IZB_NEXT_BINDING) readonly buffer Next { uint next[]; };
layout(std430, binding = IZB_SAMPLE_BINDING) readonly buffer Samples { uvec4 samples[]; }; // x's bits, the cell
layout(std430, binding = IZB_BLOCKED_BINDING) buffer Blocked { uint blocked[]; };
layout(std430, binding = IZB_JOB_BINDING) readonly buffer Jobs { uvec2 jobs[]; };
layout(std430, binding = IZB_JOB_COUNT_BINDING) readonly buffer JobCount { uint jobCount, groupsX, groupsY, groupsZ; };
layout(std430, binding = IZB_CELL_FLAG_BINDING) writeonly buffer CellFlags { uint cellFlags[]; };
layout(std430, binding = IZB_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform float uRayOffset;
uniform uint uWalkCap;
uniform int uCellTest; // 0: every cell of the box (cell_test off)

void addWide(int lo, uint value) COUNTER_ADD_WIDE(counters, lo, value)

void main() {
    uint job = gl_WorkGroupID.y * uint(IZB_ROW) + gl_WorkGroupID.x;
    if (job >= jobCount) return;
    uvec2 j = jobs[job];
    uint t = j.x;
    int face = int(j.y >> 24);
    int tilesPerSide = (uGrid + IZB_TILE - 1) / IZB_TILE;
    int tile = int(j.y & 0xFFFFFFu);
    ivec2 cell = ivec2(tile % tilesPerSide, tile / tilesPerSide) * IZB_TILE + ivec2(gl_LocalInvocationID.xy);
    if (any(greaterThanEqual(cell, ivec2(uGrid)))) return;
    vec3 a = sceneVertex(t, 0u), b = sceneVertex(t, 1u), c = sceneVertex(t, 2u);
    Footprint fp;
    if (!izbFootprint(a, b, c, face, fp)) return;
    vec2 lo, hi;
    izbCellBox(face, cell, lo, hi);
    if (uCellTest != 0 && !izbCellTouches(fp, lo, hi)) return;
    uint index = izbCellIndex(face, cell);
    uint s = head[index], steps = 0u, tests = 0u;
    for (; s != IZB_NONE && steps < uWalkCap; s = next[s]) {
        ++steps;
        if (blocked[s] != 0u) continue;
        ++tests;
        vec3 x = uintBitsToFloat(samples[s].xyz);
        if (watertightHit(shadowRayToLight(x, uRayOffset), a, b, c)) blocked[s] = 1u;
    }
    if (s != IZB_NONE) {
        cellFlags[index] = 1u;
        atomicAdd(counters[steps >= uWalkCap ? IZB_C_CAPPED_CELLS : IZB_C_CUT_LOOPS], 1u);
    }
#if SHADOWLAB_STATISTICS
    addWide(IZB_C_TESTS_LO, tests);
    atomicMax(counters[IZB_C_LIST_MAX], steps);
#endif
}
