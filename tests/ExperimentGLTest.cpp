// End-to-end: the shadowlab binary runs configs headless on OSMesa; outputs are complete and
// parseable, and each algorithm agrees with the reference within the thresholds of kAccuracy.
#include "framework/core/JsonNode.h"
#include "tests/TestSupport.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// Config files are named relative to the source tree (configs/… or tests/data/…), optionally
/// followed by `--set` overrides (e.g. the demo at a test-sized resolution).
std::string configPath(const std::string& name) { return std::string(SHADOWLAB_SOURCE_DIR) + "/" + name; }

/// Runs `shadowlab run CONFIG --out DIR` once per config for the whole test binary.
const Json& runOnce(const std::string& config, std::string* dirOut = nullptr) {
    static std::map<std::string, std::pair<std::string, Json>> cache;
    auto it = cache.find(config);
    if (it == cache.end()) {
        std::string dir = test::makeTempDir("exp") + "/out";
        std::string out;
        int rc = test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + configPath(config) + " --no-progress --out " + dir, out);
        EXPECT_EQ(rc, 0) << out;
        Json summary = fs::exists(dir + "/summary.json") ? Json::parse(slurp(dir + "/summary.json")) : Json::object();
        it = cache.emplace(config, std::make_pair(dir, summary)).first;
    }
    if (dirOut) *dirOut = it->second.first;
    return it->second.second;
}

/// configs/smoke.json writes every output: the files, the device record, resolved parameters,
/// per-stage times, images and a parseable frames.csv.
void expectEveryOutputOfTheSmokeRun() {
    std::string dir;
    const Json& s = runOnce("configs/smoke.json", &dir);
    ASSERT_TRUE(s.value("complete", false));
    for (const char* f : {"config.resolved.json", "frames.csv", "summary.json", "report.md", "plot_frame_time.png",
                          "plot_accuracy.png", "plot_stages.png"})
        EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
    EXPECT_FALSE(s["renderer"].get<std::string>().empty());
    EXPECT_GT(s["triangles"].get<size_t>(), 1000u);
    // The device record: the same strings as the older top-level keys, limits and extensions.
    const Json& device = s["device"];
    ASSERT_TRUE(device.is_object());
    EXPECT_EQ(device["renderer"], s["renderer"]);
    EXPECT_EQ(device["version"], s["gl_version"]);
    EXPECT_EQ(device["backend"], s["backend"]);
    EXPECT_EQ(device["subgroup_size"], s["subgroup_size"]);
    for (const char* key : {"vendor", "glsl_version"}) EXPECT_FALSE(device[key].get<std::string>().empty()) << key;
    EXPECT_GT(device["limits"]["GL_MAX_SHADER_STORAGE_BLOCK_SIZE"].get<long long>(), 0);
    EXPECT_EQ(device["limits"]["GL_MAX_COMPUTE_WORK_GROUP_SIZE"].size(), 3u);
    EXPECT_TRUE(device["extensions"]["GL_ARB_shader_ballot"].is_boolean());
    // What each entry's auto parameters came to; ptsv's split depth is a number once it has run.
    for (const auto& [id, a] : s["algorithms"].items()) EXPECT_TRUE(a["resolved_params"].is_object()) << id;
    for (const auto& [id, a] : s["algorithms"].items()) {
        if (a["algorithm"] == "ptsv") {
            EXPECT_NE(a["resolved_params"]["traversal"], "auto");
            const std::string split = a["resolved_params"]["split_level"].get<std::string>();
            EXPECT_TRUE(!split.empty() && std::all_of(split.begin(), split.end(), ::isdigit)) << split;
        }
        if (a["algorithm"] == "metric_tree") EXPECT_NE(a["resolved_params"]["tile"], "auto");
    }
    const std::string report = slurp(dir + "/report.md");
    EXPECT_NE(report.find("\n- device: "), std::string::npos);
    EXPECT_NE(report.find("## Parameters resolved on this device"), std::string::npos);
    EXPECT_NE(report.find("traversal = "), std::string::npos);
    // Every registered algorithm appears in the smoke config.
    std::string list;
    ASSERT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " list --json", list), 0);
    for (const auto& a : Json::parse(list)) {
        bool found = false;
        for (const auto& [id, v] : s["algorithms"].items()) found |= v["algorithm"] == a["name"];
        EXPECT_TRUE(found) << a["name"] << " is missing from configs/smoke.json";
    }
    // Per-stage times, counters and memory are present and sane.
    for (const auto& [id, a] : s["algorithms"].items()) {
        ASSERT_TRUE(a["time_ms"].contains("total")) << id;
        EXPECT_GT(a["time_ms"]["total"]["mean"].get<double>(), 0.0) << id;
        EXPECT_GT(a["memory_bytes"].get<size_t>(), 0u) << id;
    }
    // Images at the requested frames: shaded, visibility, and a difference image for non-reference entries.
    EXPECT_TRUE(fs::exists(dir + "/images/shadow_map_f0000_shaded.png"));
    EXPECT_TRUE(fs::exists(dir + "/images/shadow_map_f0003_diff.png"));
    EXPECT_TRUE(fs::exists(dir + "/images/reference_f0000_visibility.png"));
    // frames.csv: header + one row per algorithm × frame × stage, parseable numbers.
    std::istringstream csv(slurp(dir + "/frames.csv"));
    std::string header, line;
    std::getline(csv, header);
    EXPECT_EQ(header.rfind("id,algorithm,frame,stage,gpu_ms,cpu_ms,mismatch_ratio", 0), 0u);
    size_t totals = 0;
    while (std::getline(csv, line))
        if (line.find(",total,") != std::string::npos) ++totals;
    EXPECT_EQ(totals, s["algorithms"].size() * s["frames"].get<size_t>());
    // The resolved config is itself a valid config (every default filled in).
    Json resolved = Json::parse(slurp(dir + "/config.resolved.json"));
    EXPECT_EQ(resolved["resolution"], Json::array({128, 128}));
    EXPECT_TRUE(resolved["algorithms"][0]["params"].contains("pcf"));
}

// Accuracy against the reference on every frame, per config and algorithm id. One test per config:
// ctest runs each test in its own process, so a test per algorithm ran the whole config once per
// algorithm.
struct AccuracyBound {
    const char* id;
    double maxMismatchPerFrame; ///< share of lit pixels
};
struct AccuracyCase {
    const char* name;
    const char* config;
    std::vector<AccuracyBound> bounds;
};
// The README's demo (the engine on a plane, its fly-through and light path) at 128², 4 frames
// spread over the path: the same scene and views as the main job, at a test's cost.
constexpr const char* kDemoSmall = "configs/demo.json --set resolution=[128,128] --set frames=4 --set warmup_frames=1"
                                   " --set output.images_at_frames=[3]";
// The cars passing behind the fence (all three cars move) at a test's cost.
constexpr const char* kCarsSmall = "configs/dynamic/cars_fence.json --set resolution=[96,96] --set frames=4"
                                   " --set warmup_frames=0 --set output.images_at_frames=[3]";

// The reference compared with itself must agree exactly.
constexpr AccuracyBound kReferenceItself{"reference", 0.0};
// Shadow maps are approximate: PCF edges and the depth bias at contact points (fence posts, torus on
// the ground, the engine's feet) flip a fraction of lit pixels (measured ≤ 0.3 % at 128² with 1024²
// maps; ≤ 0.15 % on the demo's frames with 2048², and at 256² on the moving cars); 1 % still catches
// a wrong projection, face or bias sign, which costs tens of percent.
constexpr double kShadowMapBound = 0.01;
// The exact family is required to stay within 0.1 % of lit pixels on every frame; measured 0 on
// every smoke frame and on the moving cars (here and at 256²), ≤ 0.0007 % on the full demo:
// - psv: exact up to float rounding in the plane tests of grazing pixels;
// - bvh_raytrace traces the reference's own rays (same origin offset, watertight triangle test like
//   Embree's robust mode), for hard and soft shadows;
// - ptsv tests the reference's own shadow-ray origins against exact per-triangle volumes; node
//   culling only ever sends work deeper;
// - metric_tree culls conservatively, then casts the reference's own rays against the triangles.
constexpr double kExactBound = 0.001;
// line_space is approximate by design: a ray through a non-empty shaft is decided by the occupied
// leaves it crosses, so shadows grow by up to a leaf, all towards shadow. With (N, d) = (6, 3) and
// the defaults (exact start region, leaves on the last level) that flips 1.1-2.6 % of lit pixels on
// these scenes (measured worst frames: 2.3 % hard, 2.6 % soft); 4 % bounds regressions (the paper's
// Algorithm 1, start_region = node and last_level = shaft, flips 13-17 %). RMSE and the over-/
// under-occluded shares per scene: tests/LineSpaceGLTest.cpp.
constexpr double kLineSpaceBound = 0.04;

const AccuracyCase kAccuracy[] = {
    {"smoke", "configs/smoke.json",
     {kReferenceItself, {"shadow_map", kShadowMapBound}, {"psv", kExactBound}, {"bvh_raytrace", kExactBound},
      {"ptsv", kExactBound}, {"metric_tree", kExactBound}, {"line_space", kLineSpaceBound}}},
    {"lights_spot", "tests/data/lights_spot.json", {{"shadow_map", kShadowMapBound}}},
    {"lights_directional", "tests/data/lights_directional.json", {{"shadow_map", kShadowMapBound}}},
    {"demo_reduced", kDemoSmall,
     {{"sm_2k", kShadowMapBound}, {"psv", kExactBound}, {"bvh_raytrace", kExactBound}, {"ptsv", kExactBound},
      {"metric_tree", kExactBound}}},
    {"soft_smoke", "configs/line_space/soft_smoke.json", {{"bvh_raytrace", kExactBound}, {"line_space", kLineSpaceBound}}},
    // The shipped moving scene, through the binary.
    {"cars_fence_reduced", kCarsSmall,
     {{"psv", kExactBound}, {"metric_tree", kExactBound}, {"ptsv", kExactBound}, {"bvh_raytrace", kExactBound},
      {"shadow_map", kShadowMapBound}}},
};

void PrintTo(const AccuracyCase& c, std::ostream* os) {
    *os << c.config << ":";
    for (const AccuracyBound& b : c.bounds) *os << " " << b.id << " ≤ " << b.maxMismatchPerFrame;
}

class ExperimentGLTest : public ::testing::TestWithParam<AccuracyCase> {};

TEST_P(ExperimentGLTest, AgreesWithReferenceOnEveryFrame) {
    const AccuracyCase& c = GetParam();
    const Json& s = runOnce(c.config);
    ASSERT_TRUE(s.contains("algorithms")) << "no summary";
    for (const AccuracyBound& b : c.bounds) {
        SCOPED_TRACE(b.id);
        ASSERT_TRUE(s["algorithms"].contains(b.id));
        const Json& acc = s["algorithms"][b.id]["accuracy"];
        ASSERT_TRUE(acc.is_object());
        ASSERT_EQ(acc["per_frame_mismatch"].size(), s["frames"].get<size_t>());
        for (size_t f = 0; f < acc["per_frame_mismatch"].size(); ++f)
            EXPECT_LE(acc["per_frame_mismatch"][f].get<double>(), b.maxMismatchPerFrame) << b.id << " frame " << f;
        EXPECT_EQ(s["algorithms"][b.id]["overflow"].get<uint64_t>(), 0u);
    }
    // The smoke run's outputs are checked on the same run.
    if (std::string(c.name) == "smoke") expectEveryOutputOfTheSmokeRun();
}

INSTANTIATE_TEST_SUITE_P(Table, ExperimentGLTest, ::testing::ValuesIn(kAccuracy),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ExperimentOutputGLTest, ExistingOutputIsNeverOverwrittenSilently) {
    std::string dir = test::makeTempDir("keep") + "/out";
    fs::create_directories(dir);
    std::ofstream(dir + "/summary.json") << "{\"earlier\": true}";
    std::string out;
    int rc = test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + configPath("configs/smoke.json") + " --no-progress --out " + dir, out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("--force"), std::string::npos) << out;
    EXPECT_EQ(slurp(dir + "/summary.json"), "{\"earlier\": true}");
}

} // namespace
} // namespace shadowlab
