#version 450
// shadow_volumes: the close-call workgroups' grid for glDispatchComputeIndirect, one workgroup per
// listed pixel, rows of at most SV_CLOSE_ROW groups (every GL allows 65,535 per dimension).
#include "shadow_volumes/layout.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = SV_CLOSE_LIST_BINDING) readonly buffer CloseList { uint closeCount; uint closeList[]; };
layout(std430, binding = SV_CLOSE_ARGS_BINDING) writeonly buffer CloseArgs { uint groupsX, groupsY, groupsZ; };
void main() {
    uint n = closeCount;
    groupsX = min(n, uint(SV_CLOSE_ROW));
    groupsY = (n + uint(SV_CLOSE_ROW) - 1u) / uint(SV_CLOSE_ROW);
    groupsZ = 1u;
}
