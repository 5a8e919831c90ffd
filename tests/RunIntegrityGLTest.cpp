// A run that meets a GL error saves nothing: sixth probe, a run whose allocations failed
// (GL_OUT_OF_MEMORY) committed a summary saying "complete": true, and a sweep then merged it.
#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/experiment/Config.h"
#include "framework/experiment/Runner.h"
#include "framework/gl/GlContext.h"
#include "tests/SmallExperiment.h"
#include "tests/TestSupport.h"

#include <filesystem>

namespace shadowlab {
namespace {

using test::GLTest;

Json smallConfig() {
    Json c = test::sphereOverPlane("integrity");
    c["resolution"] = {32, 32};
    c["frames"] = 2;
    c["warmup_frames"] = 0;
    c["algorithms"] = Json::array({{{"algorithm", "psv"}}});
    c["statistics"] = "images";
    return c;
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
