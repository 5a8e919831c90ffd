#include "framework/view/Light.h"

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

namespace {

// Exact-decision arithmetic shared with shaders/common/light.glsl: every sum and product rounded
// to float (this file is compiled without contraction) and a subnormal result flushed to zero, as
// a GPU may do on its own (GLSL 4.50 section 4.7.1); flushing on both sides makes that choice moot.
float flushed(float x) { return std::fabs(x) < std::numeric_limits<float>::min() ? 0.0f : x; }
float exactSub(float a, float b) { return flushed(flushed(a) - flushed(b)); }
float exactMul(float a, float b) { return flushed(flushed(a) * flushed(b)); }
float exactDot(glm::vec3 a, glm::vec3 b) {
    return flushed(flushed(exactMul(a.x, b.x) + exactMul(a.y, b.y)) + exactMul(a.z, b.z));
}
glm::vec3 exactSub(glm::vec3 a, glm::vec3 b) { return {exactSub(a.x, b.x), exactSub(a.y, b.y), exactSub(a.z, b.z)}; }

} // namespace

float Light::cosConeSquared() const {
    const double c = std::cos(double(coneDeg) * (3.14159265358979323846 / 180.0));
    return float(c * c);
}

bool Light::illuminates(glm::vec3 p) const {
    if (type != LightType::Spot && type != LightType::Area) return true;
    const glm::vec3 d = direction(), fromLight = exactSub(p, position);
    const float along = exactDot(fromLight, d);
    if (type == LightType::Area) return along > 0.0f;
    // Inside the cone: cos(angle to the axis) > cos(half-angle), squared (both sides positive).
    return along > 0.0f && exactMul(along, along) > exactMul(cosConeSquared(), exactDot(fromLight, fromLight));
}

bool Light::reaches(glm::vec3 p, glm::vec3 n) const {
    if (type == LightType::Directional) return exactDot(n, -direction()) > 0.0f;
    return illuminates(p) && exactDot(n, exactSub(position, p)) > 0.0f;
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
