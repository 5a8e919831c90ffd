// The exact family (psv in each traversal, metric_tree in each query, ptsv) against the Embree
// reference with no tolerance at all: the same decision on every lit pixel.
//
// Two tables. "Frames": the frames of shipped configs where a pixel once differed, at the
// resolution that showed it (each row's comment says what was wrong and why). "Grazing": scenes
// and lights built to put query points next to shadow planes and triangle planes, where a plane
// test and the reference's ray test could round differently: thin posts, long slivers, a light on
// the extension of a wall's plane, a light skimming the ground.
#include "algorithms/bvh_raytrace/BvhRaytrace.h"
#include "algorithms/izb/Izb.h"
#include "algorithms/metric_tree/MetricTree.h"
#include "algorithms/psv/Psv.h"
#include "algorithms/ptsv/Ptsv.h"
#include "framework/experiment/Config.h"
#include "framework/scene/Procedural.h"
#include "tests/AlgorithmHarness.h"
#include "tests/TestSupport.h"

#include <cstdio>

namespace shadowlab {
namespace {

using namespace test;

struct Exact {
    const char* name;
    AlgorithmInfo (*info)();
    std::map<std::string, ParamValue> params;
};

// Every exact configuration whose image is claimed to be the reference's.
const Exact kExact[] = {
    {"psv_stack", psvInfo, {{"traversal", std::string("stack")}}},
    {"psv_stackless", psvInfo, {{"traversal", std::string("stackless")}}},
    {"psv_hybrid", psvInfo, {{"traversal", std::string("hybrid")}}},
    {"psv_stackless_depth_skip", psvInfo, {{"traversal", std::string("stackless")}, {"depth_skip", true}}},
    {"metric_tree_tile", metricTreeInfo, {{"query", std::string("tile")}}},
    {"metric_tree_pixel", metricTreeInfo, {{"query", std::string("pixel")}}},
    {"ptsv", ptsvInfo, {}},
};

// Runs every exact configuration on `shot` at `res`² and expects no differing pixel and no overflow.
void expectAllExact(const Shot& shot, int res, const char* where) {
    for (const Exact& e : kExact) {
        RunOptions options;
        options.resolution = res;
        const AlgorithmRun o = runAlgorithm(e.info(), shot, e.params, options);
        const size_t wrong = size_t(o.accuracy.mismatchRatio * double(o.accuracy.litPixels) + 0.5);
        std::printf("[exact] %-28s %-26s lit %6zu wrong %zu (false lit %.6f%%)\n", where, e.name, o.accuracy.litPixels,
                    wrong, 100 * o.accuracy.falseLit);
        EXPECT_EQ(wrong, 0u) << e.name << " on " << where;
        EXPECT_EQ(o.overflow, 0u) << e.name << " on " << where;
    }
}

// ---- Frames of the shipped configs --------------------------------------------------------------

struct FrameCase {
    const char* name;
    const char* config; ///< relative to the source tree
    int frame;
    int resolution;
};

void PrintTo(const FrameCase& c, std::ostream* os) { *os << c.name; }

// Before the close calls were decided by the reference's ray test (the plane tests alone), each of
// these frames had one wrong pixel: a plane value within rounding of 0 decided the other way.
const FrameCase kFrames[] = {
    // psv and ptsv: 1 falsely shadowed pixel (at 256² and at 512²), a post's grazing shadow edge.
    {"fence_256_frame0", "configs/metric_tree/ablation_fence.json", 0, 256},
    {"fence_512_frame0", "configs/metric_tree/ablation_fence.json", 0, 512},
    // The main job: psv and ptsv 1 falsely lit pixel (frame 23), ptsv 1 falsely shadowed (frame 7),
    // metric_tree 1 falsely shadowed (frame 57: its own ray test, with widened barycentrics).
    {"demo_512_frame7", "configs/demo.json", 7, 512},
    {"demo_512_frame23", "configs/demo.json", 23, 512},
    {"demo_512_frame57", "configs/demo.json", 57, 512},
};

class ExactFramesGLTest : public GLTest, public ::testing::WithParamInterface<FrameCase> {};

TEST_P(ExactFramesGLTest, EveryPixelIsTheReferences) {
    const FrameCase& c = GetParam();
    const ExperimentConfig cfg = loadConfig(std::string(SHADOWLAB_SOURCE_DIR) + "/" + c.config);
    ASSERT_FALSE(cfg.scene->dynamic()) << "a static scene: the frame is its camera and light";
    Shot shot{*cfg.scene, cfg.cameraAt(c.frame), cfg.lightAt(c.frame)};
    expectAllExact(shot, c.resolution, c.name);
}

INSTANTIATE_TEST_SUITE_P(Table, ExactFramesGLTest, ::testing::ValuesIn(kFrames),
                         [](const auto& info) { return std::string(info.param.name); });

// ---- Grazing geometry ---------------------------------------------------------------------------

// Thin posts (radius 0.004, 48 sides: long facets nearly parallel to the light) on the ground.
Shot thinPosts(glm::vec3 light) {
    Shot s;
    s.scene = makePlane({6, 6}, 6, Material{});
    s.scene.append(makeFence(16, 0.12f, 0.8f, 0.004f, 4, 48, Material{}), translate({0, 0, -0.3f}));
    s.camera = lookAt({0.4f, 1.6f, 2.4f}, {0, 0.2f, -0.3f}, 50.0f);
    s.light = pointLight(light);
    return s;
}

// Long slivers (1.6 long, 0.002 wide) fanned over the ground at several heights and tilts.
Shot slivers(glm::vec3 light) {
    Shot s;
    s.scene = makePlane({6, 6}, 4, Material{});
    std::vector<glm::vec3> tris;
    for (int i = 0; i < 40; ++i) {
        const float a = float(i) * 0.157f, y = 0.15f + 0.02f * float(i % 7);
        const glm::vec3 d(std::cos(a), 0.1f * std::sin(3.0f * a), std::sin(a));
        const glm::vec3 side = glm::normalize(glm::cross(d, glm::vec3(0, 1, 0))) * 0.002f;
        const glm::vec3 o(0.05f * std::sin(a), y, 0.05f * std::cos(a));
        tris.insert(tris.end(), {o - 0.8f * d, o + 0.8f * d, o + 0.8f * d + side});
        tris.insert(tris.end(), {o - 0.8f * d, o + 0.8f * d + side, o - 0.8f * d + side});
    }
    s.scene.addTriangles(tris, Material{});
    s.camera = lookAt({0.0f, 2.2f, 2.2f}, {0, 0.1f, 0}, 55.0f);
    s.light = pointLight(light);
    return s;
}

// A wall (a thin box's faces) whose big faces lie in planes through the light, beside a sphere and
// posts: shadow planes and capping planes that contain, or nearly contain, the light.
Shot wallInLightPlane(glm::vec3 light) {
    Shot s;
    s.scene = makePlane({6, 6}, 4, Material{});
    // The wall's faces at x = light.x ± 1e-4 and a face exactly in the plane x = light.x.
    const float x = light.x;
    s.scene.addTriangles({{x, 0, -1}, {x, 0.6f, -1}, {x, 0.6f, 0.2f}, {x, 0, -1}, {x, 0.6f, 0.2f}, {x, 0, 0.2f}}, Material{});
    s.scene.addTriangles({{x + 1e-4f, 0, -1}, {x + 1e-4f, 0.5f, 0.2f}, {x + 1e-4f, 0.5f, -1}}, Material{});
    s.scene.append(makeSphere(0.3f, 800, Material{}), translate({x - 0.6f, 0.4f, -0.2f}));
    s.scene.append(makeFence(5, 0.2f, 0.6f, 0.01f, 1, 24, Material{}), translate({x + 0.5f, 0, -0.4f}));
    s.camera = lookAt({x + 0.3f, 1.8f, 2.4f}, {x, 0.2f, -0.3f}, 55.0f);
    s.light = pointLight(light);
    return s;
}

struct GrazingCase {
    const char* name;
    Shot (*make)(glm::vec3);
    glm::vec3 light;
};

void PrintTo(const GrazingCase& c, std::ostream* os) { *os << c.name; }

const GrazingCase kGrazing[] = {
    {"posts_high", thinPosts, {0.7f, 2.5f, 1.5f}},
    {"posts_low", thinPosts, {1.5f, 0.35f, 0.8f}},       // shadows drawn out along the ground
    {"posts_skimming", thinPosts, {2.5f, 0.02f, -0.3f}}, // the light 0.02 above the ground's plane
    {"posts_in_line", thinPosts, {0.0f, 1.2f, -0.3f}},   // the light above the fence's own line
    {"slivers_high", slivers, {0.3f, 2.0f, 0.4f}},
    {"slivers_low", slivers, {1.8f, 0.4f, -0.5f}},
    {"wall_in_light_plane", wallInLightPlane, {0.2f, 1.5f, 0.6f}},
    {"wall_light_at_top", wallInLightPlane, {0.2f, 0.6f, 0.6f}}, // also level with the wall's top edge
};

class ExactGrazingGLTest : public GLTest, public ::testing::WithParamInterface<GrazingCase> {};

TEST_P(ExactGrazingGLTest, EveryPixelIsTheReferences) {
    const GrazingCase& c = GetParam();
    expectAllExact(c.make(c.light), 192, c.name);
}

INSTANTIATE_TEST_SUITE_P(Table, ExactGrazingGLTest, ::testing::ValuesIn(kGrazing),
                         [](const auto& info) { return std::string(info.param.name); });

// ---- Where the GPU's triangle test and Embree's part ways ----------------------------------------

// Thin posts standing almost under a point light, so that the shadow rays of the ground around
// their feet run along the posts' sides for 8 units, a hair from parallel to them (sin φ from 5e-4
// to 5e-3), the whole shot turned by an odd rotation so that no coordinate is round, seen close up.
Shot postsTowardTheLight() {
    const glm::mat4 turn = rotate(37.0f, glm::normalize(glm::vec3(0.3f, 1.0f, 0.55f))) * rotate(11.0f, {1, 0, 0});
    const auto at = [&](glm::vec3 p) { return glm::vec3(turn * glm::vec4(p, 1.0f)); };
    Scene local = makePlane({2, 2}, 1, Material{});
    for (int i = 0; i < 24; ++i) {
        const float a = glm::radians(15.0f * float(i) + 3.7f), r = 0.005f + 0.002f * float(i);
        local.append(makeCylinder(0.0015f, 8.0f, 16, Material{}), translate({r * std::cos(a), 0, r * std::sin(a)}));
    }
    Shot s;
    s.scene.append(local, turn);
    s.camera = lookAt(at({0.015f, 0.02f, -0.03f}), at({0.012f, 0.0f, 0.0008f}), 6.0f);
    s.light = pointLight(at({0.0f, 10.0f, 0.0f}));
    return s;
}

// On rays that run a hair from parallel to a triangle for a long way, the watertight test in
// floats decides by rounding, and ours (common/watertight.glsl) and Embree's robust one round
// differently: both are watertight, neither is wrong, and on this shot a few pixels differ. What
// holds is that every GPU algorithm makes the one decision of the shared test: the exact family,
// izb and bvh_raytrace give the same image, bit for bit, and each differs from the reference on the
// same pixels. (The falsely lit pixel of frame 1 of configs/metric_tree/many_models.json, 74 M
// triangles among thin fence posts, stays with metric_tree's slabs, overlap intervals, depth skip
// and tile query all off, which leaves its bounding spheres and this triangle test: most likely the
// same cause, not proven there; docs/algorithms/metric_tree.md.)
class ExactFamilyGLTest : public GLTest {};

TEST_F(ExactFamilyGLTest, GpuAlgorithmsShareOneTriangleDecisionWhereEmbreeDiffers) {
    const Shot shot = postsTowardTheLight();
    const AlgorithmRun bvh = runAlgorithm(bvhRaytraceInfo(), shot, {});
    const size_t differs = size_t(bvh.accuracy.mismatchRatio * double(bvh.accuracy.litPixels) + 0.5);
    std::printf("[exact] posts toward the light: bvh_raytrace differs from the reference on %zu of %zu lit pixels\n",
                differs, bvh.accuracy.litPixels);
    for (const Exact& e : kExact) {
        const AlgorithmRun o = runAlgorithm(e.info(), shot, e.params);
        EXPECT_EQ(o.visibility, bvh.visibility) << e.name;
        EXPECT_EQ(o.overflow, 0u) << e.name;
    }
    const AlgorithmRun izb = runAlgorithm(izbInfo(), shot, {});
    EXPECT_EQ(izb.visibility, bvh.visibility) << "izb";
}

} // namespace
} // namespace shadowlab
