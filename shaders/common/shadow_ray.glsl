// The reference's shadow ray from a query point, for the exact algorithms' last word on a triangle
// whose plane tests are too close to call (psv, ptsv) or for every triangle they test (metric_tree).
// The same ray as EmbreeTracer's and bvh_raytrace's: from o (the G-buffer point already moved
// `offset` along its normal) towards a point light, stopping `offset` short of it, or along a
// directional light without end; tested with the same watertight test, so the decision is the
// reference's own. Include after common/light.glsl.
#include "common/watertight.glsl"

WatertightRay shadowRayToLight(vec3 o, float offset) {
    if (lightIsDirectional()) return watertightRay(o, -uLightDirection, uintBitsToFloat(0x7F800000u));
    vec3 d = uLightPosition - o;
    float dist = length(d);
    // The origin on the light: nothing lies between them (tfar 0 hits nothing).
    if (!(dist > 0.0)) return watertightRay(o, vec3(0.0, 0.0, 1.0), 0.0);
    return watertightRay(o, d / dist, max(0.0, dist - offset));
}

