// Where along the view ray (eye + v t, v a unit vector) the line a + d s passes closest to it:
// false when the two run parallel (no such place; the caller makes the pixel a close call), with
// a flag rather than a NaN t: GLSL need not keep NaNs (4.50, section 4.7.1), and a compiler may fold
// the `t == t` that would test one to true (architecture.md, rule 5).
bool svClosestAlong(vec3 eye, vec3 a, vec3 d, vec3 v, out float t) {
    vec3 w = eye - a;
    float bd = dot(v, d), dd = dot(d, d), denom = dd - bd * bd;
    t = 0.0;
    // dd - bd * bd cancels for parallel lines, to its rounding error (a few ulps of dd, ~1e-7 dd),
    // not to 0: below 1e-5 dd (an angle under ~3e-3 rad) the lines are taken as parallel, which only
    // ever adds a close call.
    if (!(denom > 1e-5 * dd)) return false;
    t = (bd * dot(d, w) - dd * dot(v, w)) / denom;
    return true;
}
