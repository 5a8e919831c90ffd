// The shadow planes psv and ptsv build their volumes from (shaders/common/shadow_volume.glsl): the
// plane through the light and a triangle edge. For an edge that points nearly at the light (sin φ
// small, φ the angle between the edge and the light's ray through it: thin posts, poles) the cross
// product of the two rounded vectors loses a share u / sin φ of its length, and the plane misses
// the edge's own ends by up to u |r| / sin φ, more than the close-call margin. The planes are now
// computed from error-free sums and products, rounded once: their error no longer depends on φ.
// The fault SHADOWLAB_FAULT_ROUNDED_CROSS (test-only) puts the plain float cross product back.
#include "framework/gl/GlObjects.h"
#include "framework/gl/Shader.h"
#include "framework/render/LightUniforms.h"
#include "tests/ShadowTestScenes.h"
#include "tests/TestSupport.h"

#include <glm/glm.hpp>
#include <cmath>
#include <vector>

namespace shadowlab {
namespace {

using namespace test;

class ShadowPlaneGLTest : public GLTest {};

struct Edges {
    std::vector<glm::vec4> ends; // a, b per edge
    Light light;
};

// The long edges of 24 thin posts (8 high, 1.5 mm thick, 5 to 51 mm from the foot of a point light
// 10 above the ground: sin φ from 5e-4 to 5e-3), the whole turned by an odd rotation so that no
// coordinate is round; each edge both ways round.
Edges postEdges() {
    const glm::mat4 turn = rotate(37.0f, glm::normalize(glm::vec3(0.3f, 1.0f, 0.55f))) * rotate(11.0f, {1, 0, 0});
    const auto at = [&](glm::vec3 p) { return glm::vec3(turn * glm::vec4(p, 1.0f)); };
    Edges e;
    e.light = pointLight(at({0.0f, 10.0f, 0.0f}));
    for (int i = 0; i < 24; ++i) {
        const float a = glm::radians(15.0f * float(i) + 3.7f), r = 0.005f + 0.002f * float(i);
        for (int k = 0; k < 8; ++k) {
            const float b = glm::radians(45.0f * float(k));
            const glm::vec3 foot{r * std::cos(a) + 0.0015f * std::cos(b), 0.0f, r * std::sin(a) + 0.0015f * std::sin(b)};
            const glm::vec3 lo = at(foot), hi = at(foot + glm::vec3(0.0f, 8.0f, 0.0f));
            e.ends.insert(e.ends.end(), {glm::vec4(lo, 0.0f), glm::vec4(hi, 0.0f), glm::vec4(hi, 0.0f), glm::vec4(lo, 0.0f)});
        }
    }
    return e;
}

// The largest distance, over all edges, from an edge's ends to its plane (in double), and the
// bound a plane rounded once allows there: a few ulps of the ends' and the light's distance from
// the origin (the normal's rounding tilts it by ~u, its offset is rounded to ~u |light|).
struct PlaneError {
    double worst = 0, worstOverBound = 0;
};

PlaneError planeErrors(const Edges& e) {
    const uint32_t n = uint32_t(e.ends.size() / 2);
    const std::vector<glm::vec4> p = runComputeProbe("tests/edge_plane_probe.comp", e.light, "uEdges", e.ends, n, glm::vec4(0.0f));
    const double u = std::ldexp(1.0, -24);
    const glm::dvec3 light(e.light.position);
    PlaneError out;
    for (uint32_t i = 0; i < n; ++i) {
        EXPECT_NE(glm::vec3(p[i]), glm::vec3(0.0f)) << "edge " << i << " is not edge-on";
        for (int end = 0; end < 2; ++end) {
            const glm::dvec3 x(glm::vec3(e.ends[2 * i + end]));
            const double value = std::abs(glm::dot(glm::dvec3(glm::vec3(p[i])), x) + double(p[i].w));
            const double bound = 4.0 * u * (glm::length(x - light) + glm::length(light) + glm::length(x));
            out.worst = std::max(out.worst, value);
            out.worstOverBound = std::max(out.worstOverBound, value / bound);
        }
    }
    return out;
}

TEST_F(ShadowPlaneGLTest, FaultRoundedCrossProductAndTheAccuratePlanes) {
    const PlaneError accurate = planeErrors(postEdges());
    PlaneError rounded;
    {
        ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_ROUNDED_CROSS", "1"}});
        rounded = planeErrors(postEdges());
    }
    std::printf("[shadow planes] worst distance of an edge's end from its plane: %.3g (%.2f of the bound), "
                "with the float cross product %.3g (%.1f of it)\n",
                accurate.worst, accurate.worstOverBound, rounded.worst, rounded.worstOverBound);
    EXPECT_LE(accurate.worstOverBound, 1.0);
    EXPECT_GT(rounded.worstOverBound, 1.0) << "the posts must be ill-conditioned enough to tell the two apart";
}

} // namespace
} // namespace shadowlab
