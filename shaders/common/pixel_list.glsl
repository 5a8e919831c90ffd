// A list of pixels one per-pixel pass hands to a second, slower one (framework/algorithm/
// PixelList.h): {count, x | y << 16 per entry}, with room for every pixel once. Define
// PIXEL_LIST_BINDING (its storage block binding) before including.
layout(std430, binding = PIXEL_LIST_BINDING) buffer PixelList { uint pixelListCount; uint pixelListEntries[]; };

#define PIXEL_LIST_GROUP 64    // listed pixels a workgroup of the second pass
#define PIXEL_LIST_ROW 32768   // workgroups a row of its grid (every GL allows 65,535 per dimension)

// Lists px; false when the list is full, which a pass that lists each pixel at most once never
// sees (the caller writes the pixel shadowed and counts it all the same).
#ifndef SHADOWLAB_FAULT_FULL_PIXEL_LIST
#define SHADOWLAB_FAULT_FULL_PIXEL_LIST 0
#endif
bool pixelListAppend(ivec2 px) {
#if SHADOWLAB_FAULT_FULL_PIXEL_LIST
    return false; // test fault (framework/gl/Shader.h): a list with no room left
#endif
    uint entry = atomicAdd(pixelListCount, 1u);
    if (entry >= uint(pixelListEntries.length())) return false;
    pixelListEntries[entry] = uint(px.x) | uint(px.y) << 16;
    return true;
}

// In the second pass (PIXEL_LIST_GROUP invocations a workgroup, dispatched by PixelList): this
// invocation's listed pixel; false past the list's end.
bool pixelListEntry(out ivec2 px) {
    uint group = gl_WorkGroupID.y * uint(PIXEL_LIST_ROW) + gl_WorkGroupID.x;
    uint entry = group * uint(PIXEL_LIST_GROUP) + gl_LocalInvocationIndex;
    px = ivec2(0);
    if (entry >= min(pixelListCount, uint(pixelListEntries.length()))) return false;
    uint word = pixelListEntries[entry];
    px = ivec2(int(word & 0xFFFFu), int(word >> 16));
    return true;
}
