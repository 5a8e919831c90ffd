#version 450
// Between the two traversal passes: turns pass one's job count into pass two's indirect dispatch,
// one workgroup per PTSV_JOBS_PER_GROUP jobs, as a 2D grid past 65535 groups (the count never leaves the GPU).
#include "common/light.glsl"
#include "common/scene.glsl"
#include "ptsv/ptsv.glsl"
layout(local_size_x = 1) in;

uniform uint uJobCapacity;

void main() {
    uint count = min(ptsvCounters[PTSV_C_JOBS_PUSHED], uJobCapacity);
#if PTSV_PER_INVOCATION
    const uint perGroup = uint(PTSV_INVOCATION_GROUP); // one job per invocation
#else
    const uint perGroup = uint(PTSV_JOBS_PER_GROUP);   // a batch per workgroup
#endif
    uint groups = (count + perGroup - 1u) / perGroup;
    uint gx = min(groups, 65535u);
    ptsvCounters[PTSV_C_DISPATCH] = gx;
    ptsvCounters[PTSV_C_DISPATCH + 1] = gx == 0u ? 0u : (groups + gx - 1u) / gx;
    ptsvCounters[PTSV_C_DISPATCH + 2] = 1u;
}
