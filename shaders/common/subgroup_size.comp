#version 450
// Reports the driver's subgroup width: never assume it (llvmpipe 8, NVIDIA 32, AMD 64).
#extension GL_ARB_shader_ballot : require
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Out { uint subgroupSize; };
void main() {
    if (gl_LocalInvocationIndex == 0u) subgroupSize = gl_SubGroupSizeARB;
}
