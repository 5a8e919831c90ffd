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

// Unit vector from p towards the light.
vec3 toLight(vec3 p) {
    return uLightType == LIGHT_DIRECTIONAL ? -uLightDirection : normalize(uLightPosition - p);
}
