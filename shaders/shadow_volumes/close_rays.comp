#version 450
// shadow_volumes: the close calls decided by the reference's own ray (common/shadow_ray.glsl, the
// watertight test) traced through the scene's BVH (framework/accel, common/bvh_traverse.glsl): one
// invocation per listed pixel (common/pixel_list.glsl).
// The walk is bounded by the tree (uBvhStepCap); one that overflows its stack or reaches its cap
// (or that a driver's loop limit ends) is counted and its pixel written shadowed, never lit by
// mistake. Through the tree each ray costs O(log triangles), so a frame's close calls stay far
// from a watchdog however many triangles the scene has.
#include "common/statistics.glsl"
#include "common/light.glsl"
#include "common/shadow_ray.glsl"
#include "common/counters.glsl"
#include "shadow_volumes/layout.glsl"
#define BVH_TRAVERSE_NODE_UNIT SV_BVH_NODE_UNIT
#define BVH_TRAVERSE_TRI_UNIT SV_BVH_TRI_UNIT
#include "common/bvh_traverse.glsl"
#define PIXEL_LIST_BINDING SV_CLOSE_LIST_BINDING
#include "common/pixel_list.glsl"
layout(local_size_x = PIXEL_LIST_GROUP) in;
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
layout(std430, binding = SV_COUNTER_BINDING) buffer Counters { uint counters[]; };
uniform float uRayOffset;

#if SHADOWLAB_STATISTICS
void addWide(int lo, uint value) COUNTER_ADD_WIDE(counters, lo, value)
#endif

void main() {
    ivec2 px;
    if (!pixelListEntry(px)) return;
    vec3 p = texelFetch(uPosition, px, 0).xyz, n = texelFetch(uNormal, px, 0).xyz;
    vec3 o = watertightOrigin(p, n, uRayOffset), d;
    float tfar;
    shadowRaySegment(o, uRayOffset, d, tfar);
    BvhTrace t = bvhTrace(bvhMakeRay(o, d, tfar));
    if (t.overflow) atomicAdd(counters[SV_C_STACK_OVERFLOW], 1u);
    if (t.capped) atomicAdd(counters[SV_C_CUT_LOOPS], 1u);
#if SHADOWLAB_STATISTICS
    addWide(SV_C_CLOSE_TESTS_LO, t.tested);
#endif
    imageStore(uVisibility, px, vec4(t.occluded || t.overflow || t.capped ? 0.0 : 1.0));
}
