// `compare` on run folders written by hand (summary.json alone), so that what changed is known:
// frames of one pass get no time verdict, and one id whose time swings between runs does not move
// the '*' yardstick the others are divided by.
#include "framework/experiment/Compare.h"
#include "tests/TestSupport.h"

#include <filesystem>
#include <fstream>

namespace shadowlab {
namespace {

/// An entry with 9 passes around `ms` (±1 %, a fixed pattern) and 4 frames at `ms`.
Json entryAround(double ms, int passes = 9) {
    Json p = Json::array(), frames = Json::array();
    for (int k = 0; k < passes; ++k) p.push_back(ms * (1 + 0.01 * double((k * 7) % 5 - 2) / 2));
    for (int k = 0; k < 4; ++k) frames.push_back(ms * (1 + 0.002 * k));
    Json e = {{"time_ms", {{"total", {{"mean", ms}}}}}, {"total_ms_per_frame", frames}};
    if (passes > 1) e["repetitions"] = {{"count", passes}, {"time_ms", {{"total", p}}}};
    return e;
}

std::string runFolder(const std::string& dir, const Json& algorithms) {
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/summary.json") << Json{{"complete", true}, {"renderer", "llvmpipe"}, {"algorithms", algorithms}}.dump();
    return dir;
}

const Json& totalOf(const Comparison& c, const std::string& id) {
    for (const Json& r : c.records)
        if (r["id"] == id) return r["time"].back();
    static const Json none;
    return none;
}

// Four frames paired gave verdicts, and one build against itself was called slower or faster in
// 1 to 3 of 10 pairs per id: frames of one run say nothing of how two runs differ.
TEST(CompareTest, FramesOfOnePassGetNoTimeVerdict) {
    const std::string dir = test::makeTempDir("compare-frames");
    const std::string base = runFolder(dir + "/base", {{"psv", entryAround(10, 1)}});
    const std::string next = runFolder(dir + "/new", {{"psv", entryAround(13, 1)}});
    const Comparison c = compareRuns(base, next, {});
    EXPECT_EQ(totalOf(c, "psv")["method"], "frames paired");
    EXPECT_NEAR(totalOf(c, "psv")["ratio"].get<double>(), 1.3, 0.01);
    EXPECT_EQ(totalOf(c, "psv")["verdict"], "too few passes");
    EXPECT_EQ(c.regressions, 0u);
}

// Fifteenth probe: a base time of 0 gave a ratio of 0, read as an infinite speed-up. New over 0 is
// no number: no ratio, and no verdict either way; with repetitions too.
TEST(CompareTest, ABaseTimeOfZeroGivesNoRatio) {
    const std::string dir = test::makeTempDir("compare-zero");
    Json zero = entryAround(10, 1);
    zero["time_ms"]["total"]["mean"] = 0.0;
    zero.erase("total_ms_per_frame");
    Json some = entryAround(10, 1);
    some.erase("total_ms_per_frame");
    const Comparison c = compareRuns(runFolder(dir + "/base", {{"psv", zero}}), runFolder(dir + "/new", {{"psv", some}}), {});
    EXPECT_TRUE(totalOf(c, "psv")["ratio"].is_null()) << totalOf(c, "psv");
    EXPECT_EQ(totalOf(c, "psv")["verdict"], "no ratio (base time 0)");
    EXPECT_EQ(c.regressions, 0u);
    EXPECT_NE(comparisonMarkdown(c, dir + "/base", dir + "/new", {}).find("undefined (base 0)"), std::string::npos);
}

// The reference's time swung 3.5x between two runs of one build; as a geometric mean of five ids,
// the '*' yardstick moved by 28 % and every other id looked 22 % faster. As a median it stays.
TEST(CompareTest, OneSwingingIdDoesNotMoveTheMachinesYardstick) {
    const std::string dir = test::makeTempDir("compare-yardstick");
    const Json same = {{"psv", entryAround(10)}, {"izb", entryAround(20)}, {"ptsv", entryAround(30)}, {"metric_tree", entryAround(8)},
                       {"reference", entryAround(1)}};
    Json swung = same;
    swung["reference"] = entryAround(3.5);
    const std::string base = runFolder(dir + "/base", same);
    CompareOptions opt;
    opt.relativeTo = "*";
    const Comparison c = compareRuns(base, runFolder(dir + "/swung", swung), opt);
    for (const char* id : {"psv", "izb", "ptsv", "metric_tree"}) {
        EXPECT_EQ(totalOf(c, id)["verdict"], "within noise") << id << totalOf(c, id).dump();
        EXPECT_NEAR(totalOf(c, id)["ratio"].get<double>(), 1.0, 0.03) << id;
    }
    // A real slowdown beside it (two of five ids changed: the median is still an unchanged one's)
    // is still psv's alone.
    swung["psv"] = entryAround(13);
    const Comparison slowed = compareRuns(base, runFolder(dir + "/slowed", swung), opt);
    EXPECT_EQ(totalOf(slowed, "psv")["verdict"], "slower") << totalOf(slowed, "psv").dump();
    EXPECT_EQ(totalOf(slowed, "izb")["verdict"], "within noise") << totalOf(slowed, "izb").dump();
}

} // namespace
} // namespace shadowlab
