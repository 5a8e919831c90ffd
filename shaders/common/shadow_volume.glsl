// The edge planes of a triangle's shadow volume, shared by psv (its frusta) and ptsv (its
// per-triangle volumes). Include after common/light.glsl.

// Lexicographic order of two points: makes an edge's plane independent of which triangle asks.
bool svLexLess(vec3 a, vec3 b) {
    return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.z < b.z);
}

// ---- The plane's normal without the 1/sin φ error -----------------------------------------------
// cross(e, r) for an edge e nearly along the light's ray r through it (thin posts, poles: sin φ
// small, φ the angle between them) is a difference of two nearly equal products, so in floats its
// rounding, u |e| |r| per component, is a share u / sin φ of its length: the plane tilts by that
// angle and misses the edge's own ends by up to u |r| / sin φ, beyond psv's and ptsv's close-call
// margin (tests/ShadowPlaneGLTest.cpp: thin posts under a light). So e, r and the products are carried as
// unevaluated sums of two floats (Knuth's TwoSum, Dekker's TwoProduct with Veltkamp's split): each
// component is then the exact value rounded once, up to ~u^2 |e| |r|, and the plane's error no
// longer depends on φ. These transformations are exact under GLSL's correctly rounded +, -, *
// (4.50, section 4.7.1), which `precise` keeps from being contracted or reassociated.
vec2 svTwoSum(float a, float b) {
    precise float s = a + b;
    precise float bv = s - a;
    precise float e = (a - (s - bv)) + (b - bv);
    return vec2(s, e);
}
vec2 svSplit(float a) {
    precise float c = 4097.0 * a;
    precise float h = c - (c - a);
    precise float l = a - h;
    return vec2(h, l);
}
// a * b + c * d + ... as (p, error) pairs: a.x b.x exactly, plus the cross terms (the a.y b.y term,
// ~u^2 |ab|, is dropped).
vec2 svProduct(vec2 a, vec2 b) {
    precise float p = a.x * b.x;
    vec2 A = svSplit(a.x), B = svSplit(b.x);
    precise float e = ((A.x * B.x - p) + A.x * B.y + A.y * B.x) + A.y * B.y;
    precise float cross = a.x * b.y + a.y * b.x;
    precise float lo = e + cross;
    return vec2(p, lo);
}
// a - b for two such pairs, rounded once.
float svDifference(vec2 a, vec2 b) {
    vec2 s = svTwoSum(a.x, -b.x);
    precise float lo = s.y + (a.y - b.y);
    precise float d = s.x + lo;
    return d;
}
// cross(e, r) for e and r given as (value, error) pairs per axis: each component rounded once.
vec3 svCrossAccurate(vec2 ex, vec2 ey, vec2 ez, vec2 rx, vec2 ry, vec2 rz) {
    return vec3(svDifference(svProduct(ey, rz), svProduct(ez, ry)), svDifference(svProduct(ez, rx), svProduct(ex, rz)),
                svDifference(svProduct(ex, ry), svProduct(ey, rx)));
}

// Plane through the light and edge a→b (a, b in the triangle's winding order). Both triangles that
// share an edge evaluate the same expression on the same (lexicographically ordered) operands, so
// their planes are bit-identical up to an exact negation: no crack along the edge can let light
// through a closed mesh. cross(b - a, a - light) has the triangle on its negative side when the
// light is on the negative side of the winding normal (flip = 1); swapping a and b negates it.
// A null plane (vec4(0)) when the edge points at the light.
vec4 svEdgePlane(vec3 a, vec3 b, float flip) {
    bool swapped = svLexLess(b, a);
    vec3 lo = swapped ? b : a, hi = swapped ? a : b;
    // `precise`: no contraction into fma at one call site and not at another (this is inlined three
    // times, and a shared edge can be (v0, v1) in one triangle and (v2, v0) in the other).
    vec2 ex = svTwoSum(hi.x, -lo.x), ey = svTwoSum(hi.y, -lo.y), ez = svTwoSum(hi.z, -lo.z);
    vec3 l = lightIsDirectional() ? uLightDirection : uLightPosition;
    vec2 rx = lightIsDirectional() ? vec2(l.x, 0.0) : svTwoSum(lo.x, -l.x);
    vec2 ry = lightIsDirectional() ? vec2(l.y, 0.0) : svTwoSum(lo.y, -l.y);
    vec2 rz = lightIsDirectional() ? vec2(l.z, 0.0) : svTwoSum(lo.z, -l.z);
#if SHADOWLAB_FAULT_ROUNDED_CROSS
    // Test fault: the plain float cross product of the rounded vectors (the code before).
    precise vec3 n = cross(vec3(ex.x, ey.x, ez.x), vec3(rx.x, ry.x, rz.x));
#else
    precise vec3 n = svCrossAccurate(ex, ey, ez, rx, ry, rz);
#endif
    precise float len = length(n);
    if (!(len > 0.0)) return vec4(0.0);
    n /= len;
    precise float w = lightIsDirectional() ? -dot(n, lo) : -dot(n, uLightPosition);
    vec4 p = vec4(n, w);
    // Negation is exact, so the two triangles of an edge still hold opposite copies of one plane.
    return (swapped ? -flip : flip) > 0.0 ? p : -p;
}
