// izb (the irregular z-buffer) on OSMesa: against the Embree reference on the hard scenes shared
// with shadow_volumes (a light amid clutter, grazing light over thin geometry, open meshes, soups,
// non-manifold fins, the engine) under point, spot and directional lights, grid sizes and the
// conservative cell test; its job list and list walks overflowing, reported and never lighting a
// pixel by mistake.
#include "algorithms/izb/Izb.h"
#include "tests/AlgorithmHarness.h"
#include "tests/TestSupport.h"

#include <cstdio>

namespace shadowlab {
namespace {

using namespace test;

// izb tests each listed sample with the reference's own ray and watertight test, against every
// triangle whose conservative footprint covers the sample's cell: exact by construction. Every row
// is held to 1e-4 of the lit pixels, which at 96² (4,000 to 9,000 lit pixels) is no wrong pixel.
const std::vector<AccuracyCase> kAccuracy = hardSceneTable(1e-4, {
    // Grids: the auto one at 96² is the coarsest, 64 cells a side (long lists); finer ones (a few
    // samples per cell); every cell of a footprint's box tested (no conservative rasterisation):
    // the same image, different work.
    {"grid_256_clutter", lightAmidClutter, {{"grid", 256}}, 1e-4},
    {"grid_1024_thousands", thousandsOfTriangles, {{"grid", 1024}}, 1e-4},
    {"grid_1024_directional", directionalObjects, {{"grid", 1024}}, 1e-4},
    {"no_cell_test_clutter", lightAmidClutter, {{"cell_test", false}}, 1e-4},
    {"no_cell_test_grazing", grazingOverThin, {{"cell_test", false}}, 1e-4},
    // Each face's grid fitted to its samples' box instead of over the whole face.
    {"fit_samples_clutter", lightAmidClutter, {{"grid_fit", std::string("samples")}}, 1e-4},
    {"fit_samples_directional", directionalObjects, {{"grid_fit", std::string("samples")}}, 1e-4},
    {"fit_samples_camera_inside", cameraInsideShadow, {{"grid_fit", std::string("samples")}}, 1e-4},
    {"fit_samples_grazing", grazingOverThin, {{"grid_fit", std::string("samples")}}, 1e-4},
    {"fit_samples_engine", engineOnGround, {{"grid_fit", std::string("samples")}}, 1e-4},
});

class IzbGLTest : public GLTest {};
class IzbAccuracyGLTest : public GLTest, public ::testing::WithParamInterface<AccuracyCase> {};

TEST_P(IzbAccuracyGLTest, MatchesReference) {
    const AccuracyCase& c = GetParam();
    const AlgorithmRun o = runAlgorithm(izbInfo(), c.make(), c.params);
    std::printf("[izb] %-24s lit %5zu mismatch %.5f%% (false lit %.5f%%) samples %.0f jobs %.0f tests/sample %.1f "
                "list max %.0f\n",
                c.name, o.accuracy.litPixels, 100 * o.accuracy.mismatchRatio, 100 * o.accuracy.falseLit,
                o.counters.at("samples"), o.counters.at("jobs"), o.counters.at("tests_per_sample"), o.counters.at("list_max"));
    expectAccurateRow(o, c.maxMismatch);
}

INSTANTIATE_TEST_SUITE_P(Table, IzbAccuracyGLTest, ::testing::ValuesIn(kAccuracy),
                         [](const auto& info) { return std::string(info.param.name); });

// Every pixel that differs from the reference is written shadowed (never lit by mistake), and the
// overflow counts at least as many pixels as differ.
void expectLostWorkShadowed(const AlgorithmRun& o, const char* what) {
    size_t wrong = 0;
    for (size_t i = 0; i < o.lit.size(); ++i)
        if (o.lit[i] && (o.visibility[i] < 0.5f) != (o.reference[i] < 0.5f)) {
            ++wrong;
            EXPECT_LT(o.visibility[i], 0.5f) << what << ": pixel " << i << " lit by mistake";
        }
    std::printf("[izb] %s: overflow %llu pixels, %zu differ from the reference\n", what, (unsigned long long)o.overflow, wrong);
    EXPECT_GT(o.overflow, 0u) << what;
    EXPECT_GE(o.overflow, uint64_t(wrong)) << what;
    EXPECT_EQ(o.accuracy.falseLit, 0.0) << what;
}

// A job list of 1,024 (triangle, tile) jobs on the engine, which asks for far more: the tiles left
// out are flagged, and their samples written shadowed and counted.
TEST_F(IzbGLTest, FullJobListLosesTilesThatAreWrittenShadowed) {
    const AlgorithmRun o = runAlgorithm(izbInfo(), lightAmidClutter(), {{"job_capacity", 8192}});
    EXPECT_GT(o.counters.at("lost_tiles"), 0.0);
    EXPECT_GT(o.counters.at("jobs"), 1024.0);
    expectLostWorkShadowed(o, "job_capacity 1024");
}

// A walk of at most 16 samples per cell and triangle where the roof's shadow puts hundreds of
// samples in one cell (cameraInsideShadow: 451 at most): the capped cells' samples are written
// shadowed and counted.
TEST_F(IzbGLTest, CappedListWalksAreWrittenShadowed) {
    const AlgorithmRun o = runAlgorithm(izbInfo(), cameraInsideShadow(), {{"walk_cap", 16}});
    EXPECT_GT(o.counters.at("capped_cells"), 0.0);
    expectLostWorkShadowed(o, "walk_cap 16");
}

// A job counter that wraps after capacity + 64 pushes instead of 2^32 (a fault site, test-only: the
// wrap a flood of pushes, ~1,000 times the capacity, would cause) must not hand out the slots of
// live jobs again: the pushes past capacity are taken back, every tile left out is flagged and
// written shadowed.
TEST_F(IzbGLTest, FaultPushFloodOverwritesNoJob) {
    ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_PUSH_FLOOD", "1"}});
    const AlgorithmRun o = runAlgorithm(izbInfo(), lightAmidClutter(), {{"job_capacity", 8192}});
    EXPECT_GT(o.counters.at("lost_tiles"), 0.0);
    expectLostWorkShadowed(o, "job_capacity 8192, flooded");
}

// A GPU may flush a stored denormal and canonicalise a stored NaN (a fault site, test-only, at every
// float izb stores): the samples facing away from the light or outside the spot's cone, and those
// in the first 2^23 cells of face 0, must keep their cell, or a pixel the light does not reach
// is written lit.
TEST_F(IzbGLTest, FaultFloatStorageKeepsEveryPixelExact) {
    ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_FLOAT_STORAGE", "1"}});
    for (LightType light : {LightType::Point, LightType::Spot, LightType::Directional}) {
        SCOPED_TRACE(toString(light));
        const AlgorithmRun o = runAlgorithm(izbInfo(), withLight(lightAmidClutter(), light), {});
        EXPECT_EQ(o.overflow, 0u);
        EXPECT_EQ(o.accuracy.mismatchRatio, 0.0);
        // The metrics compare the pixels the light reaches; the rest must stay unlit too.
        size_t unreachedLit = 0;
        for (size_t i = 0; i < o.visibility.size(); ++i) unreachedLit += o.reference[i] == 0.0f && o.visibility[i] > 0.0f;
        EXPECT_EQ(unreachedLit, 0u) << "pixels the light does not reach written lit";
    }
}

} // namespace
} // namespace shadowlab
