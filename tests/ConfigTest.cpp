// Config parsing and validation: defaults fill in, and every bad input is one InputError naming
// the file, the JSON path and the cause.
#include "framework/core/Error.h"
#include "framework/experiment/Config.h"

#include <gtest/gtest.h>

namespace shadowlab {
namespace {

Json minimal() {
    return Json::parse(R"({
        "scene": {"objects": [{"procedural": "plane"}, {"procedural": "sphere", "triangles": 200}]},
        "algorithms": [{"algorithm": "shadow_map"}]
    })");
}

TEST(ConfigTest, MissingKeysTakeDefaults) {
    ExperimentConfig c = parseConfig(minimal(), "/tmp/x/cfg.json");
    EXPECT_EQ(c.resolution, glm::ivec2(256, 256));
    EXPECT_EQ(c.frames, 30);
    EXPECT_TRUE(c.reference);
    ASSERT_EQ(c.algorithms.size(), 1u);
    EXPECT_EQ(c.algorithms[0].id, "shadow_map");
    EXPECT_EQ(std::get<int>(c.algorithms[0].params.get("resolution")), 2048);
    EXPECT_EQ(c.outputDir, "/tmp/x/results/experiment"); // relative to the config's folder
    // The resolved config names every value used, defaults included.
    EXPECT_EQ(c.resolved["algorithms"][0]["params"]["pcf"], 1);
    EXPECT_EQ(c.resolved["camera"]["fov_y_deg"], 60.0);
    EXPECT_EQ(c.resolved["light"]["type"], "point");
}

// Seventh probe: frames took 1.0 while resolution refused [1e2, 32]; every integer takes both.
TEST(ConfigTest, IntegersWrittenAsFloatsAreIntegersEverywhere) {
    Json j = minimal();
    j["resolution"] = Json::parse("[1e2, 64.0]");
    j["frames"] = Json::parse("3.0");
    const ExperimentConfig c = parseConfig(j, "/tmp/x/cfg.json");
    EXPECT_EQ(c.resolution, glm::ivec2(100, 64));
    EXPECT_EQ(c.frames, 3);
}

TEST(ConfigTest, ResolvedConfigParsesToTheSameExperiment) {
    ExperimentConfig a = parseConfig(minimal(), "/tmp/x/cfg.json");
    ExperimentConfig b = parseConfig(a.resolved, "/tmp/x/cfg.json");
    EXPECT_EQ(a.resolved, b.resolved);
}

// Fifth probe: a spot light moving along a path whose keys name no target pointed down -z on
// every frame, ignoring the light.target the config fixes. Keys without a target aim at it.
TEST(ConfigTest, PathKeysWithoutTargetAimAtTheFixedTarget) {
    Json j = minimal();
    j["frames"] = 3;
    j["light"] = Json::parse(R"({"type": "spot", "target": [1, 0, 2], "path": {"keyframes": [
        {"time": 0, "position": [0, 5, 0]}, {"time": 1, "position": [3, 5, 0], "target": [0, 0, 0]},
        {"time": 2, "position": [0, 6, 1]}]}})");
    j["camera"] = Json::parse(R"({"target": [0, 1, 0], "path": {"keyframes": [{"time": 0, "position": [0, 2, 6]}]}})");
    ExperimentConfig c = parseConfig(j, "/tmp/x/cfg.json");
    EXPECT_EQ(c.lightAt(0).target, glm::vec3(1, 0, 2));
    EXPECT_EQ(c.lightAt(1).target, glm::vec3(0, 0, 0)); // a key's own target wins
    EXPECT_EQ(c.lightAt(2).target, glm::vec3(1, 0, 2));
    EXPECT_EQ(c.cameraAt(0).target, glm::vec3(0, 1, 0));
    // The resolved config writes every key's target: it replays the same views.
    EXPECT_EQ(c.resolved["light"]["path"]["keyframes"][0]["target"], Json::parse("[1.0, 0.0, 2.0]"));
}

struct BadCase {
    const char* name;
    const char* patch;     ///< JSON merged into minimal() (merge_patch)
    const char* path;      ///< expected JSON path in the message
    const char* cause;     ///< expected fragment of the cause
};

const BadCase kBad[] = {
    {"images_frame_twice", R"({"frames": 3, "output": {"images_at_frames": [1, 0, 1]}})", "/output/images_at_frames/2", "listed twice"},
    // Expectations (docs/config.md, `expect`): each entry's problem at its own path.
    {"expect_not_a_list", R"({"expect": {"id": "shadow_map"}})", "/expect", "expected a list"},
    {"expect_unknown_id", R"({"expect": [{"id": "psb", "measure": "overflow", "max": 0}]})", "/expect/0/id", "not an algorithm id"},
    {"expect_unknown_measure", R"({"expect": [{"id": "shadow_map", "measure": "accuracy.mismatch", "max": 0}]})", "/expect/0/measure",
     "is not a measure"},
    {"expect_bad_statistic", R"({"expect": [{"id": "shadow_map", "measure": "time_ms.total.p99", "max": 1}]})", "/expect/0/measure",
     "STAT: mean, median, min or max"},
    {"expect_no_bound", R"({"expect": [{"id": "shadow_map", "measure": "overflow"}]})", "/expect/0/max", "needs \"max\", \"min\""},
    {"expect_min_above_max", R"({"expect": [{"id": "shadow_map", "measure": "overflow", "min": 2, "max": 1}]})", "/expect/0/min",
     "above max"},
    {"expect_relative_to_itself", R"({"expect": [{"id": "shadow_map", "measure": "memory_bytes", "relative_to": "shadow_map", "max": 1}]})",
     "/expect/0/relative_to", "relative to itself"},
    {"expect_relative_to_unknown", R"({"expect": [{"id": "shadow_map", "measure": "memory_bytes", "relative_to": "x", "max": 1}]})",
     "/expect/0/relative_to", "not an algorithm id"},
    {"expect_accuracy_without_reference", R"({"reference": false, "expect": [{"id": "shadow_map", "measure": "accuracy.rmse", "max": 1}]})",
     "/expect/0/measure", "turns off"},
    {"expect_unknown_key", R"({"expect": [{"id": "shadow_map", "measure": "overflow", "max": 0, "maximum": 1}]})", "/expect/0/maximum",
     "accepted keys"},
    {"expect_bound_not_a_number", R"({"expect": [{"id": "shadow_map", "measure": "overflow", "max": "0"}]})", "/expect/0/max", "number"},
    // Fifth probe: ids that differ only in case name one file on a case-insensitive file system.
    {"ids_differ_in_case_only", R"({"algorithms": [{"algorithm": "shadow_map", "id": "SM"}, {"algorithm": "shadow_map", "id": "sm"}]})",
     "/algorithms/1/id", "only in case"},
    {"id_reference_in_another_case", R"({"algorithms": [{"algorithm": "shadow_map", "id": "Reference"}]})", "/algorithms/0/id", "only in case"},
    // Twentieth probe: matplotlib hides a legend label starting with '_', and 1e-400 was read as 0.
    {"id_starting_with_underscore", R"({"algorithms": [{"algorithm": "shadow_map", "id": "_mine"}]})", "/algorithms/0/id",
     "starting with a letter or digit"},
    // Nineteenth probe: an id "scene" replaced the scene's bytes in the memory tables.
    {"id_scene", R"({"algorithms": [{"algorithm": "shadow_map", "id": "scene"}]})", "/algorithms/0/id", "the scene's own entry"},
    {"id_scene_gpu", R"({"algorithms": [{"algorithm": "shadow_map", "id": "scene_gpu"}]})", "/algorithms/0/id", "the scene's own entry"},
    {"unknown_top_key", R"({"framez": 3})", "/framez", "accepted keys"},
    // Seventh probe: an integer written as a float was taken by frames but not by resolution; both take
    // it now, and a fraction is refused by both.
    {"resolution_with_a_fraction", R"({"resolution": [100.5, 32]})", "/resolution", "expected integers"},
    // Seventh probe: keys the file did not use (expect, repeats) were missing from the list.
    {"unknown_key_lists_unused_keys", R"({"framez": 3})", "/framez", "expect, frames, light, name, output, reference, repeats"},
    {"wrong_type", R"({"frames": "ten"})", "/frames", "expected an integer"},
    {"out_of_range", R"({"resolution": [0, 64]})", "/resolution", "must lie in"},
    {"unknown_algorithm", R"({"algorithms": [{"algorithm": "magic"}]})", "/algorithms/0/algorithm", "registered: shadow_map"},
    {"unknown_param", R"({"algorithms": [{"algorithm": "shadow_map", "params": {"resolutoin": 512}}]})",
     "/algorithms/0/params/resolutoin", "accepted keys"},
    {"param_out_of_range", R"({"algorithms": [{"algorithm": "shadow_map", "params": {"pcf": 99}}]})",
     "/algorithms/0/params/pcf", "out of range"},
    {"duplicate_id", R"({"algorithms": [{"algorithm": "shadow_map"}, {"algorithm": "shadow_map"}]})", "/algorithms/1/id",
     "duplicate id"},
    {"unsupported_light", R"({"light": {"type": "area"}})", "/algorithms/0/algorithm", "does not support area"},
    {"bad_light_type", R"({"light": {"type": "laser"}})", "/light/type", "accepted: point, spot"},
    {"image_frame_outside", R"({"frames": 5, "output": {"images_at_frames": [7]}})", "/output/images_at_frames/0", "outside"},
    {"unknown_camera_key", R"({"camera": {"fov": 60}})", "/camera/fov", "accepted keys"},
    {"keyframes_not_increasing", R"({"camera": {"path": {"keyframes": [{"time": 1, "position": [0,0,0]}, {"time": 1, "position": [1,0,0]}]}}})",
     "/camera/path/keyframes/1/time", "increase"},
    {"keyframe_missing_position", R"({"light": {"path": {"keyframes": [{"time": 0}]}}})", "/light/path/keyframes/0/position",
     "missing"},
    {"unknown_scene_object_key", R"({"scene": {"objects": [{"procedural": "sphere", "radiuss": 1}]}})", "/scene/objects/0/radiuss",
     "accepted keys"},
    {"no_scene_objects", R"({"scene": {"objects": []}})", "/scene", "no objects"},
};

class ConfigErrorTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(ConfigErrorTest, NamesFilePathAndCause) {
    const BadCase& c = GetParam();
    Json j = minimal();
    j.merge_patch(Json::parse(c.patch));
    try {
        parseConfig(j, "configs/bad.json");
        FAIL() << "accepted a bad config";
    } catch (const InputError& e) {
        std::string msg = e.what();
        EXPECT_EQ(msg.rfind("configs/bad.json: at ", 0), 0u) << msg;
        EXPECT_NE(msg.find(c.path), std::string::npos) << msg;
        EXPECT_NE(msg.find(c.cause), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "error must be one line: " << msg;
    }
}

INSTANTIATE_TEST_SUITE_P(Table, ConfigErrorTest, ::testing::ValuesIn(kBad), [](const auto& info) { return std::string(info.param.name); });

TEST(ConfigTest, InvalidJsonFileNamesTheFile) {
    EXPECT_THROW(
        {
            try {
                JsonNode::parseFile(std::string(SHADOWLAB_TEST_DATA) + "/broken.json");
            } catch (const InputError& e) {
                EXPECT_NE(std::string(e.what()).find("broken.json"), std::string::npos);
                EXPECT_NE(std::string(e.what()).find("invalid JSON"), std::string::npos);
                throw;
            }
        },
        InputError);
}

} // namespace
} // namespace shadowlab

namespace shadowlab {
namespace {

TEST(ConfigOverrideTest, ArrayIndicesAreDigitsWithinTheArray) {
    // Each is bad input naming the path walked, never a number parser's exception (exit 1).
    for (const char* bad : {"algorithms.-1.id=x", "algorithms.+0.id=x", "algorithms.100000000000000000000.id=x",
                            "algorithms.1e3.id=x", "algorithms.2.id=x", "algorithms.0x1.id=x"}) {
        Json cfg = {{"algorithms", Json::array({{{"algorithm", "psv"}}, {{"algorithm", "ptsv"}}})}};
        try {
            applyOverride(cfg, bad);
            ADD_FAILURE() << bad << " accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), "--set") << bad;
            EXPECT_NE(e.cause().find("no element"), std::string::npos) << bad << ": " << e.what();
        }
    }
    Json cfg = {{"algorithms", Json::array({{{"algorithm", "psv"}}, {{"algorithm", "ptsv"}}})}};
    applyOverride(cfg, "algorithms.1.id=second");
    EXPECT_EQ(cfg["algorithms"][1]["id"], "second");
}

// Twelfth probe: "cone_deg": 0.1 was out of its own range [0.1, 89] (the bound was the float
// 0.100000001); the bounds a message prints can be entered.
TEST(ConfigOverrideTest, TheBoundsOfARangeAreInIt) {
    Json cfg = {{"scene", {{"objects", Json::array({{{"procedural", "plane"}}})}}},
                {"light", {{"type", "spot"}, {"cone_deg", 0.1}, {"position", {0, 4, 0}}}},
                {"camera", {{"fov_y_deg", 1}}}};
    const ExperimentConfig c = parseConfig(cfg, "c.json", false);
    EXPECT_FLOAT_EQ(c.light.coneDeg, 0.1f);
    cfg["light"]["cone_deg"] = 89;
    cfg["camera"]["fov_y_deg"] = 179;
    EXPECT_NO_THROW(parseConfig(cfg, "c.json", false));
}

// Eleventh probe: a list holding a number past a double (1e400) did not parse, was taken as bare
// text, and was reported as "expected a list". Text that starts as JSON must be JSON: its parse
// error is the cause; bare words stay strings.
TEST(ConfigOverrideTest, AValueThatStartsAsJsonMustParseAndNamesItsCause) {
    Json cfg = {{"expect", Json::array()}};
    for (const char* bad : {"expect=[{\"id\": \"psv\", \"max\": 1e400}]", "frames=1e400", "name=\"open", "resolution=[64,"}) {
        try {
            applyOverride(cfg, bad);
            ADD_FAILURE() << bad << " accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), "--set") << bad;
            EXPECT_EQ(e.cause().find("expected a list"), std::string::npos) << bad << ": " << e.what();
        }
    }
    try {
        applyOverride(cfg, "frames=1e400");
    } catch (const InputError& e) {
        EXPECT_NE(e.cause().find("does not fit in a double"), std::string::npos) << e.what();
        EXPECT_EQ(e.jsonPath(), "frames");
    }
    applyOverride(cfg, "light.type=directional");
    EXPECT_EQ(cfg["light"]["type"], "directional");
}

} // namespace
} // namespace shadowlab
