#version 450
// shadow_volumes, the volume pass: every counted fragment of a volume face adds to the stencil (the
// fixed-function ops set by the host: ZFAIL counts the faces behind the test point q, +1 on back
// faces and -1 on front faces; ZPASS those in front of it, the reverse) and, exactly, to the R32F
// count attachment (additive blending of ±1, exact to 2^24), which the resolve pass compares with
// the 8-bit stencil to catch a count that wrapped.
//
// Which fragments count. `depth_test: hardware` (SV_ANALYTIC 0): the depth test against the depth
// pass's buffer, as the papers do. `analytic` (SV_ANALYTIC 1, the default): the same question asked
// in world space, at float precision instead of the depth buffer's: the face crosses the pixel's
// view ray beyond q exactly when the eye and q lie on the same side of its plane (the rasteriser
// only draws the face where the ray, in front of the eye, meets it). The point's own triangle is
// always beyond q (q lies between it and the eye), a far cap at infinity always beyond.
//
// Close calls. A face whose plane passes within the tolerance of the pixel's point p, of q or of
// the reference's ray origin x = p + n * offset (or between them) makes the pixel a close call, which
// the reference's own ray test decides (close_rays.comp). The tolerance is the plane tests' own
// rounding and, with the hardware depth test, the depth buffer's resolution at that depth
// (SV_DEPTH_ULPS steps of the float), far coarser. This shader has side effects (the close-call
// image), so it runs for every fragment rasterised, before any depth test, as the close calls need.
// With the analytic test and ZFAIL (SV_CHECK), the faces before q are summed too (see below).
#include "common/statistics.glsl"
#include "common/counters.glsl"
#include "common/light.glsl"
#include "shadow_volumes/layout.glsl"
#include "shadow_volumes/test_point.glsl"
#include "shadow_volumes/closest_along.glsl"
layout(binding = 0) uniform sampler2D uPosition;
layout(binding = 1) uniform sampler2D uNormal;
layout(binding = SV_TRIANGLE_ID_UNIT) uniform usampler2D uTriangleId;
layout(r32ui, binding = SV_CLOSE_IMAGE) writeonly uniform uimage2D uClose;
#if SV_ANALYTIC && SV_CHECK
layout(r32i, binding = SV_OTHER_IMAGE) uniform iimage2D uOther; // the faces before q, +1 front, -1 back
#endif
#if SHADOWLAB_STATISTICS
layout(std430, binding = SV_COUNTER_BINDING) buffer Counters { uint counters[]; };
#endif
flat in vec4 vPlane;
flat in uint vTriangle;
flat in vec3 vA, vB, vC;
flat in int vKind;
uniform float uRayOffset;
uniform float uCloseCall;  // world units: the plane tests' own rounding
uniform float uCountSign;  // ZFAIL: -1 on front faces; ZPASS: +1
uniform int uCountBehind;  // ZFAIL 1: the faces beyond q count; ZPASS 0: those before it
uniform vec3 uForward;     // the camera's unit view axis
uniform float uDepthScale; // (far - near) / (far * near): world depth per unit of window depth, over z^2
uniform float uPixelAngle; // a pixel's angular size: 2 tan(fov / 2) / height
uniform float uBorderMargin; // pixels: four steps of the rasteriser's subpixel grid (the host reads it)
uniform mat4 uInverseViewProj; // a background pixel's view ray (markNeighbours)
uniform float uCoordinateTolerance; // world units: 16 float steps of the scene's and the eye's largest coordinate
layout(location = 0) out float oCount;

#if SHADOWLAB_STATISTICS
void addWide(int lo, uint value) COUNTER_ADD_WIDE(counters, lo, value)
#endif

const vec4 kNever = vec4(0.0, 0.0, 0.0, 1.0); // a far cap's plane (volume.vert)

// One border line of a face: the point `a` on it and its direction.
struct Border {
    vec3 a, d;
};

// Distance from x to border b, in the plane of unit normal n, signed by the side `inward` points
// to (positive inside), as seen across the view ray v: the in-plane distance times the sine of the
// angle between v and the direction it is measured in.
float inside(vec3 x, Border b, vec3 n, vec3 inward, vec3 v) {
    vec3 m = cross(n, b.d);
    float l = length(m);
    if (!(l > 0.0)) return -1.0;
    m /= l;
    float across = sqrt(max(0.0, 1.0 - dot(m, v) * dot(m, v)));
    return (dot(m, inward) >= 0.0 ? dot(m, x - b.a) : -dot(m, x - b.a)) * across;
}


// The face as rasterised here may not be where the view ray meets its plane: the rasteriser snaps
// vertices to a subpixel grid (GL_SUBPIXEL_BITS: 1/256 of a pixel on llvmpipe and today's GPUs, 1/16
// where GL's minimum) and clips faces one by one, so within that of a face's border the pixel can
// go to the neighbour across it, whose plane the ray meets elsewhere: near the border, about as far
// from it along the ray as X (where it meets this face's plane) is. So where X lies within
// uBorderMargin pixels (as seen from the eye: four steps of that grid) of a border, the pixel is a
// close call if the test point lies in that stretch of the ray around the border. Returns SV_SIDE_*
// and, for SV_SIDE_BORDER, where along the ray X is (tPlane) and the border passes closest (tBorder).
int borderSide(vec3 v, float se, out float tPlane, out float tBorder) {
    tBorder = tPlane = 0.0;
    float cosine = dot(vPlane.xyz, v);
    if (abs(cosine) < 1e-6) return SV_SIDE_CLOSE; // the face seen edge-on
    float t = -se / cosine;
    tPlane = t;
    vec3 x = uEye + v * t, n = vPlane.xyz;
    float margin = max(t, 0.0) * uPixelAngle * uBorderMargin + uCloseCall;
    Border b[3];
    vec3 inward[3];
    if (vKind == SV_FACE_NEAR_CAP) {
        b[0] = Border(vA, vB - vA); inward[0] = vC - vA;
        b[1] = Border(vB, vC - vB); inward[1] = vA - vB;
        b[2] = Border(vC, vA - vC); inward[2] = vB - vC;
    } else { // a side quad: beyond the edge from the light, between the light's rays through its ends
        vec3 ra = lightIsDirectional() ? uLightDirection : vA - uLightPosition;
        vec3 rb = lightIsDirectional() ? uLightDirection : vB - uLightPosition;
        b[0] = Border(vA, vB - vA); inward[0] = ra;
        b[1] = Border(vA, ra); inward[1] = vB - vA;
        b[2] = Border(vB, rb); inward[2] = vA - vB;
    }
    int nearest = -1;
    float best = margin;
    for (int k = 0; k < 3; ++k) {
        float d = inside(x, b[k], n, inward[k], v);
        if (d <= best) { best = d; nearest = k; }
    }
    if (nearest < 0) return SV_SIDE_PLANE;
    return svClosestAlong(uEye, b[nearest].a, b[nearest].d, v, tBorder) ? SV_SIDE_BORDER : SV_SIDE_CLOSE;
}

#if SV_CLOSE_CALLS
// How far X, where the view ray (unit v) meets this face's plane, lies inside the face's nearest
// border, in pixels there (0 where it cannot be told: the face edge-on, or behind the eye).
float borderPixels(vec3 v, float se) {
    float cosine = dot(vPlane.xyz, v);
    if (abs(cosine) < 1e-6) return 0.0;
    float t = -se / cosine;
    if (!(t > 0.0)) return 0.0;
    vec3 x = uEye + v * t, n = vPlane.xyz;
    vec3 ra = lightIsDirectional() ? uLightDirection : vA - uLightPosition;
    vec3 rb = lightIsDirectional() ? uLightDirection : vB - uLightPosition;
    float d = vKind == SV_FACE_NEAR_CAP
                  ? min(min(inside(x, Border(vA, vB - vA), n, vC - vA, v), inside(x, Border(vB, vC - vB), n, vA - vB, v)),
                        inside(x, Border(vC, vA - vC), n, vB - vC, v))
                  : min(min(inside(x, Border(vA, vB - vA), n, ra, v), inside(x, Border(vA, ra), n, vB - vA, v)),
                        inside(x, Border(vB, rb), n, vA - vB, v));
    return max(d, 0.0) / (t * uPixelAngle);
}

// The lateral case. A face that passes between a neighbour pixel's test point q and its ray origin
// x (up to ray_offset apart) while its border keeps it off that pixel's centre gives the neighbour
// no fragment: neither its count nor its own tests see the face, though the face may put x in a
// volume that q is not in. So a fragment within 1.5 pixels of its face's border (deeper inside, the
// face covers the neighbours' centres too, and each tests it itself) tests the face's plane against
// its 8 neighbours' q and x, and makes each it passes between (or near) a close call. A face that
// reaches no pixel centre within a pixel of the point is the border pass's (below): its borders'
// fragments test the pixel itself too (`self`).
void markNeighbours(ivec2 px, bool self) {
    ivec2 size = textureSize(uPosition, 0);
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 m = px + ivec2(dx, dy);
            if ((dx == 0 && dy == 0 && !self) || any(lessThan(m, ivec2(0))) || any(greaterThanEqual(m, size))) continue;
            vec4 pm = texelFetch(uPosition, m, 0);
            if (pm.w < 0.5) continue;
            // q and x lie within the ray offset of p (x along the triangle's unit normal, q along the
            // view ray at x's depth): a plane farther from p than that, and the tests' rounding,
            // separates neither from anything (1.01: a unit normal's own rounding, with room).
            if (abs(dot(vPlane.xyz, pm.xyz) + vPlane.w) > 1.01 * uRayOffset + uCloseCall) continue;
            // The neighbour's own triangle: resolve.comp tests it (ownTriangleMayHide).
            if (vTriangle != ~0u && vTriangle + 1u == texelFetch(uTriangleId, m, 0).x) continue;
            vec3 nm = texelFetch(uNormal, m, 0).xyz;
            vec3 qm = svTestPoint(pm.xyz, nm, uRayOffset), xm = pm.xyz + nm * uRayOffset;
            float sq = dot(vPlane.xyz, qm) + vPlane.w, sx = dot(vPlane.xyz, xm) + vPlane.w;
            if (min(abs(sq), abs(sx)) <= uCloseCall || (sq > 0.0) != (sx > 0.0)) imageStore(uClose, m, uvec4(1u));
        }
}
#endif

#if SV_BORDER_PASS
// The border pass (exact variant only): every volume face's borders drawn as lines and its finite
// corners as points, counting nothing. A face thinner on screen than a pixel may reach no pixel
// centre, and so make no fragment of the volume pass anywhere near a point x it separates from q.
// But then the face's border passes within the screen length of the segment [q, x] of the pixel's
// centre (its projection starts at the centre; the resolve pass makes every pixel where that
// length exceeds SV_BORDER_REACH pixels a close call instead), inside the pixel's diamond: a line
// through the diamond makes a fragment there by the diamond-exit rule, one ending inside it (a
// corner) a point does, and GL lets either land at most one pixel off (GL 4.5 section 14.5.1). So
// testing the face's plane against the q and x of the fragment's pixel and its 8 neighbours finds
// every pixel the face separates from its test point.
void main() {
    if (vPlane == kNever) discard;
    markNeighbours(ivec2(gl_FragCoord.xy), true);
    discard;
}
#else
void main() {
#if SHADOWLAB_STATISTICS
    addWide(SV_C_FRAGMENTS_LO, 1u);
#endif
    oCount = gl_FrontFacing ? uCountSign : -uCountSign;
#if SV_ANALYTIC || SV_CLOSE_CALLS
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(uPosition, px, 0);
    bool farCap = vPlane == kNever;
    if (pos.w < 0.5) { // background: the resolve pass writes 1 whatever the count
#if SV_CLOSE_CALLS
        if (!farCap) {
            vec2 ndc = 2.0 * gl_FragCoord.xy / vec2(textureSize(uPosition, 0)) - 1.0;
            vec4 far = uInverseViewProj * vec4(ndc, 1.0, 1.0);
            vec3 v = normalize(far.xyz / far.w - uEye);
            if (borderPixels(v, dot(vPlane.xyz, uEye) + vPlane.w) <= 1.5) markNeighbours(px, false);
        }
#endif
        return;
    }
    bool own = vTriangle != ~0u && vTriangle + 1u == texelFetch(uTriangleId, px, 0).x;
    vec3 p = pos.xyz, n = texelFetch(uNormal, px, 0).xyz;
    vec3 q = svTestPoint(p, n, uRayOffset);
    float sq = dot(vPlane.xyz, q) + vPlane.w;
    float se = dot(vPlane.xyz, uEye) + vPlane.w;
    bool behind = farCap || own || (se > 0.0) == (sq > 0.0);
    bool close = false;
    float tol = uCloseCall;
    vec3 v = normalize(p - uEye);
#if !SV_ANALYTIC
    // The depth test compares depths projected from world coordinates: besides the depth buffer's
    // own steps, the rounding of those coordinates, which the projection magnifies by z / near
    // along the view (far from the origin, many depth steps).
    float z = dot(p - uEye, uForward);
    float slant = max(dot(v, uForward), 1e-3);
    tol = max(max(tol, uCoordinateTolerance * max(1.0, z * uDepthScale) / slant),
              float(SV_DEPTH_ULPS) * exp2(-24.0) * z * z * uDepthScale / slant);
#endif
    if (!farCap && !own) {
        vec3 x = p + n * uRayOffset;
        float sp = dot(vPlane.xyz, p) + vPlane.w, sx = dot(vPlane.xyz, x) + vPlane.w;
        // The eye on the plane: the side test can flip.
        close = min(min(abs(sp), abs(sq)), min(abs(sx), abs(se))) <= tol || sign(sp) != sign(sx) || sign(sq) != sign(sx);
        // The rasteriser's rounding at a face's border, whichever test counts the face.
        float tPlane, tBorder;
        int side = borderSide(v, se, tPlane, tBorder);
        if (side == SV_SIDE_CLOSE) close = true;
        else if (side == SV_SIDE_BORDER) {
            float tq = dot(q - uEye, v);
            float reach = abs(tPlane - tBorder) + uPixelAngle * max(tq, 0.0) + 2.0 * uCloseCall;
            close = close || abs(tq - tBorder) <= reach;
        }
    }
#if SV_CLOSE_CALLS
    if (close) imageStore(uClose, px, uvec4(1u));
    if (!farCap && borderPixels(normalize(p - uEye), se) <= 1.5) markNeighbours(px, false);
#endif
#if SV_ANALYTIC
    if (behind != (uCountBehind != 0)) {
#if SV_CHECK
        // ZFAIL's other side, for the resolve pass's check: over each closed volume the faces
        // beyond q minus those before it is 1 when the volume holds the eye, else 0, so every
        // pixel's two sums differ by the eye's own count. A face the rasteriser dropped or drew
        // twice at this pixel (a crack where clipped faces meet) breaks that.
        imageAtomicAdd(uOther, px, gl_FrontFacing ? 1 : -1);
#endif
        discard;
    }
#endif
#endif
}
#endif
