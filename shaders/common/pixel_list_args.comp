#version 450
// The grid of a pixel list's second pass for glDispatchComputeIndirect (framework/algorithm/
// PixelList.h): PIXEL_LIST_GROUP listed pixels a workgroup, in rows of PIXEL_LIST_ROW workgroups.
#include "common/pixel_list.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = PIXEL_LIST_ARGS_BINDING) writeonly buffer PixelListArgs { uint groupsX, groupsY, groupsZ; };
void main() {
    uint listed = min(pixelListCount, uint(pixelListEntries.length()));
    uint groups = (listed + uint(PIXEL_LIST_GROUP) - 1u) / uint(PIXEL_LIST_GROUP);
    groupsX = min(groups, uint(PIXEL_LIST_ROW));
    groupsY = (groups + uint(PIXEL_LIST_ROW) - 1u) / uint(PIXEL_LIST_ROW);
    groupsZ = 1u;
}
