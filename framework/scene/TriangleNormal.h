#pragma once
// The one rule by which the scene decides a triangle's normal and whether it has an area.
#include <glm/glm.hpp>

#include <cmath>

namespace shadowlab {

/// The unit normal of triangle (a, b, c) by its winding, or false when it has none in float: its
/// cross product's length is 0 (no area, or so little that its square underflows) or not finite
/// (edges past about 1e9 units, whose cross product's square overflows). The shaders normalise the
/// same cross products in float, so a triangle kept here is one they can take too; an object that
/// loses triangles to this rule is refused where it is placed (SceneConfig.cpp, checkBuilt).
inline bool unitNormal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, glm::vec3& normal) {
    const glm::vec3 n = glm::cross(b - a, c - a);
    const float len = glm::length(n);
    if (!(len > 0.0f) || !std::isfinite(len)) return false;
    normal = n / len;
    return true;
}

} // namespace shadowlab
