// A run that meets a GL error saves nothing: sixth probe, a run whose allocations failed
// (GL_OUT_OF_MEMORY) committed a summary saying "complete": true, and a sweep then merged it.
#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/experiment/Config.h"
#include "framework/experiment/Runner.h"
#include "framework/gl/GlContext.h"
#include "tests/TestSupport.h"

#include <filesystem>

namespace shadowlab {
namespace {

using test::GLTest;

Json smallConfig() {
    return {{"name", "integrity"},
            {"resolution", {32, 32}},
            {"frames", 2},
            {"warmup_frames", 0},
            {"scene", {{"objects", Json::array({{{"procedural", "plane"}, {"size", {8, 8}}},
                                                {{"procedural", "sphere"}, {"radius", 0.8}, {"transform", {{"translate", {0, 1.0, 0}}}}}})}}},
            {"camera", {{"position", {0.5, 5, 4}}, {"target", {0, 0, 0}}}},
            {"light", {{"type", "point"}, {"position", {0.7, 5, 0.4}}}},
            {"algorithms", Json::array({{{"algorithm", "psv"}}})},
            {"output", {{"plots", false}}}};
}

class RunIntegrityGLTest : public GLTest {};

TEST_F(RunIntegrityGLTest, AGlErrorStopsTheRunAndThePreviousResultsStay) {
    const std::string dir = test::makeTempDir("gl-error");
    ExperimentConfig cfg = parseConfig(smallConfig(), dir + "/c.json");
    RunOptions opt;
    opt.progress = false;
    opt.outputDir = dir + "/out";
    runExperiment(cfg, opt, "osmesa");
    const std::string before = readInputFile(dir + "/out/summary.json");
    opt.force = true;
    {
        test::ScopedShaderFaults fault(ShaderDefines{{"SHADOWLAB_FAULT_GL_ERROR", "1"}});
        ExperimentConfig faulted = parseConfig(smallConfig(), dir + "/c.json");
        try {
            runExperiment(faulted, opt, "osmesa");
            FAIL() << "a run with a GL error completed";
        } catch (const RuntimeError& e) {
            EXPECT_NE(std::string(e.what()).find("OpenGL error(s) during the run"), std::string::npos) << e.what();
        }
    }
    EXPECT_GT(glErrorCount(), 0);
    resetGlErrors();  // the planted error, expected
    EXPECT_EQ(readInputFile(dir + "/out/summary.json"), before);
    for (const auto& e : std::filesystem::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
}

} // namespace
} // namespace shadowlab
