// `compare` on runs written in-process: a run against itself changes nothing; planted regressions
// (a psv that writes a few pixels lit, a psv whose traverse is done many times over) are named,
// and bvh_raytrace, untouched, is not.
#include "framework/experiment/Compare.h"
#include "framework/experiment/Config.h"
#include "framework/experiment/Runner.h"
#include "tests/SmallExperiment.h"
#include "tests/TestSupport.h"

#include <filesystem>

namespace shadowlab {
namespace {

using test::GLTest;

Json comparedConfig() {
    Json c = test::sphereOverPlane("compared");
    c["repeats"] = 5;
    c["output"]["images_at_frames"] = {2};
    return c;
}

void runInto(const std::string& dir) {
    ExperimentConfig cfg = parseConfig(comparedConfig(), dir + ".json");
    RunOptions opt;
    opt.progress = false;
    opt.outputDir = dir;
    runExperiment(cfg, opt, "osmesa");
}

const Json& record(const Comparison& c, const std::string& id) {
    for (const Json& r : c.records)
        if (r["id"] == id) return r;
    static const Json none;
    return none;
}

class CompareGLTest : public GLTest {};

TEST_F(CompareGLTest, PlantedRegressionsAreNamedAndARunAgainstItselfChangesNothing) {
    const std::string dir = test::makeTempDir("compare");
    runInto(dir + "/base");
    {
        test::ScopedShaderFaults fault(ShaderDefines{{"SHADOWLAB_FAULT_PLANTED_LIT", "1"}, {"SHADOWLAB_FAULT_SLOW_TRAVERSE", "100"}});
        runInto(dir + "/planted");
    }
    const Comparison same = compareRuns(dir + "/base", dir + "/base", {});
    EXPECT_EQ(same.regressions, 0u);
    EXPECT_DOUBLE_EQ(record(same, "psv")["time"].back()["ratio"].get<double>(), 1.0);

    CompareOptions opt;
    opt.imagesDir = dir;
    const Comparison c = compareRuns(dir + "/base", dir + "/planted", opt);
    const Json& psv = record(c, "psv");
    ASSERT_TRUE(psv.is_object());
    EXPECT_EQ(psv["time"].back()["stage"], "total");
    EXPECT_EQ(psv["time"].back()["verdict"], "slower") << psv["time"].dump(2);
    EXPECT_EQ(psv["accuracy"]["verdict"], "worse") << psv["accuracy"].dump();
    ASSERT_EQ(psv["images"].size(), 1u);
    EXPECT_GT(psv["images"][0]["changed_pixels"].get<size_t>(), 0u);
    EXPECT_TRUE(psv["images"][0].contains("picture"));
    EXPECT_EQ(psv["regressions"].size(), 2u) << psv["regressions"].dump();
    // bvh_raytrace is untouched: its image and accuracy are the same. Its absolute time (and the
    // reference's) is left to the relative comparison below: two runs under a loaded ctest -j2
    // differed past the threshold (a failure of this test, not of compare;
    // results/reference/compare_noise_llvmpipe.md). So every other regression is a time's.
    const Json& bvh = record(c, "bvh_raytrace");
    EXPECT_NE(bvh["accuracy"]["verdict"], "worse") << bvh.dump(2);
    EXPECT_EQ(bvh["images"][0]["changed_pixels"], 0u);
    size_t others = 0;
    for (const Json& r : c.records) {
        if (r["id"] == "psv") continue;
        others += r["regressions"].size();
        for (const Json& g : r["regressions"]) EXPECT_NE(g.dump().find("time"), std::string::npos) << r.dump(2);
    }
    EXPECT_EQ(c.regressions, 2u + others);
    const std::string junit = comparisonJUnit(c);
    EXPECT_NE(junit.find("failures=\"" + std::to_string(c.regressions) + "\""), std::string::npos) << junit;
    // Relative to the machine's speed in each pass (the median of the ids' scaled totals), the
    // slowdown stays psv's and bvh_raytrace's time is no regression.
    opt.relativeTo = "*";
    const Comparison relative = compareRuns(dir + "/base", dir + "/planted", opt);
    EXPECT_EQ(record(relative, "psv")["time"].back()["verdict"], "slower") << record(relative, "psv")["time"].dump(2);
    EXPECT_EQ(record(relative, "bvh_raytrace")["regressions"].size(), 0u);
}

// Seventh probe: an image compare could not read (truncated, missing, a FIFO, another size) was
// skipped without a word, and the report read as if nothing had changed. Each is now named.
TEST_F(CompareGLTest, ImagesThatCannotBeComparedAreNamed) {
    const std::string dir = test::makeTempDir("compare-images");
    runInto(dir + "/base");
    std::filesystem::copy(dir + "/base", dir + "/broken", std::filesystem::copy_options::recursive);
    std::filesystem::resize_file(dir + "/broken/images/psv_f0002_visibility.png", 200);
    std::filesystem::remove(dir + "/broken/images/bvh_raytrace_f0002_visibility.png");
    const Comparison c = compareRuns(dir + "/base", dir + "/broken", {});
    for (const char* id : {"psv", "bvh_raytrace"}) {
        const Json& images = record(c, id)["images"];
        ASSERT_EQ(images.size(), 1u) << id;
        EXPECT_TRUE(images[0]["changed_pixels"].is_null()) << id;
        EXPECT_NE(images[0]["note"].get<std::string>().find("NEW's image " + std::string(id) + "_f0002_visibility.png"), std::string::npos)
            << images.dump();
    }
    const std::string md = comparisonMarkdown(c, dir + "/base", dir + "/broken", {});
    EXPECT_NE(md.find("psv frame 2: images not compared"), std::string::npos) << md;
    EXPECT_NE(md.find("bvh_raytrace frame 2: images not compared"), std::string::npos) << md;
}

} // namespace
} // namespace shadowlab
