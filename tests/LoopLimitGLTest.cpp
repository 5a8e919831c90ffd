// A loop the device ends before its count: llvmpipe (and lavapipe, the same code generator) ends
// the loops of one shader invocation after 65,535 iterations in all, silently (gallivm's loop
// limiter). The template plugin's loop over every triangle, in scene order on the engine (its
// ground first, so a lit ground point tests all 110k triangles), runs into it there: every ray cut
// short must be counted and taken as blocked, so no pixel is lit by mistake. On a device without
// the limit the image is simply exact.
#include "algorithms/template/Template.h"
#include "tests/AlgorithmHarness.h"
#include "tests/TestSupport.h"

#include <cstdio>

namespace shadowlab {
namespace {

using namespace test;

class LoopLimitGLTest : public GLTest {};

TEST_F(LoopLimitGLTest, LoopsEndedByTheDeviceAreCountedAndNeverLightAPixel) {
    RunOptions options;
    options.resolution = 48; // every lit pixel tests up to 110k triangles on the CPU
    const AlgorithmRun o = runAlgorithm(templateInfo(), engineOnGround(), {{"largest_first", false}}, options);
    std::printf("[template] engine in scene order at 48²: %.0f rays cut short, mismatch %.3f%% (false lit %.5f%%)\n",
                o.counters.at("loop_capped_rays"), 100 * o.accuracy.mismatchRatio, 100 * o.accuracy.falseLit);
    EXPECT_EQ(o.accuracy.falseLit, 0.0);
    EXPECT_EQ(o.overflow, uint64_t(o.counters.at("loop_capped_rays")));
    if (o.overflow == 0) EXPECT_EQ(o.accuracy.mismatchRatio, 0.0);
}

} // namespace
} // namespace shadowlab
