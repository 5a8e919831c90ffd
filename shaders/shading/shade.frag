#version 450
// Deferred shading shared by every algorithm: albedo × (ambient + direct × N·L × visibility).
#include "common/light.glsl"
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(binding = 2) uniform sampler2D uAlbedo;
layout(binding = 3) uniform sampler2D uVisibility;
uniform float uAmbient;
uniform vec3 uBackground;
out vec4 oColor;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(uPosition, px, 0);
    if (pos.w < 0.5) { oColor = vec4(uBackground, 1.0); return; }
    vec3 n = texelFetch(uNormal, px, 0).xyz;
    vec3 albedo = texelFetch(uAlbedo, px, 0).rgb;
    float vis = texelFetch(uVisibility, px, 0).r;
    vec3 l = toLight(pos.xyz);
    float ndotl = max(dot(n, l), 0.0);
    if (uLightType == LIGHT_SPOT) ndotl *= smoothstep(uLightCosCone, uLightCosCone + 0.02, dot(-l, uLightDirection));
    if (uLightType == LIGHT_AREA && dot(pos.xyz - uLightPosition, uLightDirection) <= 0.0) ndotl = 0.0;
    vec3 c = albedo * (uAmbient + (1.0 - uAmbient) * ndotl * vis);
    oColor = vec4(pow(c, vec3(1.0 / 2.2)), 1.0); // display gamma
}
