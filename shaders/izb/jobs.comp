#version 450
// izb, pass 2: one invocation per (triangle, face) lists the 8 × 8 tiles of cells its footprint
// covers, and that hold a sample, as jobs for the test pass. A job that does not fit the list (job_capacity) is lost: its
// tile is flagged, and every sample in it is written shadowed and counted (never lit by mistake).
// The loops run over at most (grid / 8)^2 tiles; one ended early is counted (rule 13) and then every
// lit sample is written shadowed, since the tiles it left are not known.
#include "common/light.glsl"
#include "common/scene.glsl"
#include "izb/layout.glsl"
#include "izb/grid.glsl"
#include "izb/footprint.glsl"
#include "common/list_push.glsl"
layout(local_size_x = 64) in;
uniform uint uInvocationsPerRow;
layout(std430, binding = IZB_JOB_BINDING) writeonly buffer Jobs { uvec2 jobs[]; };
layout(std430, binding = IZB_JOB_COUNT_BINDING) buffer JobCount { uint jobCount, groupsX, groupsY, groupsZ; };
layout(std430, binding = IZB_FLAG_BINDING) buffer TileFlags { uint tileFlags[]; };
layout(std430, binding = IZB_COUNTER_BINDING) buffer Counters { uint counters[]; };
layout(std430, binding = IZB_OCCUPIED_BINDING) readonly buffer Occupied { uint occupied[]; };
uniform uint uTriangleCount;
uniform int uFaces;         // 6 (point, spot) or 1 (directional)
uniform uint uJobCapacity;

void main() {
    uint id = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x; // rows: ShaderProgram::dispatchLinear
    if (id >= uTriangleCount * uint(uFaces)) return;
    uint t = id / uint(uFaces);
    int face = int(id % uint(uFaces));
    Footprint fp;
    if (!izbFootprint(sceneVertex(t, 0u), sceneVertex(t, 1u), sceneVertex(t, 2u), face, fp)) return;
    // Every sample of the face lies in its grid's box: a footprint wholly outside it covers none.
    vec4 box = izbFaceBox(face);
    if (any(greaterThan(fp.lo, box.zw)) || any(lessThan(fp.hi, box.xy))) return;
    ivec2 c0 = izbCellOf(face, fp.lo), c1 = izbCellOf(face, fp.hi);
    ivec2 t0 = c0 / IZB_TILE, t1 = c1 / IZB_TILE;
    int tilesPerSide = (uGrid + IZB_TILE - 1) / IZB_TILE;
    int ty = t0.y, tx = t0.x;
    for (ty = t0.y; ty <= t1.y; ++ty) {
        for (tx = t0.x; tx <= t1.x; ++tx) {
            uint tile = uint(ty * tilesPerSide + tx);
            if (occupied[uint(face) * uint(tilesPerSide * tilesPerSide) + tile] == 0u) continue; // no sample there
            uint slot;
            LIST_RESERVE(jobCount, 1u, uJobCapacity, slot);
            if (slot < uJobCapacity) jobs[slot] = uvec2(t, uint(face) << 24 | tile);
            else {
                tileFlags[uint(face) * uint(tilesPerSide * tilesPerSide) + tile] = 1u;
                atomicAdd(counters[IZB_C_LOST_TILES], 1u);
            }
        }
        if (tx <= t1.x) break; // the inner loop was ended early
    }
    if (ty <= t1.y) atomicAdd(counters[IZB_C_CUT_LOOPS], 1u);
}
