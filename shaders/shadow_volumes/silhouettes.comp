#version 450
// shadow_volumes, pass 2: the silhouette edges and their multiplicity. Each triangle's volume,
// wound outwards (facing.comp), has one side quad per edge, walking the edge against the
// triangle's walk. Where two volumes share an edge their quads cancel or add: the edge's
// multiplicity is the sum over its triangles of +1 (the triangle walks the edge's direction) or -1,
// times the triangle's facing sign. An edge of multiplicity m != 0 is drawn |m| times, reversed
// when m < 0: on a closed mesh that is the silhouette (m = ±2 with every triangle casting, ±1
// light-facing only); on an open or non-manifold mesh it is whatever the sum of the volumes needs.
// The loop over an edge's sides ends at its count, and the record list holds 3 n quads, which the
// sum of |m| can never exceed (each side adds at most 1): an overflow is counted all the same.
#include "shadow_volumes/layout.glsl"
layout(local_size_x = 64) in;
uniform uint uInvocationsPerRow;
layout(std430, binding = SV_SIDES_BINDING) readonly buffer Sides { uint sides[]; };
layout(std430, binding = SV_FIRST_BINDING) readonly buffer First { uint first[]; };
layout(std430, binding = SV_FACING_BINDING) readonly buffer Facing { int facing[]; };
layout(std430, binding = SV_RECORDS_BINDING) writeonly buffer Records { uint records[]; };
layout(std430, binding = SV_DRAW_BINDING) buffer Draw {
    uint drawCount, drawQuads, drawFirst, drawBaseInstance; // the faces
    uint lineCount, lineQuads, lineFirst, lineBaseInstance; // the border pass's lines and corners
    uint pointCount, pointQuads, pointFirst, pointBaseInstance;
};
layout(std430, binding = SV_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform uint uEdgeCount;
uniform uint uCapacity;

void main() {
    uint e = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x; // rows: ShaderProgram::dispatchLinear
    if (e >= uEdgeCount) return;
    int m = 0;
    for (uint i = first[e]; i < first[e + 1u]; ++i) {
        uint s = sides[i];
        int f = facing[s >> 3];
        m += (s & 1u) != 0u ? -f : f;
    }
    if (m == 0) return;
    uint k = uint(abs(m));
    uint base = atomicAdd(drawQuads, k);
    atomicAdd(lineQuads, k);
    atomicAdd(pointQuads, k);
    atomicAdd(counters[SV_C_SILHOUETTES], 1u);
    atomicAdd(counters[SV_C_QUADS], k);
    if (base + k > uCapacity || base + k < base) {
        atomicAdd(counters[SV_C_RECORD_OVERFLOW], k);
        return;
    }
    uint record = first[e] << 1 | (m < 0 ? 1u : 0u); // the edge by its first side: its vertices
    for (uint j = 0u; j < k; ++j) records[base + j] = record;
}
