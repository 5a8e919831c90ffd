// The edge planes of a triangle's shadow volume, shared by psv (its frusta) and ptsv (its
// per-triangle volumes). Include after common/light.glsl.

// Lexicographic order of two points: makes an edge's plane independent of which triangle asks.
bool svLexLess(vec3 a, vec3 b) {
    return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.z < b.z);
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
    precise vec3 n = lightIsDirectional() ? cross(hi - lo, uLightDirection) : cross(hi - lo, lo - uLightPosition);
    precise float len = length(n);
    if (!(len > 0.0)) return vec4(0.0);
    n /= len;
    precise float w = lightIsDirectional() ? -dot(n, lo) : -dot(n, uLightPosition);
    vec4 p = vec4(n, w);
    // Negation is exact, so the two triangles of an edge still hold opposite copies of one plane.
    return (swapped ? -flip : flip) > 0.0 ? p : -p;
}
