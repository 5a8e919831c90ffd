// Rigid motion without a GL context: keyframed paths, how scene objects, grids and transforms
// compose their motions, glTF node animations (LINEAR, STEP, CUBICSPLINE) and what is refused.
#include "framework/core/Error.h"
#include "framework/experiment/Config.h"
#include "framework/scene/GltfLoader.h"
#include "framework/scene/Motion.h"
#include "framework/scene/SceneConfig.h"
#include "tests/AnimatedGltf.h"
#include "tests/HostileInputs.h"
#include "tests/TestSupport.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <fstream>

namespace shadowlab {
namespace {

RigidPath parsePath(const Json& j) {
    Json resolved;
    return RigidPath::parse(JsonNode("p.json", &j, "/path", &resolved));
}

glm::vec3 apply(const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1.0f)); }

void expectNear(glm::vec3 a, glm::vec3 b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

TEST(RigidPathTest, InterpolatesTranslateRotateAndScale) {
    RigidPath linear = parsePath({{"interpolation", "linear"},
                                  {"keyframes", {{{"time", 0}, {"translate", {0, 0, 0}}, {"rotate_deg", {0, 0, 0}}},
                                                 {{"time", 2}, {"translate", {4, 0, 0}}, {"rotate_deg", {0, 360, 0}}, {"scale", 3}}}}});
    // Half way: half the translation, half a turn (a full 360° key spins, it is not 0°), scale 2.
    expectNear(apply(linear.at(1.0), {1, 0, 0}), {2 - 2, 0, 0});
    expectNear(apply(linear.at(0.5), {1, 0, 0}), glm::vec3(1, 0, 0) + glm::vec3(0, 0, -1.5f) * 1.0f);
    // Clamped outside its keys.
    expectNear(apply(linear.at(-5.0), {1, 0, 0}), {1, 0, 0});
    expectNear(apply(linear.at(9.0), {1, 0, 0}), {7, 0, 0});

    RigidPath step = parsePath({{"interpolation", "step"},
                                {"keyframes", {{{"time", 0}, {"translate", {0, 1, 0}}}, {{"time", 1}, {"translate", {0, 5, 0}}}}}});
    expectNear(apply(step.at(0.99), {0, 0, 0}), {0, 1, 0});
    expectNear(apply(step.at(1.0), {0, 0, 0}), {0, 5, 0});

    // Catmull-Rom (the default, as for camera paths) passes through every key.
    RigidPath smooth = parsePath({{"keyframes",
                                   {{{"time", 0}, {"translate", {0, 0, 0}}},
                                    {{"time", 1}, {"translate", {1, 2, 0}}},
                                    {{"time", 2}, {"translate", {3, 0, 1}}}}}});
    expectNear(apply(smooth.at(1.0), {0, 0, 0}), {1, 2, 0});
    expectNear(apply(smooth.at(2.0), {0, 0, 0}), {3, 0, 1});
}

TEST(RigidPathTest, RefusesBadKeyframes) {
    auto cause = [](const Json& j) {
        try {
            parsePath(j);
        } catch (const InputError& e) {
            return e.jsonPath() + ": " + e.cause();
        }
        return std::string("accepted");
    };
    EXPECT_EQ(cause({{"keyframes", Json::array()}}), "/path/keyframes: a path needs at least one keyframe");
    EXPECT_NE(cause({{"keyframes", {{{"time", 1}}, {{"time", 1}}}}}).find("/path/keyframes/1/time: keyframe times must increase"),
              std::string::npos);
    EXPECT_NE(cause({{"keyframes", {{{"time", 0}, {"scale", 0}}}}}).find("/path/keyframes/0/scale: path scales must be greater than 0"),
              std::string::npos);
    EXPECT_NE(cause({{"keyframes", {{{"time", 0}, {"spin", 1}}}}}).find("spin"), std::string::npos);
    EXPECT_NE(cause({{"keyframes", {{{"time", 0}}}}, {"interpolation", "cubic"}}).find("/path/interpolation"), std::string::npos);
}

Scene sceneOf(const Json& objects) {
    Json scene = {{"objects", objects}}, resolved;
    return buildScene(JsonNode("s.json", &scene, "/scene", &resolved));
}

TEST(MovingSceneTest, AnObjectWithAPathIsOneMovingPartPlacedByItsTransformFirst) {
    Json spin = {{"keyframes", {{{"time", 0}, {"rotate_deg", {0, 0, 0}}}, {{"time", 1}, {"rotate_deg", {0, 90, 0}}}}},
                 {"interpolation", "linear"}};
    Scene s = sceneOf({{{"procedural", "plane"}, {"size", {2, 2}}},
                       {{"procedural", "plane"}, {"size", {1, 1}}, {"transform", {{"translate", {2, 0, 0}}}}, {"path", spin}}});
    ASSERT_EQ(s.moving.size(), 1u);
    const MovingPart& part = s.moving[0];
    EXPECT_EQ(part.firstTriangle, 2u);
    EXPECT_EQ(part.triangleCount, 2u);
    EXPECT_EQ(s.motionTimeRange(), glm::dvec2(0, 1));
    // world(t) = path(t) · transform: the translated plane turns about the world origin.
    const glm::vec3 centre = 0.5f * (part.local[0] + part.local[2]);
    expectNear(apply(part.worldFromLocal(0.0), centre), {2, 0, 0}, 0.6f);
    expectNear(apply(part.worldFromLocal(1.0), glm::vec3(2, 0, 0)), {0, 0, -2});
    // The static ground keeps its own bounds; posing moves only the part.
    Scene posed = s;
    posed.applyPose(posed.poseAt(1.0));
    for (size_t i = 0; i < 6; ++i) EXPECT_EQ(posed.positions[i], s.positions[i]);
    EXPECT_LT(posed.bounds.min.z, -2.4f);
    const Bounds b = s.boundsAt(s.poseAt(1.0));
    EXPECT_LE(b.min.z, posed.bounds.min.z);
}

TEST(MovingSceneTest, GridsCopyMovingObjectsAndComposeTheirOwnPath) {
    Json bob = {{"keyframes", {{{"time", 0}, {"translate", {0, 0, 0}}}, {{"time", 2}, {"translate", {0, 1, 0}}}}},
                {"interpolation", "linear"}};
    Json slide = {{"keyframes", {{{"time", 0}, {"translate", {0, 0, 0}}}, {{"time", 4}, {"translate", {10, 0, 0}}}}},
                  {"interpolation", "linear"}};
    Scene s = sceneOf({{{"procedural", "grid"},
                        {"object", {{"procedural", "plane"}, {"size", {0.5, 0.5}}, {"path", bob}}},
                        {"count", {3, 1, 1}},
                        {"spacing", {2, 1, 1}},
                        {"path", slide}}});
    ASSERT_EQ(s.moving.size(), 3u);  // one part per copy
    EXPECT_EQ(s.motionTimeRange(), glm::dvec2(0, 4));
    // Copy 0 sits at x = -2; at t = 2 it has bobbed up 1 (clamped after) and slid 5.
    expectNear(apply(s.moving[0].worldFromLocal(2.0), glm::vec3(0)), {-2 + 5, 1, 0});
    expectNear(apply(s.moving[2].worldFromLocal(4.0), glm::vec3(0)), {2 + 10, 1, 0});
}

TEST(MovingSceneTest, ConfigsRefuseStaticOnlyAlgorithmsOnMovingScenesUnlessTheyRebuild) {
    auto config = [](Json params) {
        return Json{{"resolution", {16, 16}},
                    {"frames", 2},
                    {"scene", {{"objects", {{{"procedural", "sphere"}, {"triangles", 100},
                                             {"path", {{"keyframes", {{{"time", 0}}, {{"time", 1}, {"translate", {1, 0, 0}}}}}}}}}}}},
                    {"light", {{"type", "point"}, {"position", {0, 5, 0}}}},
                    {"camera", {{"position", {0, 2, 5}}, {"target", {0, 0, 0}}}},
                    {"algorithms", {{{"algorithm", "line_space"}, {"params", params}}}}};
    };
    try {
        parseConfig(config(Json::object()), "dyn.json");
        FAIL() << "line_space on a moving scene was accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.jsonPath(), "/algorithms/0/algorithm");
        EXPECT_NE(e.cause().find("rebuild_every_frame"), std::string::npos) << e.cause();
    }
    ExperimentConfig ok = parseConfig(config({{"rebuild_every_frame", true}}), "dyn.json");
    EXPECT_TRUE(ok.scene->dynamic());
    // The clock: without camera or light paths, the span of the scene's motion.
    EXPECT_DOUBLE_EQ(ok.sceneTimeAt(0), 0.0);
    EXPECT_DOUBLE_EQ(ok.sceneTimeAt(1), 1.0);
}

TEST(GltfAnimationTest, PlaysNodeChannelsOnTheFilesClock) {
    const std::string file = test::makeTempDir("anim") + "/spin.gltf";
    test::writeAnimatedGltf(file);
    Scene s = loadGltf(file, nullptr, 1000, {"spin"});
    ASSERT_EQ(s.moving.size(), 1u);
    EXPECT_EQ(s.moving[0].triangleCount, 2u);
    EXPECT_EQ(s.motionTimeRange(), glm::dvec2(0, 2));
    const glm::vec3 corner(0.3f, 0, -0.25f);  // a blade vertex in mesh space
    // t = 1: the hub turned 90° about Y ((x, y, z) -> (z, y, -x)); the STEP slide still at its first key.
    expectNear(apply(s.moving[0].worldFromLocal(1.0), corner), {-0.25f, 2, -0.3f});
    // t = 2: 180°, and the slide jumped to +0.4 along the blade.
    expectNear(apply(s.moving[0].worldFromLocal(2.0), corner), {-0.7f, 2, 0.25f});
    // LINEAR quaternions are slerped: 45° at t = 0.5.
    const float c = std::cos(glm::radians(45.0f)), sn = std::sin(glm::radians(45.0f));
    expectNear(apply(s.moving[0].worldFromLocal(0.5), {1, 0, 0}), {c, 2, -sn});
    // The same animation by index; without one, the file is static at its rest pose.
    EXPECT_EQ(loadGltf(file, nullptr, 1000, {"0"}).moving.size(), 1u);
    EXPECT_FALSE(loadGltf(file, nullptr, 1000).dynamic());

    // CUBICSPLINE with zero tangents eases between the same keys: through them, and half way at t = 0.5
    // (the slide, LINEAR now, has moved the blade 0.2 and 0.1 along its x axis by then).
    test::AnimatedGltfOptions o;
    o.rotationInterpolation = "CUBICSPLINE";
    o.translationInterpolation = "LINEAR";
    test::writeAnimatedGltf(file, o);
    Scene cubic = loadGltf(file, nullptr, 1000, {"spin"});
    expectNear(apply(cubic.moving[0].worldFromLocal(1.0), {1, 0, 0}), {0, 2, -1.2f});
    expectNear(apply(cubic.moving[0].worldFromLocal(0.5), {1, 0, 0}), {1.1f * c, 2, -1.1f * sn});
}

TEST(GltfAnimationTest, ConfigNodePathsTurnAPartAboutItsCentreOrItsOrigin) {
    const std::string file = test::makeTempDir("anim") + "/spin.gltf";
    test::writeAnimatedGltf(file);
    auto blade = [&](const char* pivot) {
        Json objects = {{{"gltf", file},
                         {"node_paths", {{{"node", 1}, {"pivot", pivot},
                                          {"path", {{"keyframes", {{{"time", 0}}, {{"time", 1}, {"rotate_deg", {0, 90, 0}}}}},
                                                    {"interpolation", "linear"}}}}}}}};
        return sceneOf(objects);
    };
    // The file's animation is not played; only the blade (node 1, below the hub at y = 2) turns.
    Scene centre = blade("centre"), origin = blade("origin");
    ASSERT_EQ(centre.moving.size(), 1u);
    const glm::vec3 corner(0.3f, 0, -0.25f);
    // About the blade's centre (1.1, 0, 0): the corner, 0.8 short of it, swings round it.
    expectNear(apply(centre.moving[0].worldFromLocal(1.0), corner), {1.1f - 0.25f, 2, 0.8f});
    // About the node's origin (the hub): the whole blade swings round the hub.
    expectNear(apply(origin.moving[0].worldFromLocal(1.0), corner), {-0.25f, 2, -0.3f});
}

std::string gltfError(const std::string& file, const std::string& animation) {
    try {
        loadGltf(file, nullptr, 1'000'000, {animation});
    } catch (const InputError& e) {
        return e.jsonPath() + ": " + e.cause();
    }
    return "accepted";
}

TEST(GltfAnimationTest, RefusesSkinsMorphTargetsAndUnknownAnimationsClearly) {
    const std::string dir = test::makeTempDir("anim");
    test::writeAnimatedGltf(dir + "/spin.gltf");
    EXPECT_EQ(gltfError(dir + "/spin.gltf", "wave"), "/animations: no animation \"wave\" (the file has 1: 0 \"spin\")");
    test::AnimatedGltfOptions morph;
    morph.morphChannel = true;
    test::writeAnimatedGltf(dir + "/morph.gltf", morph);
    EXPECT_NE(gltfError(dir + "/morph.gltf", "spin").find("/animations/0/channels/2/target/path: morph target"), std::string::npos);
    // Debian's assimp test models: a skinned mesh, and a morph-target animation.
    EXPECT_NE(gltfError(test::kAssimpGltf + "/simple_skin/simple_skin.gltf", "0").find("skinned meshes are not supported"),
              std::string::npos);
    EXPECT_NE(gltfError(test::kAssimpGltf + "/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf", "0")
                  .find("morph target animation (weights) is not supported"),
              std::string::npos);
}

TEST(MovingSceneTest, BoundsKeepANaNThatGlmMinAndMaxWouldDrop) {
    Bounds b;
    b.extend(glm::vec3(1, 2, 3));
    EXPECT_TRUE(b.finite());
    b.extend(glm::vec3(std::nanf(""), 0, 0));
    EXPECT_FALSE(b.finite());
    EXPECT_TRUE(std::isnan(b.min.x) && std::isnan(b.max.x));
    b.extend(glm::vec3(5, 5, 5));  // a later finite point does not wash it out
    EXPECT_TRUE(std::isnan(b.min.x));
    Bounds c;
    c.extend(glm::vec3(0));
    c.extend(b);
    EXPECT_FALSE(c.finite());
    Bounds inf;
    inf.extend(glm::vec3(0, INFINITY, 0));
    EXPECT_FALSE(inf.finite());
}

TEST(RigidPathTest, APoseBeyondFloatRangeIsAnErrorNamingThePathAndTheTime) {
    // Catmull-Rom through 1, 3.4e38, 3.4e38, 1 overshoots to 3.8e38 half way between the middle keys.
    RigidPath p = parsePath({{"keyframes", {{{"time", 0}, {"scale", 1}}, {{"time", 1}, {"scale", 3.4e38}},
                                            {{"time", 2}, {"scale", 3.4e38}}, {{"time", 3}, {"scale", 1}}}}});
    try {
        p.at(1.5);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.file(), "p.json");
        EXPECT_EQ(e.jsonPath(), "/path");
        EXPECT_NE(e.cause().find("interpolated scale is not finite"), std::string::npos) << e.cause();
        EXPECT_NE(e.cause().find("at time 1.5 s"), std::string::npos) << e.cause();
    }
    // Keys of 1, 1, 3e38 overflowed a float spline into NaN; in double it is a finite, huge scale,
    // which the experiment's coordinate check refuses (HostileInputTest.PathCatmullRomScaleOvershoots).
    RigidPath q = parsePath({{"keyframes", {{{"time", 0}, {"scale", 1}}, {{"time", 1}, {"scale", 1}}, {{"time", 2}, {"scale", 3e38}}}}});
    const glm::mat4 m = q.at(1.5);
    EXPECT_TRUE(isFinite(m));
    EXPECT_GT(m[0][0], 1e37f);
}

TEST(MovingSceneTest, ANonFinitePoseOfAnyPartIsAnErrorNamingWhereItsMotionWasGiven) {
    Scene s = sceneOf({{{"procedural", "sphere"}, {"path", {{"keyframes", {{{"time", 0}}, {{"time", 1}, {"translate", {1, 0, 0}}}}}}}}});
    ASSERT_EQ(s.moving.size(), 1u);
    EXPECT_EQ(s.moving[0].sourceFile, "s.json");
    EXPECT_EQ(s.moving[0].sourcePath, "/scene/objects/0/path");
    // A motion function without its own checks: poseAt() is the last guard.
    s.moving[0].worldFromLocal = [](double t) { return t > 0.5 ? glm::mat4(std::nanf("")) : glm::mat4(1.0f); };
    EXPECT_NO_THROW(s.poseAt(0.0));
    try {
        s.poseAt(0.75);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.jsonPath(), "/scene/objects/0/path");
        EXPECT_NE(e.cause().find("not finite at time 0.75 s"), std::string::npos) << e.cause();
    }
}

TEST(GltfAnimationTest, ARotationKeyOfHugeComponentsIsTheRotationItPointsAt) {
    // (1e38, 0, 0, 1): its float length overflows (and the pose became NaN); as a direction it is a
    // half turn about X, which is what the node plays.
    const std::string file = test::makeTempDir("anim") + "/big.gltf";
    std::ofstream(file) << test::animatedTriangleGltf({{"rotation", "LINEAR", {0, 1}, {0, 0, 0, 1, 1e38f, 0, 0, 1}}});
    Scene s = loadGltf(file, nullptr, 1000, {"0"});
    ASSERT_EQ(s.moving.size(), 1u);
    EXPECT_EQ(s.moving[0].sourcePath, "/nodes/0");
    for (double t : {0.0, 0.25, 0.5, 1.0}) EXPECT_TRUE(isFinite(s.moving[0].worldFromLocal(t))) << t;
    expectNear(apply(s.moving[0].worldFromLocal(1.0), {0, 1, 0}), {0, -1, 0});
    expectNear(apply(s.moving[0].worldFromLocal(0.5), {0, 1, 0}), {0, 0, 1});
}

TEST(GltfAnimationTest, TwoChannelsOnOneNodesPropertyAreRefused) {
    const std::string file = test::makeTempDir("anim") + "/two.gltf";
    // Two rotations of node 0: one of them would never play.
    std::ofstream(file) << test::animatedTriangleGltf({{"rotation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 1, 0, 1}},
                                                       {"scale", "LINEAR", {0, 1}, {1, 1, 1, 2, 2, 2}},
                                                       {"rotation", "STEP", {0, 1}, {0, 0, 0, 1, 1, 0, 0, 1}}});
    EXPECT_EQ(gltfError(file, "a"), "/animations/0/channels/2/target: node 0's rotation is animated by /animations/0/channels/0 "
                                    "already (glTF allows one channel per node and property)");
}

} // namespace
} // namespace shadowlab
