#pragma once
// The shaders' watertight ray–triangle test (shaders/common/watertight.glsl) in C++, operation for
// operation, so that the reference decides every ray–triangle pair exactly as the GPU algorithms
// do, ties included: a ray grazing a silhouette edge or passing through a vertex goes the same way
// on both sides, on any GPU GLSL 4.50 allows.
//
// Why the shaders' test and not Embree's own: both are watertight (a ray through an edge two
// triangles share hits one of them), but they round differently, and where a ray grazes a
// silhouette one could say hit and the other miss (the exactness campaign found two such pixels in
// about 2,000 scenes: results/reference/exactness_campaign_llvmpipe.md). What makes the two sides
// equal bit for bit: no division and no square root (GLSL allows 2.5 ULP for a division and more
// for a square root; the ray is sheared by multiplying through by the direction's dominant
// component, scaled by a power of two), no fused multiply-add (`precise` in GLSL, -ffp-contract=off
// here), and every subnormal flushed on both sides (framework/core/ExactFloat.h). Which side of an
// exact tie (a float edge value of 0) a ray goes is decided in double from the float coordinates,
// whose products double holds exactly.
#include <glm/glm.hpp>

namespace shadowlab::watertight {

/// A ray prepared for the test: the origin, the direction permuted so that its dominant axis is
/// the third and scaled by a power of two (|d.z| in [0.5, 1)), and tfar scaled alike. Hits count
/// on t in (0, tfar] along the direction as given.
struct Ray {
    glm::vec3 o{0.0f};
    glm::vec3 d{0.0f};
    float tfar = 0.0f;
    int kz = 2;
};

Ray makeRay(glm::vec3 o, glm::vec3 d, float tfar);

/// Whether the ray hits triangle (v0, v1, v2) at some t in (0, tfar]. `t`, when given and hit,
/// receives the hit's distance in units of the scaled direction (for ordering the hits of one ray,
/// not for deciding anything).
bool hit(const Ray& r, glm::vec3 v0, glm::vec3 v1, glm::vec3 v2, float* t = nullptr);

/// A shadow ray's direction and end, as the shaders' shadowRayTo() (common/shadow_ray.glsl) sets
/// them up towards light sample s: to a point or spot light the whole segment o + t (s - o), t in
/// (0, 1] (no square root or division that a GPU could round otherwise; validate keeps every
/// surface 1.25 ray offsets from such a light); to a sample of an area light, unit direction and
/// `offset` short of it (an area light may sit on a surface). A zero d: o is on the sample.
struct Segment {
    glm::vec3 d;
    float tfar;
};
Segment towardsSample(glm::vec3 o, glm::vec3 s, float offset, bool areaLight);

/// The reference's ray origin p + n * offset, rounded as the shaders' watertightOrigin() rounds it.
glm::vec3 origin(glm::vec3 p, glm::vec3 n, float offset);

} // namespace shadowlab::watertight
