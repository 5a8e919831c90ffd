#pragma once
// The one rule by which the scene decides a triangle's normal and whether it has an area.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

namespace shadowlab {

/// The unit normal of triangle (a, b, c) by its winding, or false when it has no area in float.
/// The cross product is scaled by its largest component before its length is taken: squared, the
/// components of a triangle a few 1e10 units across overflow a float, and such triangles were
/// dropped as if degenerate (sixth probe: a sphere of radius 4e10 lost 64 % of its triangles).
inline bool unitNormal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, glm::vec3& normal) {
    const glm::vec3 n = glm::cross(b - a, c - a);
    const float largest = std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)});
    if (!(largest > 0.0f) || !std::isfinite(largest)) return false;
    const glm::vec3 scaled = n / largest;
    normal = scaled / glm::length(scaled);
    return true;
}

} // namespace shadowlab
