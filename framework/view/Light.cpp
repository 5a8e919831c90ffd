#include "framework/view/Light.h"

#include "framework/core/ExactFloat.h"

#include <cmath>
#include <limits>
#include <random>

namespace shadowlab {

const char* toString(LightType t) {
    switch (t) {
    case LightType::Point: return "point";
    case LightType::Spot: return "spot";
    case LightType::Directional: return "directional";
    case LightType::Area: return "area";
    }
    return "?";
}

void Light::areaFrame(glm::vec3& u, glm::vec3& v, glm::vec3& n) const {
    n = direction();
    glm::vec3 ref = std::abs(n.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    u = glm::normalize(glm::cross(ref, n));
    v = glm::cross(n, u);
}

std::vector<glm::vec3> Light::samplePoints() const {
    if (type != LightType::Area) return {position};
    glm::vec3 u, v, n;
    areaFrame(u, v, n);
    std::vector<glm::vec3> out;
    for (glm::vec2 s : areaSamplePattern(pattern, samples, seed)) out.push_back(position + s.x * size.x * u + s.y * size.y * v);
    return out;
}

glm::vec3 Light::toLight(glm::vec3 p) const {
    if (type == LightType::Directional) return -direction();
    return glm::normalize(position - p);
}

float Light::cosConeSquared() const {
    const double c = std::cos(double(coneDeg) * (3.14159265358979323846 / 180.0));
    return float(c * c);
}

bool Light::illuminates(glm::vec3 p) const {
    if (type != LightType::Spot && type != LightType::Area) return true;
    const glm::vec3 d = direction(), fromLight = exact::sub(p, position);
    const float along = exact::dot(fromLight, d);
    if (type == LightType::Area) return along > 0.0f;
    // Inside the cone: cos(angle to the axis) > cos(half-angle), squared (both sides positive).
    return along > 0.0f && exact::mul(along, along) > exact::mul(cosConeSquared(), exact::dot(fromLight, fromLight));
}

bool Light::reaches(glm::vec3 p, glm::vec3 n) const {
    if (type == LightType::Directional) return exact::dot(n, -direction()) > 0.0f;
    return illuminates(p) && exact::dot(n, exact::sub(position, p)) > 0.0f;
}

std::vector<glm::vec2> areaSamplePattern(const std::string& pattern, int count, uint32_t seed) {
    std::vector<glm::vec2> out;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    if (pattern == "random") {
        for (int i = 0; i < count; ++i) out.emplace_back(uni(rng) - 0.5f, uni(rng) - 0.5f);
        return out;
    }
    // grid / stratified: the most square cols×rows with cols·rows ≥ count, cells filled row by row.
    int cols = int(std::ceil(std::sqrt(double(count))));
    int rows = (count + cols - 1) / cols;
    for (int i = 0; i < count; ++i) {
        int cx = i % cols, cy = i / cols;
        float jx = 0.5f, jy = 0.5f;
        if (pattern == "stratified") jx = uni(rng), jy = uni(rng);
        out.emplace_back((cx + jx) / cols - 0.5f, (cy + jy) / rows - 0.5f);
    }
    return out;
}

} // namespace shadowlab
