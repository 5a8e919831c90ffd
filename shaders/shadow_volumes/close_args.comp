#version 450
// shadow_volumes: the close calls' grid for glDispatchComputeIndirect, SV_CLOSE_GROUP listed pixels
// a workgroup, rows of at most SV_CLOSE_ROW workgroups (every GL allows 65,535 per dimension).
#include "shadow_volumes/layout.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = SV_CLOSE_LIST_BINDING) readonly buffer CloseList { uint closeCount; uint closeList[]; };
layout(std430, binding = SV_CLOSE_ARGS_BINDING) writeonly buffer CloseArgs { uint groupsX, groupsY, groupsZ; };
void main() {
    uint groups = (closeCount + uint(SV_CLOSE_GROUP) - 1u) / uint(SV_CLOSE_GROUP);
    groupsX = min(groups, uint(SV_CLOSE_ROW));
    groupsY = (groups + uint(SV_CLOSE_ROW) - 1u) / uint(SV_CLOSE_ROW);
    groupsZ = 1u;
}
