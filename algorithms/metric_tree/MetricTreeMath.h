#pragma once
// Light-space distances of the metric tree on the CPU: a line-for-line mirror of
// shaders/metric_tree/tree.glsl, used by the CPU (median) tree builder and by the tests that check
// the bounds against brute force. Point light: unit directions and angles; directional light:
// points (u, v, 0) in the plane orthogonal to the light and Euclidean distances.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

namespace shadowlab::mt {

constexpr float kPi = 3.14159265358979f;

inline float angle(glm::vec3 u, glm::vec3 v) { return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v)); }

inline bool onArc(glm::vec3 y, glm::vec3 a, glm::vec3 b, glm::vec3 n) {
    return glm::dot(glm::cross(a, y), n) >= 0.0f && glm::dot(glm::cross(y, b), n) >= 0.0f;
}

inline float pointArc(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
    float d = std::min(angle(p, a), angle(p, b));
    glm::vec3 n = glm::cross(a, b);
    const float nl = glm::length(n);
    if (nl > 1e-12f) {
        n /= nl;
        const float s = glm::dot(p, n);
        const glm::vec3 q = p - s * n;
        if (onArc(q, a, b, n)) d = std::min(d, std::atan2(std::abs(s), glm::length(q)));
    }
    return d;
}

inline float arcArc(glm::vec3 a1, glm::vec3 b1, glm::vec3 a2, glm::vec3 b2) {
    float d = std::min(std::min(pointArc(a1, a2, b2), pointArc(b1, a2, b2)), std::min(pointArc(a2, a1, b1), pointArc(b2, a1, b1)));
    const glm::vec3 n1 = glm::cross(a1, b1), n2 = glm::cross(a2, b2);
    glm::vec3 x = glm::cross(n1, n2);
    const float xl = glm::length(x);
    if (xl > 1e-12f && glm::length(n1) > 1e-12f && glm::length(n2) > 1e-12f) {
        x /= xl;
        if ((onArc(x, a1, b1, n1) && onArc(x, a2, b2, n2)) || (onArc(-x, a1, b1, n1) && onArc(-x, a2, b2, n2))) d = 0.0f;
    }
    return d;
}

inline float pointSeg(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
    const glm::vec3 ab = b - a;
    const float l2 = glm::dot(ab, ab);
    const float t = l2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / l2, 0.0f, 1.0f) : 0.0f;
    return glm::length(p - (a + t * ab));
}

inline float cross2(glm::vec2 u, glm::vec2 v) { return u.x * v.y - u.y * v.x; }

inline float segSeg(glm::vec3 a1, glm::vec3 b1, glm::vec3 a2, glm::vec3 b2) {
    const glm::vec2 d1 = glm::vec2(b1) - glm::vec2(a1), d2 = glm::vec2(b2) - glm::vec2(a2);
    const float o1 = cross2(d1, glm::vec2(a2 - a1)), o2 = cross2(d1, glm::vec2(b2 - a1));
    const float o3 = cross2(d2, glm::vec2(a1 - a2)), o4 = cross2(d2, glm::vec2(b1 - a2));
    if (((o1 < 0 && o2 > 0) || (o1 > 0 && o2 < 0)) && ((o3 < 0 && o4 > 0) || (o3 > 0 && o4 < 0))) return 0.0f;
    return std::min(std::min(pointSeg(a1, a2, b2), pointSeg(b1, a2, b2)), std::min(pointSeg(a2, a1, b1), pointSeg(b2, a1, b1)));
}

/// Distance from a light-space point to an element's centre (point a = b, or arc/segment a-b).
inline float pointDist(bool directional, glm::vec3 p, glm::vec3 a, glm::vec3 b) {
    if (a == b) return directional ? glm::length(p - a) : angle(p, a);
    return directional ? pointSeg(p, a, b) : pointArc(p, a, b);
}

/// Smallest distance between two elements' centres.
inline float minDist(bool directional, glm::vec3 a1, glm::vec3 b1, glm::vec3 a2, glm::vec3 b2) {
    if (a1 == b1) return pointDist(directional, a1, a2, b2);
    if (a2 == b2) return pointDist(directional, a2, a1, b1);
    return directional ? segSeg(a1, b1, a2, b2) : arcArc(a1, b1, a2, b2);
}

/// Largest distance between two elements' centres.
inline float maxDist(bool directional, glm::vec3 a1, glm::vec3 b1, glm::vec3 a2, glm::vec3 b2) {
    if (directional)
        return std::max(std::max(glm::length(a1 - a2), glm::length(a1 - b2)), std::max(glm::length(b1 - a2), glm::length(b1 - b2)));
    return kPi - minDist(false, -a1, -b1, a2, b2);
}

} // namespace shadowlab::mt
