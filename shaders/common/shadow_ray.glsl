// The reference's shadow ray from a query point, for the exact algorithms' last word on a triangle
// whose plane tests are too close to call (psv, ptsv) or for every triangle they test (metric_tree).
// The same ray as EmbreeTracer's and bvh_raytrace's, tested with the same watertight test as the
// reference's (common/watertight.glsl, whose C++ twin the reference runs), so the decision is the
// reference's own, bit for bit. Include after common/light.glsl.
#include "common/watertight.glsl"

// The ray from o towards the light sample s: to a point or spot light, the whole segment o + t (s - o),
// t in (0, 1], with no square root or division that a GPU could round differently from the
// reference (validate keeps every surface 1.25 ray offsets away from such a light, so nothing lies
// at the segment's end: framework/experiment/LightClearance.h); to a sample of an area light (the
// soft algorithms'; it may sit on a surface), unit direction and `offset` short of the sample.
// A zero direction (o on the light) hits nothing.
void shadowRayTo(vec3 o, vec3 s, float offset, out vec3 d, out float tfar) {
    d = exactSub(s, o);
    tfar = 1.0;
    if (uLightType == LIGHT_AREA) {
        float dist = length(d);
        d = dist > 0.0 ? d / dist : vec3(0.0);
        tfar = max(0.0, dist - offset);
    }
}

// The ray's direction d and length tfar towards the light (for a traversal that builds its own ray).
void shadowRaySegment(vec3 o, float offset, out vec3 d, out float tfar) {
    if (lightIsDirectional()) {
        d = -uLightDirection;
        tfar = uintBitsToFloat(0x7F800000u);
        return;
    }
    shadowRayTo(o, uLightPosition, offset, d, tfar);
}

WatertightRay shadowRayToLight(vec3 o, float offset) {
    vec3 d;
    float tfar;
    shadowRaySegment(o, offset, d, tfar);
    return watertightRay(o, d, tfar);
}
