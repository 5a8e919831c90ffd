#version 450
// Visibility from a shadow map: PCF over (2k+1)² texels with constant + slope-scaled bias.
#include "common/light.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
#if CUBE
layout(binding = 2) uniform samplerCube uMap;
#else
layout(binding = 2) uniform sampler2D uMap;
#endif
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
uniform mat4 uLightViewProj;
uniform vec3 uDirectionalOrigin;
uniform float uBiasConstant; // world units
uniform float uBiasSlope;    // × texel world size × tan(theta)
uniform float uTexelAngle;   // perspective maps: texel size / distance
uniform float uOrthoTexel;   // orthographic map: texel size in world units
uniform int uPcf;
uniform float uMapSize;

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(uVisibility)))) return;
    vec4 pos = texelFetch(uPosition, px, 0);
    if (pos.w < 0.5) { imageStore(uVisibility, px, vec4(1.0)); return; }
    vec3 p = pos.xyz;
    vec3 n = texelFetch(uNormal, px, 0).xyz;
    vec3 l = toLight(p);
    float cosTheta = clamp(dot(n, l), 0.05, 1.0);
    float tanTheta = sqrt(1.0 - cosTheta * cosTheta) / cosTheta;
    bool directional = uLightType == LIGHT_DIRECTIONAL;
    float dist = directional ? dot(p - uDirectionalOrigin, uLightDirection) : length(p - uLightPosition);
    float texelWorld = directional ? uOrthoTexel : uTexelAngle * dist;
    float receiver = dist - uBiasConstant - uBiasSlope * texelWorld * min(tanTheta, 10.0);

    float lit = 0.0;
    int taps = 0;
#if CUBE
    vec3 d = p - uLightPosition;
    vec3 a = abs(d);
    float major = max(a.x, max(a.y, a.z));
    // Tangent axes of the face the direction falls in; one texel is 2/size in face coordinates.
    vec3 t1 = a.x == major ? vec3(0, 1, 0) : vec3(1, 0, 0);
    vec3 t2 = cross(d / major, t1);
    float step = 2.0 / uMapSize * major;
    for (int y = -uPcf; y <= uPcf; ++y)
        for (int x = -uPcf; x <= uPcf; ++x) {
            float stored = texture(uMap, d + (float(x) * t1 + float(y) * t2) * step).r;
            lit += receiver <= stored ? 1.0 : 0.0;
            ++taps;
        }
#else
    vec4 clip = uLightViewProj * vec4(p, 1.0);
    vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
    if (clip.w <= 0.0 || any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        // Outside the map: spot pixels outside the cone get no light from shading anyway.
        imageStore(uVisibility, px, vec4(1.0));
        return;
    }
    ivec2 texel = ivec2(uv * uMapSize);
    ivec2 maxTexel = ivec2(uMapSize) - 1;
    for (int y = -uPcf; y <= uPcf; ++y)
        for (int x = -uPcf; x <= uPcf; ++x) {
            float stored = texelFetch(uMap, clamp(texel + ivec2(x, y), ivec2(0), maxTexel), 0).r;
            lit += receiver <= stored ? 1.0 : 0.0;
            ++taps;
        }
#endif
    imageStore(uVisibility, px, vec4(lit / float(taps)));
}
