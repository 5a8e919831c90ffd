// The pixel an invocation of an 8 × 8 work group shades, in 4 × 2 blocks of consecutive
// invocations instead of rows of 8.
ivec2 pixelOfInvocation() {
    uint i = gl_LocalInvocationIndex;
    uvec2 inBlock = uvec2(i & 3u, (i >> 2) & 1u);
    uint block = i >> 3;                       // 0..7: 2 across, 4 down
    uvec2 blockAt = uvec2((block & 1u) * 4u, (block >> 1) * 2u);
    return ivec2(gl_WorkGroupID.xy * 8u + blockAt + inBlock);
}
