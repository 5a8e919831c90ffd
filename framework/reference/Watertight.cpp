// Compiled with -ffp-contract=off (CMakeLists.txt): every line repeats shaders/common/watertight.glsl.
#include "framework/reference/Watertight.h"

#include "framework/core/ExactFloat.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace shadowlab::watertight {

namespace {

/// (v[kx], v[ky], v[kz]) with kx = (kz + 1) % 3, ky = (kx + 1) % 3: watertightPermute().
glm::vec3 permute(glm::vec3 v, int kz) {
    if (kz == 0) return {v.y, v.z, v.x};
    if (kz == 1) return {v.z, v.x, v.y};
    return v;
}

/// a.x * b.y - a.y * b.x with the endpoints in one canonical order: watertightEdge().
float edge(glm::vec2 a, glm::vec2 b) {
    const bool swapped = a.x > b.x || (a.x == b.x && a.y > b.y);
    const glm::vec2 p = swapped ? b : a, q = swapped ? a : b;
    const float e = exact::sub(exact::mul(p.x, q.y), exact::mul(p.y, q.x));
    return swapped ? -e : e;
}

/// The same edge value decided in double (exact products of floats, one rounding).
float edgeInDouble(glm::vec2 a, glm::vec2 b) {
    return exact::flushed(float(double(a.x) * double(b.y) - double(a.y) * double(b.x)));
}

/// A vertex relative to the origin, permuted, projected along the ray onto the plane z = 0 and
/// scaled by d.z: (A.x * d.z - d.x * A.z, A.y * d.z - d.y * A.z), and A.z.
glm::vec3 project(const Ray& r, glm::vec3 v) {
    const glm::vec3 a = permute(exact::sub(v, r.o), r.kz);
    return {exact::sub(exact::mul(a.x, r.d.z), exact::mul(r.d.x, a.z)), exact::sub(exact::mul(a.y, r.d.z), exact::mul(r.d.y, a.z)),
            a.z};
}

} // namespace

Ray makeRay(glm::vec3 o, glm::vec3 d, float tfar) {
    Ray r;
    r.o = exact::flushed(o);
    const glm::vec3 a = glm::abs(d);
    r.kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    glm::vec3 pd = permute(exact::flushed(d), r.kz);
    int e = 0;
    std::frexp(pd.z, &e); // pd.z = m * 2^e, |m| in [0.5, 1) (0 for a zero direction)
    r.d = glm::vec3(exact::flushed(std::ldexp(pd.x, -e)), exact::flushed(std::ldexp(pd.y, -e)), std::ldexp(pd.z, -e));
    r.tfar = tfar <= std::numeric_limits<float>::max() ? std::ldexp(tfar, e) : tfar; // as the shader: +inf kept
    return r;
}

bool hit(const Ray& r, glm::vec3 v0, glm::vec3 v1, glm::vec3 v2, float* t) {
    const glm::vec3 A = project(r, v0), B = project(r, v1), C = project(r, v2);
    const glm::vec2 a(A), b(B), c(C);
    float U = edge(c, b), V = edge(a, c), W = edge(b, a);
    if (U == 0.0f || V == 0.0f || W == 0.0f) { // on an edge in float: decide it in double
        U = edgeInDouble(c, b);
        V = edgeInDouble(a, c);
        W = edgeInDouble(b, a);
    }
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
    const float det = exact::add(exact::add(U, V), W);
    const float D = exact::mul(det, r.d.z); // t = T / D
    if (D == 0.0f) return false;
    const float T = exact::add(exact::add(exact::mul(U, A.z), exact::mul(V, B.z)), exact::mul(W, C.z));
    const float end = exact::mul(r.tfar, D);
    const bool inside = D > 0.0f ? (T > 0.0f && T <= end) : (T < 0.0f && T >= end);
    if (inside && t) *t = float(double(T) / double(D));
    return inside;
}

Segment towardsSample(glm::vec3 o, glm::vec3 s, float offset, bool areaLight) {
    const glm::vec3 d = exact::sub(s, o);
    if (!areaLight) return {d, 1.0f};
    const float dist = glm::length(d);
    return {dist > 0.0f ? d / dist : glm::vec3(0.0f), std::max(0.0f, dist - offset)};
}

glm::vec3 origin(glm::vec3 p, glm::vec3 n, float offset) {
    return {exact::add(p.x, exact::mul(n.x, offset)), exact::add(p.y, exact::mul(n.y, offset)),
            exact::add(p.z, exact::mul(n.z, offset))};
}

} // namespace shadowlab::watertight
