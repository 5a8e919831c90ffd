// Light uniforms in the form every visibility shader reads them (set by LightUniforms on the host).
#define LIGHT_POINT 0
#define LIGHT_SPOT 1
#define LIGHT_DIRECTIONAL 2
#define LIGHT_AREA 3
uniform int uLightType;
uniform vec3 uLightPosition;  // point, spot, area centre
uniform vec3 uLightDirection; // unit, direction the light travels (spot, directional, area normal)
uniform float uLightCosCone;  // spot: cos(half angle)

bool lightIsDirectional() { return uLightType == LIGHT_DIRECTIONAL; }

uniform float uLightCosConeSq; // spot: cos² of the half-angle (Light::cosConeSquared)

// The decisions below repeat framework/view/Light.cpp's with the same exact-decision arithmetic.
#include "common/exact_float.glsl"

// The light reaches p at all (the twin of Light::illuminates): inside a spot's cone, in front of
// an area light; point and directional lights reach everywhere.
bool lightIlluminates(vec3 p) {
    if (uLightType != LIGHT_SPOT && uLightType != LIGHT_AREA) return true;
    vec3 fromLight = exactSub(p, uLightPosition);
    float along = exactDot(fromLight, uLightDirection);
    if (uLightType == LIGHT_AREA) return along > 0.0;
    // Inside the cone: cos(angle to the axis) > cos(half-angle), squared (both sides positive).
    return along > 0.0 && exactMul(along, along) > exactMul(uLightCosConeSq, exactDot(fromLight, fromLight));
}

// A surface point p of normal n (not normalised) receives direct light before occlusion: the
// decision every exact algorithm shares with the reference (the twin of Light::reaches, operation
// for operation, so that a tie such as grazing light or the cone's surface goes the same way).
bool lightReaches(vec3 p, vec3 n) {
    if (uLightType == LIGHT_DIRECTIONAL) return exactDot(n, -uLightDirection) > 0.0;
    return lightIlluminates(p) && exactDot(n, exactSub(uLightPosition, p)) > 0.0;
}

// Unit vector from p towards the light.
vec3 toLight(vec3 p) {
    return uLightType == LIGHT_DIRECTIONAL ? -uLightDirection : normalize(uLightPosition - p);
}
