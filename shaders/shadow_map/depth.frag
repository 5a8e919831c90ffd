#version 450
// Stores linear distance to the light (point/spot) or along the light direction (directional), so
// bias is in world units and the same comparison serves 2D and cube maps.
in vec3 vWorld;
uniform vec3 uLightPosition;
uniform vec3 uLightDirection;
uniform int uDirectional;
layout(location = 0) out float oDistance;
void main() {
    oDistance = uDirectional != 0 ? dot(vWorld - uLightPosition, uLightDirection) : length(vWorld - uLightPosition);
}
