#version 450
// Reports the driver's subgroup width as a ballot sees it: never assume it (llvmpipe 8, NVIDIA
// 32, AMD 64 or 32). gl_SubGroupSizeARB is only the largest size a subgroup may have, and a driver
// may choose the width per shader: this shader uses a ballot, as the shaders that depend on the
// width do, and each of those checks its own width again.
#extension GL_ARB_shader_ballot : require
#extension GL_ARB_gpu_shader_int64 : require
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Out { uint maxSubgroupSize; uint widest; uint narrowest; };
void main() {
    uvec2 b = unpackUint2x32(ballotARB(true)); // at entry: every invocation of the subgroup
    uint lanes = uint(bitCount(b.x) + bitCount(b.y));
    atomicMax(widest, lanes);
    atomicMin(narrowest, lanes);
    if (gl_LocalInvocationIndex == 0u) maxSubgroupSize = gl_SubGroupSizeARB;
}
