#pragma once
// Light state for one frame, and the area-light sample pattern shared by every soft-shadow
// algorithm and the reference (so both can be compared sample for sample).
#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace shadowlab {

enum class LightType { Point, Spot, Directional, Area };

const char* toString(LightType t);

struct Light {
    LightType type = LightType::Point;
    glm::vec3 position{0, 5, 0};  ///< world units (for directional: a point the light comes from, see direction())
    glm::vec3 target{0, 0, 0};    ///< spot/area: where it faces; directional: light travels position → target
    float coneDeg = 45.0f;        ///< spot: half-angle of the cone, degrees
    glm::vec2 size{1, 1};         ///< area: rectangle width, height in world units
    int samples = 16;             ///< area: number of sample points on the rectangle
    std::string pattern = "stratified"; ///< area: sample pattern (stratified | grid | random)
    uint32_t seed = 1;            ///< area: seed of the jittered patterns

    bool operator==(const Light&) const = default;

    /// Unit direction in which the light travels (position → target).
    glm::vec3 direction() const { return glm::normalize(target - position); }
    /// Orthonormal frame of the area light: (u along width, v along height, n facing target).
    void areaFrame(glm::vec3& u, glm::vec3& v, glm::vec3& n) const;
    /// World-space sample points of the area light (one point, the position, for other types).
    std::vector<glm::vec3> samplePoints() const;
    /// Unit direction from surface point p towards the light (for N·L), ignoring occlusion.
    glm::vec3 toLight(glm::vec3 p) const;
    /// Whether p receives direct light at all before occlusion: inside a spot cone, in front of an
    /// area light (as lightIlluminates() in shaders/common/light.glsl decides it, see reaches()).
    bool illuminates(glm::vec3 p) const;
    /// Whether a surface point p of normal n (not normalised) receives direct light before
    /// occlusion: illuminates(p) and n facing the light. The decision every exact algorithm and the
    /// reference share: the same float operations as lightReaches() in shaders/common/light.glsl,
    /// each rounded as IEEE single with subnormal results flushed to zero, so that GPU and CPU
    /// decide alike even where the answer is a tie (grazing light, the cone's surface).
    bool reaches(glm::vec3 p, glm::vec3 n) const;
    /// cos² of the spot's half-angle as the shaders get it (uLightCosConeSq).
    float cosConeSquared() const;
};

/// Sample offsets in [-0.5, 0.5]^2 on the unit rectangle; deterministic for (pattern, count, seed).
std::vector<glm::vec2> areaSamplePattern(const std::string& pattern, int count, uint32_t seed);

} // namespace shadowlab
