// Honest timing by default: the timed frames of an experiment never run instrumented shaders, and
// the counters and heat maps come from a separate, untimed statistics pass. The check is structural
// (which counters each pass reports, what files hold them), not a stopwatch, so it holds on a
// loaded machine: a timed frame that ran instrumented would report the statistics-only counters.
#include "framework/algorithm/AlgorithmHost.h"
#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/experiment/Config.h"
#include "framework/experiment/Runner.h"
#include "tests/TestSupport.h"

#include <filesystem>
#include <set>
#include <string>

namespace shadowlab {
namespace {

using test::GLTest;

Json smallConfig(const std::string& statistics) {
    Json cfg = {{"name", "honest"},
                {"resolution", {48, 48}},
                {"frames", 3},
                {"warmup_frames", 1},
                {"scene", {{"objects", Json::array({{{"procedural", "plane"}, {"size", {8, 8}}},
                                                    {{"procedural", "sphere"}, {"radius", 0.6}, {"transform", {{"translate", {0, 0.8, 0}}}}}})}}},
                {"camera", {{"position", {0.5, 5, 4}}, {"target", {0, 0, 0}}, {"fov_y_deg", 60}}},
                {"light", {{"type", "point"}, {"position", {0.7, 5, 0.4}}}},
                {"algorithms", Json::array({{{"algorithm", "psv"}},
                                            {{"algorithm", "metric_tree"}, {"params", {{"cache", false}}}},
                                            {{"algorithm", "ptsv"}},
                                            {{"algorithm", "bvh_raytrace"}}})},
                {"output", {{"plots", false}, {"images_at_frames", {1}}}}};
    if (!statistics.empty()) cfg["statistics"] = statistics;
    return cfg;
}

ExperimentResults run(const Json& json, const std::string& dir, bool write) {
    ExperimentConfig cfg = parseConfig(json, dir + "/cfg.json");
    RunOptions opt;
    opt.writeOutputs = write;
    opt.progress = false;
    opt.outputDir = dir + "/out";
    return runExperiment(cfg, opt, "osmesa");
}

std::set<std::string> counterNames(const FrameRecord& f) {
    std::set<std::string> out;
    for (const auto& [k, v] : f.counters) out.insert(k);
    return out;
}

std::string slurp(const std::string& path) { return readInputFile(path); }

class HonestTimingGLTest : public GLTest {};

TEST_F(HonestTimingGLTest, TimedFramesNeverCarryTheStatisticsPassCounters) {
    const std::string dir = test::makeTempDir("honest");
    const ExperimentResults all = run(smallConfig("all"), dir, false);
    const ExperimentResults none = run(smallConfig("none"), dir, false);
    ASSERT_EQ(all.algorithms.size(), none.algorithms.size());
    size_t instrumentedOnly = 0;
    for (size_t i = 0; i < all.algorithms.size(); ++i) {
        const AlgorithmResults& a = all.algorithms[i];
        const AlgorithmResults& n = none.algorithms[i];
        SCOPED_TRACE(a.id);
        ASSERT_EQ(a.frames.size(), 3u);
        ASSERT_EQ(a.statistics.size(), 3u) << "statistics: all runs the pass on every frame";
        EXPECT_TRUE(n.statistics.empty()) << "statistics: none runs no pass";
        EXPECT_TRUE(a.visibilityDiffers.empty()) << "the statistics changed the image";
        for (size_t f = 0; f < a.frames.size(); ++f) {
            const std::set<std::string> timed = counterNames(a.frames[f]), stats = counterNames(a.statistics[f]);
            // The timed pass reports the same counters whether or not a statistics pass ran in the
            // same experiment (statistics: none never creates an instrumented host)...
            EXPECT_EQ(timed, counterNames(n.frames[f])) << "frame " << f;
            // ...and the statistics pass reports more: the counters that need the instrumented shaders.
            for (const std::string& name : timed) EXPECT_TRUE(stats.count(name)) << name << " missing from the statistics pass";
            for (const std::string& name : stats) instrumentedOnly += !timed.count(name);
            EXPECT_EQ(a.frames[f].overflow, n.frames[f].overflow);
            ASSERT_TRUE(a.frames[f].hasAccuracy);
            EXPECT_EQ(a.frames[f].accuracy.mismatchRatio, n.frames[f].accuracy.mismatchRatio);
        }
    }
    EXPECT_GT(instrumentedOnly, 0u) << "no algorithm reported a statistics-only counter: the pass measured nothing";
}

TEST_F(HonestTimingGLTest, SummarySaysWhichPassEachNumberCameFrom) {
    const std::string dir = test::makeTempDir("honest_files");
    run(smallConfig(""), dir, true);  // the default: statistics over images_at_frames
    const std::string out = dir + "/out";
    const Json s = Json::parse(slurp(out + "/summary.json"));
    EXPECT_EQ(s["statistics"], "images");
    EXPECT_EQ(s["statistics_frames"], Json::array({1}));
    EXPECT_FALSE(s.contains("timing_mode"));
    for (const auto& [id, a] : s["algorithms"].items()) {
        SCOPED_TRACE(id);
        EXPECT_EQ(a["counters_source"], "statistics_pass");
        EXPECT_EQ(a["statistics_pass"]["frames"], Json::array({1}));
        EXPECT_TRUE(a["statistics_pass"]["time_ms"].contains("total"));
        EXPECT_TRUE(a["statistics_pass"]["visibility_differs_frames"].empty());
    }
    // Timed rows and statistics rows live in different files; heat maps exist for the image frame,
    // and they come from the statistics pass (a timed host has no debug views).
    EXPECT_TRUE(std::filesystem::exists(out + "/frames.csv"));
    const std::string stats = slurp(out + "/statistics.csv");
    EXPECT_NE(stats.find("nodes_visited"), std::string::npos);
    EXPECT_TRUE(std::filesystem::exists(out + "/images/psv_f0001_heat_nodes_visited.png"));
    const std::string report = slurp(out + "/report.md");
    EXPECT_NE(report.find("statistics compiled out"), std::string::npos);
    EXPECT_NE(report.find("untimed statistics pass"), std::string::npos);

    // statistics: none: no pass, no statistics.csv, counters said to be the timed pass's.
    const std::string dirNone = test::makeTempDir("honest_none");
    run(smallConfig("none"), dirNone, true);
    const Json sn = Json::parse(slurp(dirNone + "/out/summary.json"));
    EXPECT_EQ(sn["statistics_frames"], Json::array());
    EXPECT_EQ(sn["algorithms"]["psv"]["counters_source"], "timed_pass");
    EXPECT_FALSE(sn["algorithms"]["psv"].contains("statistics_pass"));
    EXPECT_FALSE(std::filesystem::exists(dirNone + "/out/statistics.csv"));
    EXPECT_FALSE(std::filesystem::exists(dirNone + "/out/images/psv_f0001_heat_nodes_visited.png"));
}

TEST(HonestTimingConfigTest, RetiredTimingModeKeyIsRefusedWithWhereToGo) {
    Json cfg = smallConfig("");
    cfg["timing_mode"] = true;
    try {
        parseConfig(cfg, "cfg.json", false);
        FAIL() << "timing_mode accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.jsonPath(), "/timing_mode");
        EXPECT_NE(e.cause().find("statistics"), std::string::npos);
    }
    cfg.erase("timing_mode");
    cfg["statistics"] = "some";
    EXPECT_THROW(parseConfig(cfg, "cfg.json", false), InputError);
}

} // namespace
} // namespace shadowlab
