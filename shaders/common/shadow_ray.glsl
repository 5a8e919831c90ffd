// The reference's shadow ray from a query point, for the exact algorithms' last word on a triangle
// whose plane tests are too close to call (psv, ptsv) or for every triangle they test (metric_tree).
// The same ray as EmbreeTracer's and bvh_raytrace's: from o (the G-buffer point already moved
// `offset` along its normal) towards a point light, stopping `offset` short of it, or along a
// directional light without end; tested with the same watertight test, so the decision is the
// reference's own. Include after common/light.glsl.
#include "common/watertight.glsl"

// The ray's direction d and length tfar (for a traversal that builds its own ray from them).
void shadowRaySegment(vec3 o, float offset, out vec3 d, out float tfar) {
    if (lightIsDirectional()) {
        d = -uLightDirection;
        tfar = uintBitsToFloat(0x7F800000u);
        return;
    }
    vec3 v = uLightPosition - o;
    float dist = length(v);
    // The origin on the light: nothing lies between them (tfar 0 hits nothing).
    d = dist > 0.0 ? v / dist : vec3(0.0, 0.0, 1.0);
    tfar = dist > 0.0 ? max(0.0, dist - offset) : 0.0;
}

WatertightRay shadowRayToLight(vec3 o, float offset) {
    vec3 d;
    float tfar;
    shadowRaySegment(o, offset, d, tfar);
    return watertightRay(o, d, tfar);
}

