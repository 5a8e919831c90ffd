#version 450
// izb, pass 4: visibility per pixel: 0 for a blocked sample, 1 for the others; a sample whose cell
// or tile lost work (capped walk, job list full), or every sample after a loop was ended early, is
// written shadowed and counted as overflow, never lit by mistake.
#include "common/statistics.glsl"
#include "izb/layout.glsl"
#include "izb/grid.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D uPosition;
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
#if SHADOWLAB_STATISTICS
layout(r32f, binding = 1) writeonly uniform image2D uListView; // debug: the sample's cell's list length
#endif
layout(std430, binding = IZB_HEAD_BINDING) readonly buffer Head { uint head[]; };
layout(std430, binding = IZB_NEXT_BINDING) readonly buffer Next { uint next[]; };
layout(std430, binding = IZB_SAMPLE_BINDING) readonly buffer Samples { uvec4 samples[]; }; // x's bits, the cell
layout(std430, binding = IZB_BLOCKED_BINDING) readonly buffer Blocked { uint blocked[]; };
layout(std430, binding = IZB_FLAG_BINDING) readonly buffer TileFlags { uint tileFlags[]; };
layout(std430, binding = IZB_CELL_FLAG_BINDING) readonly buffer CellFlags { uint cellFlags[]; };
layout(std430, binding = IZB_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform ivec2 uResolution;

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, uResolution))) return;
    uint s = uint(px.y) * uint(uResolution.x) + uint(px.x);
    vec4 pos = texelFetch(uPosition, px, 0);
    uint cell = samples[s].w;
    float visibility = 1.0; // background, or a point on the light
    if (pos.w >= 0.5) visibility = 0.0; // unless listed and unblocked: not reached by the light
    float listed = 0.0;
    if (pos.w >= 0.5 && cell < IZB_ON_LIGHT) {
        uint cellsPerFace = uint(uGrid) * uint(uGrid);
        uint face = cell / cellsPerFace, inFace = cell % cellsPerFace;
        int tilesPerSide = (uGrid + IZB_TILE - 1) / IZB_TILE;
        uint tile = (inFace / uint(uGrid)) / uint(IZB_TILE) * uint(tilesPerSide) + (inFace % uint(uGrid)) / uint(IZB_TILE);
        bool lost = cellFlags[cell] != 0u || tileFlags[face * uint(tilesPerSide * tilesPerSide) + tile] != 0u ||
                    counters[IZB_C_CUT_LOOPS] != 0u;
        if (lost) atomicAdd(counters[IZB_C_OVERFLOW_PIXELS], 1u);
        visibility = lost || blocked[s] != 0u ? 0.0 : 1.0;
#if SHADOWLAB_STATISTICS
        uint n = 0u;
        for (uint k = head[cell]; k != IZB_NONE && n < 4096u; k = next[k]) ++n;
        listed = float(n);
#endif
    } else if (cell == IZB_ON_LIGHT) {
        visibility = 1.0; // lit, and on the light itself: nothing lies between them
    }
    imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_STATISTICS
    imageStore(uListView, px, vec4(listed));
#endif
}
