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

/// The one record of `kind` ("visibility", "shaded", "diff") in an id's compared images.
const Json& image(const Json& images, const std::string& kind) {
    for (const Json& im : images)
        if (im["image"] == kind) return im;
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
    // Frame 2's visibility, shaded and difference images: each changed where psv wrote lit.
    ASSERT_EQ(psv["images"].size(), 3u) << psv["images"].dump();
    for (const char* kind : {"visibility", "shaded", "diff"}) {
        EXPECT_GT(image(psv["images"], kind)["changed_pixels"].get<size_t>(), 0u) << kind;
        EXPECT_TRUE(image(psv["images"], kind).contains("picture")) << kind;
    }
    EXPECT_EQ(psv["regressions"].size(), 2u) << psv["regressions"].dump();
    // bvh_raytrace is untouched: its image and accuracy are the same. Its absolute time (and the
    // reference's) is left to the relative comparison below: two runs under a loaded ctest -j2
    // differed past the threshold (a failure of this test, not of compare;
    // results/reference/compare_noise_llvmpipe.md). So every other regression is a time's.
    const Json& bvh = record(c, "bvh_raytrace");
    EXPECT_NE(bvh["accuracy"]["verdict"], "worse") << bvh.dump(2);
    ASSERT_EQ(bvh["images"].size(), 3u) << bvh["images"].dump();
    for (const Json& im : bvh["images"]) EXPECT_EQ(im["changed_pixels"], 0u) << im.dump();
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
// Probe 25: only the visibility images were read, so a lost, broken or changed shaded or
// difference image went unreported; every saved image is compared now.
TEST_F(CompareGLTest, ImagesThatCannotBeComparedAreNamed) {
    const std::string dir = test::makeTempDir("compare-images");
    runInto(dir + "/base");
    std::filesystem::copy(dir + "/base", dir + "/broken", std::filesystem::copy_options::recursive);
    std::filesystem::resize_file(dir + "/broken/images/psv_f0002_visibility.png", 200);
    std::filesystem::remove(dir + "/broken/images/bvh_raytrace_f0002_visibility.png");
    std::filesystem::resize_file(dir + "/broken/images/psv_f0002_shaded.png", 100);
    std::filesystem::remove(dir + "/broken/images/bvh_raytrace_f0002_diff.png");
    // Another run's image in place of one: the same size, other pixels.
    std::filesystem::copy_file(dir + "/base/images/psv_f0002_visibility.png", dir + "/broken/images/bvh_raytrace_f0002_shaded.png",
                               std::filesystem::copy_options::overwrite_existing);
    // Probe 26: heat maps were never compared. A heat map saved by both (here the visibility and
    // shaded images under its name: other pixels) and one saved by BASE only.
    std::filesystem::copy_file(dir + "/base/images/psv_f0002_diff.png", dir + "/base/images/psv_f0002_heat_nodes_visited.png");
    std::filesystem::copy_file(dir + "/base/images/psv_f0002_visibility.png", dir + "/broken/images/psv_f0002_heat_nodes_visited.png");
    std::filesystem::copy_file(dir + "/base/images/psv_f0002_diff.png", dir + "/base/images/psv_f0002_heat_stack_overflow.png");
    // A file whose "name" is markup is no heat map of ours: not read, never written into the report.
    std::filesystem::copy_file(dir + "/base/images/psv_f0002_diff.png", dir + "/broken/images/psv_f0002_heat_x)![a](b.png");
    const Comparison c = compareRuns(dir + "/base", dir + "/broken", {});
    auto noted = [&](const std::string& id, const std::string& kind) {
        const Json& im = image(record(c, id)["images"], kind);
        EXPECT_TRUE(im["changed_pixels"].is_null()) << id << " " << kind;
        EXPECT_NE(im.value("note", "").find("NEW's image " + id + "_f0002_" + kind + ".png"), std::string::npos) << im.dump();
    };
    noted("psv", "visibility");
    noted("psv", "shaded");
    noted("bvh_raytrace", "visibility");
    noted("bvh_raytrace", "diff");
    EXPECT_GT(image(record(c, "psv")["images"], "heat_nodes_visited")["changed_pixels"].get<size_t>(), 0u) << record(c, "psv")["images"].dump();
    noted("psv", "heat_stack_overflow");
    for (const Json& im : record(c, "psv")["images"]) EXPECT_EQ(im["image"].get<std::string>().find('!'), std::string::npos) << im.dump();
    EXPECT_GT(image(record(c, "bvh_raytrace")["images"], "shaded")["changed_pixels"].get<size_t>(), 0u);
    EXPECT_EQ(image(record(c, "psv")["images"], "diff")["changed_pixels"], 0u);
    const std::string md = comparisonMarkdown(c, dir + "/base", dir + "/broken", {});
    EXPECT_NE(md.find("psv frame 2 visibility: image not compared"), std::string::npos) << md;
    EXPECT_NE(md.find("psv frame 2 shaded: image not compared"), std::string::npos) << md;
    EXPECT_NE(md.find("bvh_raytrace frame 2 diff: image not compared"), std::string::npos) << md;
    EXPECT_NE(md.find("bvh_raytrace frame 2 shaded: "), std::string::npos) << md;
}

} // namespace
} // namespace shadowlab
