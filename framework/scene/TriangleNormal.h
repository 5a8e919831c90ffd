#pragma once
// The one rule by which the scene decides a triangle's normal and whether it has an area.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

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

/// A triangle's longest edge and its height over it, in double.
inline std::pair<double, double> edgeAndHeight(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    return {longest, longest > 0.0 ? glm::length(glm::cross(b - a, c - a)) / longest : 0.0};
}

/// How much the float triangle `f` changes the shape of `exact` (the same triangle in double): the
/// larger relative change of its longest edge and of its height over it. A mesh's triangles are
/// each held to 1 % wherever they are written or placed (docs/scene.md, "mesh").
inline double shapeChange(const glm::vec3* f, const glm::dvec3* exact) {
    const auto [edge, height] = edgeAndHeight(exact[0], exact[1], exact[2]);
    const auto [edgeF, heightF] = edgeAndHeight(glm::dvec3(f[0]), glm::dvec3(f[1]), glm::dvec3(f[2]));
    return std::max(std::abs(edgeF - edge) / edge, std::abs(heightF - height) / height);
}

} // namespace shadowlab
