#include "framework/view/Light.h"

#include <cmath>
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

bool Light::illuminates(glm::vec3 p) const {
    switch (type) {
    case LightType::Spot: return glm::dot(glm::normalize(p - position), direction()) > std::cos(glm::radians(coneDeg));
    case LightType::Area: return glm::dot(p - position, direction()) > 0.0f;
    default: return true;
    }
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
