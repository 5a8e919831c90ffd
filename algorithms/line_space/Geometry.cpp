#include "algorithms/line_space/Geometry.h"

#include <algorithm>
#include <cmath>

namespace shadowlab::ls {
namespace {

// Projection of the triangle (v0, v1, v2) and of the box (half-size h, centred on the origin) on
// `axis` do not overlap.
bool separated(glm::dvec3 axis, glm::dvec3 v0, glm::dvec3 v1, glm::dvec3 v2, glm::dvec3 h) {
    double p0 = glm::dot(axis, v0), p1 = glm::dot(axis, v1), p2 = glm::dot(axis, v2);
    double r = h.x * std::abs(axis.x) + h.y * std::abs(axis.y) + h.z * std::abs(axis.z);
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

} // namespace

bool triangleOverlapsBox(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, const DBox& box) {
    const glm::dvec3 centre = 0.5 * (box.lo + box.hi), h = 0.5 * (box.hi - box.lo);
    const glm::dvec3 v0 = a - centre, v1 = b - centre, v2 = c - centre;
    // 1. The box's face normals: the triangle's bounding box against the box.
    for (int k = 0; k < 3; ++k)
        if (std::min({v0[k], v1[k], v2[k]}) > h[k] || std::max({v0[k], v1[k], v2[k]}) < -h[k]) return false;
    // 2. The triangle's normal.
    const glm::dvec3 e0 = v1 - v0, e1 = v2 - v1, e2 = v0 - v2;
    const glm::dvec3 n = glm::cross(e0, -e2);
    if (separated(n, v0, v1, v2, h)) return false;
    // 3. The nine cross products of the box's axes with the triangle's edges.
    const glm::dvec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const glm::dvec3& e : {e0, e1, e2})
        for (const glm::dvec3& u : axes)
            if (separated(glm::cross(u, e), v0, v1, v2, h)) return false;
    return true;
}

} // namespace shadowlab::ls
