#version 450
// izb: the test pass's grid for glDispatchComputeIndirect: one workgroup per job, in rows of
// IZB_ROW groups (every GL allows 65,535 per dimension); jobs past the capacity were lost (flagged).
#include "izb/layout.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = IZB_JOB_COUNT_BINDING) buffer JobCount { uint jobCount, groupsX, groupsY, groupsZ; };
layout(std430, binding = IZB_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform uint uJobCapacity;
void main() {
    counters[IZB_C_JOBS] = jobCount + counters[IZB_C_LOST_TILES]; // asked for: listed + lost (a push past capacity is taken back)
    uint n = min(jobCount, uJobCapacity);
    jobCount = n;
    groupsX = min(n, uint(IZB_ROW));
    groupsY = (n + uint(IZB_ROW) - 1u) / uint(IZB_ROW);
    groupsZ = 1u;
}
