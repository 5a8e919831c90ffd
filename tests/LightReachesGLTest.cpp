// Which pixels the light reaches at all (facing it, inside a spot's cone, in front of an area
// light) is decided on the GPU by every exact algorithm and on the CPU by the reference and the
// metrics. Both used normalize() and a cosine, whose rounding GLSL leaves to the implementation, so
// on a tie (light grazing a surface, a point on the cone's surface) a GPU could call a pixel
// reached that the reference calls unlit: a wrong pixel by construction. Now both sides run the
// same IEEE operations with subnormals flushed (Light::reaches, lightReaches in
// shaders/common/light.glsl), and this test holds them to the same answer on cases built to be
// ties.
#include "framework/gl/GlObjects.h"
#include "framework/gl/Shader.h"
#include "framework/render/LightUniforms.h"
#include "tests/ShadowTestScenes.h"
#include "tests/TestSupport.h"

#include <glm/glm.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace shadowlab {
namespace {

using namespace test;

class LightReachesGLTest : public GLTest {};

struct Cases {
    std::vector<glm::vec4> pn; // p, n per case
    size_t count() const { return pn.size() / 2; }
    void add(glm::vec3 p, glm::vec3 n) { pn.insert(pn.end(), {glm::vec4(p, 0.0f), glm::vec4(n, 0.0f)}); }
};

/// `v` moved by up to `ulps` float steps per component (ties need rounding either way).
glm::vec3 nudged(glm::vec3 v, std::mt19937& rng, int ulps) {
    std::uniform_int_distribution<int> step(-ulps, ulps);
    for (int k = 0; k < 3; ++k)
        for (int s = step(rng); s != 0; s += s > 0 ? -1 : 1) v[k] = std::nextafter(v[k], s > 0 ? INFINITY : -INFINITY);
    return v;
}

glm::dvec3 randomUnit(std::mt19937& rng) {
    std::normal_distribution<double> g;
    return glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
}

/// Normals perpendicular (in double) to the way to the light: grazing light, the facing test a tie.
Cases grazing(const Light& light, std::mt19937& rng, int count) {
    Cases c;
    std::uniform_real_distribution<double> coord(-50.0, 50.0);
    for (int i = 0; i < count; ++i) {
        const glm::vec3 p(float(coord(rng)), float(coord(rng)), float(coord(rng)));
        const glm::dvec3 toLight = light.type == LightType::Directional ? -glm::dvec3(light.direction())
                                                                          : glm::dvec3(light.position) - glm::dvec3(p);
        const glm::dvec3 n = glm::cross(toLight, randomUnit(rng));
        c.add(p, nudged(glm::vec3(n / glm::length(n)), rng, i % 3));
    }
    return c;
}

/// Points on the spot's cone (in double), facing the light: the cone test a tie.
Cases onTheCone(const Light& spot, std::mt19937& rng, int count) {
    Cases c;
    const glm::dvec3 axis(spot.direction());
    const double half = glm::radians(double(spot.coneDeg));
    std::uniform_real_distribution<double> dist(0.5, 80.0);
    for (int i = 0; i < count; ++i) {
        const glm::dvec3 u = glm::normalize(glm::cross(axis, randomUnit(rng)));
        const glm::dvec3 along = std::cos(half) * axis + std::sin(half) * u;
        const glm::vec3 p = nudged(glm::vec3(glm::dvec3(spot.position) + dist(rng) * along), rng, i % 3);
        c.add(p, glm::vec3(-along));
    }
    return c;
}

/// GPU decisions (now, before) per case.
std::vector<glm::uvec2> decide(const Light& light, const Cases& c) {
    return runComputeProbe("tests/light_reaches_probe.comp", light, "uCases", c.pn, uint32_t(c.count()), glm::uvec2(7u));
}

/// The CPU's decision as it was made before (glm::normalize, std::cos).
bool reachedBefore(const Light& light, glm::vec3 p, glm::vec3 n) {
    if (light.type == LightType::Spot &&
        !(glm::dot(glm::normalize(p - light.position), light.direction()) > float(std::cos(glm::radians(light.coneDeg)))))
        return false;
    return glm::dot(n, light.toLight(p)) > 0.0f;
}

/// Every case decided alike by Light::reaches and lightReaches; how often the two sides' former
/// decisions differed is printed (it depends on the implementation's normalize()).
void expectSameDecisions(const char* what, const Light& light, const Cases& c) {
    const std::vector<glm::uvec2> gpu = decide(light, c);
    size_t reached = 0, differedBefore = 0;
    for (size_t i = 0; i < c.count(); ++i) {
        const glm::vec3 p(c.pn[2 * i]), n(c.pn[2 * i + 1]);
        const bool cpu = light.reaches(p, n);
        ASSERT_EQ(gpu[i].x, cpu ? 1u : 0u) << what << " case " << i;
        reached += cpu;
        differedBefore += (gpu[i].y != 0u) != reachedBefore(light, p, n);
    }
    // The cases straddle the boundary (at least 1 % on each side; on the cone most round outside).
    EXPECT_GT(reached, c.count() / 100) << what;
    EXPECT_LT(reached, c.count() - c.count() / 100) << what;
    std::printf("[light_reaches] %-22s %zu ties, %zu reached; former GPU and CPU decisions differed on %zu\n", what,
                c.count(), reached, differedBefore);
}

TEST_F(LightReachesGLTest, GpuAndCpuDecideEveryTieAlike) {
    std::mt19937 rng(2026);
    const Light point = pointLight({3.7f, 41.3f, -12.9f});
    expectSameDecisions("point, grazing", point, grazing(point, rng, 4000));
    const Light sun = directionalLight({0.31f, 0.87f, -0.38f});
    expectSameDecisions("directional, grazing", sun, grazing(sun, rng, 4000));
    Light spot = point;
    spot.type = LightType::Spot;
    spot.target = {-1.0f, 0.0f, 2.5f};
    for (float cone : {7.5f, 30.0f, 61.0f}) {
        spot.coneDeg = cone;
        char what[64];
        std::snprintf(what, sizeof what, "spot %.1f deg, on the cone", double(cone));
        expectSameDecisions(what, spot, onTheCone(spot, rng, 4000));
    }
    expectSameDecisions("spot, grazing", spot, grazing(spot, rng, 4000));
}

// A normal whose product with the way to the light is subnormal: a GPU may flush it to zero
// (GLSL allows it), the CPU would keep it; both now flush, so both call the pixel unreached.
TEST_F(LightReachesGLTest, SubnormalProductsAreFlushedOnBothSides) {
    const Light point = pointLight({0.0f, 0.0f, 10.0f});
    Cases c;
    c.add({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1e-39f});   // 10 * 1e-39: subnormal
    c.add({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 3e-38f});   // 10 * 3e-38: normal, reached
    c.add({0.0f, 0.0f, 9.0f}, {0.0f, 0.0f, 1e-38f});   // the normal itself subnormal
    const std::vector<glm::uvec2> gpu = decide(point, c);
    const bool expected[] = {false, true, false};
    for (size_t i = 0; i < c.count(); ++i) {
        EXPECT_EQ(point.reaches(glm::vec3(c.pn[2 * i]), glm::vec3(c.pn[2 * i + 1])), expected[i]) << i;
        EXPECT_EQ(gpu[i].x, expected[i] ? 1u : 0u) << i;
    }
}

} // namespace
} // namespace shadowlab
