#version 450
// shadow_volumes, the resolve pass: one invocation per pixel turns the count into visibility.
// Lit where the light reaches the point and faces it, and the stencil count is 0. The exact R32F
// count decides where the 8-bit stencil wrapped (a multiple of 256 reads 0: counted, never lit by
// mistake). With SV_CHECK (analytic ZFAIL), a pixel whose counts beyond and before the test point
// do not differ by the eye's own count (eye_count.comp) lost or doubled a face: it is decided as a
// close call. A close call (volume.frag) is listed, for the reference's own ray traced through the
// scene's BVH (close_rays.comp), which then writes its visibility (written here as the stencil says,
// until then). The list holds one entry per pixel: it cannot overflow.
#include "common/statistics.glsl"
#include "common/light.glsl"
#include "common/counters.glsl"
#include "common/scene.glsl"
#include "shadow_volumes/layout.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = SV_TRIANGLE_ID_UNIT) uniform usampler2D uTriangleId;
uniform float uRayOffset;
uniform float uCloseCall; // world units: the plane tests' own rounding
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(binding = SV_STENCIL_UNIT) uniform usampler2D uStencil;
layout(binding = SV_COUNT_UNIT) uniform sampler2D uCount;
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
layout(r32ui, binding = SV_CLOSE_IMAGE) readonly uniform uimage2D uClose;
#if SV_CHECK
layout(r32i, binding = SV_OTHER_IMAGE) readonly uniform iimage2D uOther;
#endif
#if SHADOWLAB_STATISTICS
layout(r32f, binding = 1) writeonly uniform image2D uCloseView; // debug: 1 on close calls
layout(r32f, binding = 2) writeonly uniform image2D uCountView; // debug: the exact count
#endif
layout(std430, binding = SV_COUNTER_BINDING) buffer Counters { uint counters[]; };
#define PIXEL_LIST_BINDING SV_CLOSE_LIST_BINDING
#include "common/pixel_list.glsl"

// The pixel's own triangle holds p only up to the G-buffer's rounding, which grows with the
// coordinates' size (far from the origin) and at grazing views. Where that leaves the reference's
// ray origin x = p + n * offset on the far side of the own triangle's plane from the light (or
// within the tolerance of it), the own triangle can hide x from the light, and no count can say
// so: its own volume counts 0 for its own points (volume.frag). Such a pixel is a close call.
#if SV_CLOSE_CALLS
bool ownTriangleMayHide(ivec2 px, vec3 p, vec3 n) {
    uint id = texelFetch(uTriangleId, px, 0).x;
    if (id == 0u) return false;
    vec3 a = sceneVertex(id - 1u, 0u);
    precise float sx = dot(n, p + n * uRayOffset - a);
    precise float sl = lightIsDirectional() ? -dot(n, uLightDirection) : dot(n, uLightPosition - a);
    return abs(sx) <= uCloseCall || (sx > 0.0) != (sl > 0.0);
}

// Whether the segment [q, x] is longer on screen than the border pass reaches (volume.frag,
// SV_BORDER_PASS): a point nearer the eye than a few hundred ray offsets. Its faces could separate
// q and x a pixel or more away from its centre, so the ray decides it.
uniform mat4 uViewProj;
bool beyondBorderReach(vec3 p, vec3 n) {
    vec4 cp = uViewProj * vec4(p, 1.0), cx = uViewProj * vec4(p + n * uRayOffset, 1.0);
    if (!(cp.w > 0.0) || !(cx.w > 0.0)) return true;
    vec2 pixels = 0.5 * vec2(imageSize(uVisibility)) * (cx.xy / cx.w - cp.xy / cp.w);
    return !(length(pixels) <= SV_BORDER_REACH);
}
#endif

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(uVisibility)))) return;
    vec4 pos = texelFetch(uPosition, px, 0);
    float visibility = 1.0; // background
    float closeView = 0.0, countView = 0.0;
    if (pos.w >= 0.5) {
        vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
        visibility = 0.0;
        if (lightReaches(p, n)) {
            uint stencil = texelFetch(uStencil, px, 0).x & 255u;
            int count = int(texelFetch(uCount, px, 0).x);
            countView = float(count);
            bool shadowed = stencil != 0u;
            if ((uint(count) & 255u) != stencil || (stencil == 0u && count != 0)) {
                atomicAdd(counters[SV_C_WRAPPED], 1u);
                shadowed = count != 0;
            }
            bool close = imageLoad(uClose, px).x != 0u;
#if SV_CLOSE_CALLS
            close = close || ownTriangleMayHide(px, p, n) || beyondBorderReach(p, n);
#endif
#if SV_CHECK
            // Every closed volume adds 1 to (beyond - before) if it holds the eye, else 0.
            if (count - imageLoad(uOther, px).x != int(counters[SV_C_EYE])) {
                atomicAdd(counters[SV_C_INCONSISTENT], 1u);
                close = true;
            }
#endif
            if (close) {
                // Listed for close_rays.comp, which writes this pixel's visibility (a full list,
                // which one entry a pixel cannot fill, would leave it shadowed and counted).
                if (!pixelListAppend(px)) { shadowed = true; atomicAdd(counters[SV_C_CUT_LOOPS], 1u); }
                atomicAdd(counters[SV_C_CLOSE_PIXELS], 1u);
                closeView = 1.0;
            }
            visibility = shadowed ? 0.0 : 1.0;
#if SHADOWLAB_STATISTICS
            atomicAdd(counters[SV_C_LIT], 1u);
#endif
        }
    }
    imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_STATISTICS
    imageStore(uCloseView, px, vec4(closeView));
    imageStore(uCountView, px, vec4(countView));
#endif
}
