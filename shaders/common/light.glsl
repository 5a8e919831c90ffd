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

// The light reaches p at all (GLSL twin of Light::illuminates): inside a spot's cone, in front of
// an area light; point and directional lights reach everywhere.
bool lightIlluminates(vec3 p) {
    if (uLightType == LIGHT_SPOT) return dot(normalize(p - uLightPosition), uLightDirection) > uLightCosCone;
    if (uLightType == LIGHT_AREA) return dot(p - uLightPosition, uLightDirection) > 0.0;
    return true;
}

// Unit vector from p towards the light.
vec3 toLight(vec3 p) {
    return uLightType == LIGHT_DIRECTIONAL ? -uLightDirection : normalize(uLightPosition - p);
}
