// bvh_raytrace on OSMesa: the same shadow rays as the Embree reference, so hard shadows must agree
// on all but a handful of pixels (≤ 0.1 % of lit pixels) and soft shadows sample for sample; a tiny
// stack must be reported and never light a pixel; the counters describe the traversal.
#include "algorithms/bvh_raytrace/BvhRaytrace.h"
#include "framework/scene/Procedural.h"
#include "tests/AlgorithmHarness.h"
#include "tests/TestSupport.h"

#include <cstdio>
#include <map>
#include <string>
#include <tuple>

namespace shadowlab {
namespace {

using namespace test;

// This file's views are a little narrower than the other algorithms' (55° instead of 60°).
constexpr float kFovYDeg = 55.0f;

// The smoke scene and its lights (tests/ShadowTestScenes.h), 55° views.
Shot pointShot() { return smokePointShot(); }
Shot spotShot() { return smokeSpotShot(); }
Shot directionalShot() { return smokeDirectionalShot(); }
Shot areaShot(int samples, const char* pattern) { return smokeAreaShot(samples, 1.2f, pattern); }

// A single triangle over the ground: the root holds a leaf and an absent child.
Shot singleTriangle() {
    Shot s = pointShot();
    s.scene = Scene{};
    s.scene.addTriangles({{-3, 0, -3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, {-3, 0, 3}, {3, 0, 3},
                          {-0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {0.5f, 1, -0.5f}},
                         Material{});
    s.camera = lookAt({0, 4, 3}, {0, 0, 0}, kFovYDeg);
    s.light.position = {0.3f, 3.0f, 0.2f};
    return s;
}

class BvhRaytraceGLTest : public test::GLTest {
protected:
    AlgorithmRun run(const Shot& s, const std::map<std::string, ParamValue>& overrides = {}) {
        return runAlgorithm(bvhRaytraceInfo(), s, overrides);
    }
};

struct AccuracyCase {
    const char* name;
    Shot (*make)();
    double maxMismatch; ///< share of lit pixels whose binary visibility differs from the reference
    double maxRmse;     ///< RMS visibility difference over lit pixels
};

void PrintTo(const AccuracyCase& c, std::ostream* os) {
    *os << c.name << " mismatch ≤ " << c.maxMismatch << ", rmse ≤ " << c.maxRmse;
}

// The required bound for hard shadows is 0.1 % of lit pixels (≈ 5 of the ~5000 lit pixels at 96²):
// the rays are the reference's, and the watertight test matches Embree's robust mode, so only a
// ray grazing an edge within float rounding of the two tracers may differ. Soft shadows use the
// same samples, so the RMSE stays at that level too.
const AccuracyCase kAccuracy[] = {
    {"point", pointShot, 1e-3, 0.03},
    {"spot", spotShot, 1e-3, 0.03},
    {"directional", directionalShot, 1e-3, 0.03},
    {"area_16_stratified", [] { return areaShot(16, "stratified"); }, 1e-3, 0.01},
    {"area_9_grid", [] { return areaShot(9, "grid"); }, 1e-3, 0.01},
    {"single_triangle", singleTriangle, 1e-3, 0.03},
};

class BvhRaytraceAccuracyGLTest : public BvhRaytraceGLTest, public ::testing::WithParamInterface<AccuracyCase> {};

TEST_P(BvhRaytraceAccuracyGLTest, MatchesReference) {
    const AccuracyCase& c = GetParam();
    AlgorithmRun o = run(c.make());
    std::printf("[bvh_raytrace] %-20s lit %5zu mismatch %.4f%% rmse %.5f nodes/ray %.1f (max %.0f) tris/ray %.1f bvh %0.f nodes "
                "depth %.0f\n",
                c.name, o.accuracy.litPixels, 100 * o.accuracy.mismatchRatio, o.accuracy.rmse, o.counters["nodes_visited_mean"],
                o.counters["nodes_visited_max"], o.counters["triangles_tested_mean"], o.counters["bvh_nodes"],
                o.counters["bvh_depth"]);
    EXPECT_GT(o.accuracy.litPixels, size_t(kRes * kRes / 8)) << "the view should show lit surfaces";
    EXPECT_LE(o.accuracy.mismatchRatio, c.maxMismatch);
    EXPECT_LE(o.accuracy.rmse, c.maxRmse);
    EXPECT_EQ(o.overflow, 0u);
    size_t shadowed = 0;
    for (size_t i = 0; i < o.lit.size(); ++i) shadowed += o.lit[i] && o.reference[i] < 0.5f;
    EXPECT_GT(shadowed, size_t(50)) << "the scene should cast shadows onto lit pixels";
    EXPECT_GT(o.counters["nodes_visited_mean"], 0.0);
    EXPECT_EQ(o.counters["traced_pixels"], double(o.accuracy.litPixels));
}

INSTANTIATE_TEST_SUITE_P(Table, BvhRaytraceAccuracyGLTest, ::testing::ValuesIn(kAccuracy),
                         [](const auto& info) { return std::string(info.param.name); });

TEST_F(BvhRaytraceGLTest, TinyStackReportsOverflowAndNeverLightsAPixel) {
    AlgorithmRun o = run(areaShot(4, "grid"), {{"stack_size", 1}});
    const double pixels = o.counters["stack_overflow_pixels"];
    std::printf("[bvh_raytrace] stack_size 1: %.0f pixels, %.0f rays overflowed\n", pixels, o.counters["stack_overflow_rays"]);
    ASSERT_GT(pixels, 0.0);
    EXPECT_EQ(o.overflow, uint64_t(pixels));
    expectOverflowedPixelsShadowed(o, pixels);
    // Where no ray overflowed the answer is still the reference's; nowhere is a pixel lighter.
    for (size_t i = 0; i < o.visibility.size(); ++i)
        if (o.lit[i]) EXPECT_LE(o.visibility[i], o.reference[i] + 1e-6f) << "pixel " << i << " lit by overflow";
}

// The register short stack (short_stack) traverses in the same order: the same image, the same
// counters; with a stack smaller than the register part it still reports overflow.
TEST_F(BvhRaytraceGLTest, ShortStackGivesTheSameImage) {
    const Shot s = areaShot(16, "stratified");
    AlgorithmRun memory = run(s), registers = run(s, {{"short_stack", true}});
    EXPECT_EQ(registers.visibility, memory.visibility);
    EXPECT_EQ(registers.counters["nodes_visited_mean"], memory.counters["nodes_visited_mean"]);
    EXPECT_EQ(registers.overflow, 0u);
    // 20 entries: 16 in registers, 4 spilled to memory, on a tree of depth 13.
    AlgorithmRun spilled = run(s, {{"short_stack", true}, {"stack_size", 20}});
    EXPECT_EQ(spilled.visibility, memory.visibility);
    AlgorithmRun tiny = run(areaShot(4, "grid"), {{"short_stack", true}, {"stack_size", 1}});
    EXPECT_GT(tiny.counters["stack_overflow_pixels"], 0.0);
    expectOverflowedPixelsShadowed(tiny, tiny.counters["stack_overflow_pixels"]);
}

// The wall time of the frame's `trace` stage (what llvmpipe's stage times are, see StageTimer.h).
double traceMs(const AlgorithmRun& o) {
    for (const StageTime& t : o.stages)
        if (t.name == "trace") return t.cpuMs;
    return -1;
}

// A light's samples split over dispatches give the image, heat map and counters of one dispatch,
// bit for bit: at 64 samples one dispatch completes on llvmpipe too.
TEST_F(BvhRaytraceGLTest, SplitDispatchesGiveTheSingleDispatchImage) {
    const Shot s = areaShot(64, "stratified");
    RunOptions options;
    options.debugViews = {"nodes_visited"};
    AlgorithmRun single = runAlgorithm(bvhRaytraceInfo(), s, {{"samples_per_dispatch", 64}}, options);
    EXPECT_EQ(single.counters["sample_dispatches"], 1.0);
    EXPECT_EQ(single.overflow, 0u);
    for (int budget : {16, 5}) { // the default, and one that leaves a short last dispatch (4 samples)
        SCOPED_TRACE("samples_per_dispatch " + std::to_string(budget));
        AlgorithmRun split = runAlgorithm(bvhRaytraceInfo(), s, {{"samples_per_dispatch", budget}}, options);
        EXPECT_EQ(split.counters["sample_dispatches"], double((64 + budget - 1) / budget));
        EXPECT_EQ(split.visibility, single.visibility);
        EXPECT_EQ(split.views["nodes_visited"], single.views["nodes_visited"]);
        for (const char* c : {"rays", "traced_pixels", "nodes_visited_mean", "nodes_visited_max", "triangles_tested_mean"})
            EXPECT_EQ(split.counters[c], single.counters[c]) << c;
        EXPECT_EQ(split.overflow, 0u);
    }
}

// The most samples a light may have (1,024) take ceil(1024 / samples_per_dispatch) dispatches, each
// within the budget; any split gives the same image, exact against the reference. In one dispatch
// llvmpipe's loop budget (65,535 iterations per invocation, docs/algorithms/line_space.md) cuts some
// pixels short: they are reported and written shadowed, and every other pixel is the split's.
TEST_F(BvhRaytraceGLTest, MaxSamplesSplitOverDispatchesWithinTheBudget) {
    const Shot s = areaShot(1024, "stratified");
    RunOptions options;
    options.resolution = 48;
    AlgorithmRun split = runAlgorithm(bvhRaytraceInfo(), s, {}, options); // the default: 16 per dispatch
    EXPECT_EQ(split.counters["sample_dispatches"], 64.0);
    EXPECT_EQ(split.overflow, 0u);
    EXPECT_EQ(split.counters["rays"], 1024.0 * split.counters["traced_pixels"]);
    EXPECT_LE(split.accuracy.mismatchRatio, 1e-3);
    EXPECT_LE(split.accuracy.rmse, 0.01);
    AlgorithmRun uneven = runAlgorithm(bvhRaytraceInfo(), s, {{"samples_per_dispatch", 100}}, options);
    EXPECT_EQ(uneven.counters["sample_dispatches"], 11.0); // the last one 24 samples
    EXPECT_EQ(uneven.overflow, 0u);
    EXPECT_EQ(uneven.visibility, split.visibility);
    AlgorithmRun single = runAlgorithm(bvhRaytraceInfo(), s, {{"samples_per_dispatch", 1024}}, options);
    size_t flagged = 0, differ = 0;
    for (size_t i = 0; i < single.visibility.size(); ++i) {
        if (single.overflowMask[i] > 0.5f) ++flagged;
        else differ += single.visibility[i] != split.visibility[i];
    }
    std::printf("[bvh_raytrace] 1024 samples: trace %.1f ms in 64 dispatches, %.1f ms in 11, %.1f ms in one (%zu pixels cut "
                "short: %.0f truncated, %.0f capped)\n",
                traceMs(split), traceMs(uneven), traceMs(single), flagged, single.counters["truncated_pixels"],
                single.counters["loop_capped_pixels"]);
    EXPECT_EQ(double(flagged), double(single.overflow));
    EXPECT_EQ(differ, 0u);
}

// A walk that cannot end (a fault site, test-only: every other pixel's rays are sent back into the
// node they leave whenever they enter one inner child only) stops at its step cap: the frame
// finishes, the pixels are counted and written shadowed, and every other pixel keeps its value. The
// state survives the dispatches of a split area light.
TEST_F(BvhRaytraceGLTest, FaultWalkThatCannotEndIsCappedAndWrittenShadowed) {
    for (const auto& [name, shot, budget] : {std::tuple{"point", pointShot(), 16}, std::tuple{"area 16", areaShot(16, "grid"), 4}}) {
        SCOPED_TRACE(name);
        AlgorithmRun clean = run(shot, {{"samples_per_dispatch", budget}});
        EXPECT_EQ(clean.overflow, 0u);
        EXPECT_EQ(clean.counters["loop_capped_pixels"], 0.0);
        AlgorithmRun o;
        {
            ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_BVH_CYCLE", "1"}});
            o = run(shot, {{"samples_per_dispatch", budget}});
        }
        const double capped = o.counters["loop_capped_pixels"];
        std::printf("[bvh_raytrace] corrupt link, %s light: %.0f pixels capped, %.0f dispatches\n", name, capped,
                    o.counters["sample_dispatches"]);
        EXPECT_GT(capped, 0.0);
        EXPECT_EQ(o.overflow, uint64_t(capped));
        expectOverflowedPixelsShadowed(o, capped);
        size_t faultyLit = 0, elsewhere = 0, changed = 0, lighter = 0;
        for (int y = 0; y < kRes; ++y)
            for (int x = 0; x < kRes; ++x) {
                const size_t i = size_t(y) * kRes + size_t(x);
                const bool faulty = (x + y) % 2 == 0, marked = o.overflowMask[i] > 0.5f;
                faultyLit += faulty && o.lit[i];
                elsewhere += marked && !faulty;
                lighter += o.visibility[i] > clean.visibility[i];
                if (!marked) changed += o.visibility[i] != clean.visibility[i];
            }
        EXPECT_EQ(lighter, 0u) << "pixels lit by mistake";
        EXPECT_EQ(elsewhere, 0u) << "pixels capped outside the faulty ones";
        EXPECT_EQ(changed, 0u) << "pixels not capped whose value differs from the clean run";
        EXPECT_GT(capped, 0.2 * double(faultyLit));
    }
}

// A leaf loop a driver ends early (a fault site, test-only: every leaf loop stops after its first
// triangle, as llvmpipe's loop limit would) leaves triangles untested: the ray is capped, its pixel
// counted and written shadowed, never lit by a triangle nobody tested.
TEST_F(BvhRaytraceGLTest, FaultCutLeafLoopIsCappedAndWrittenShadowed) {
    const Shot shot = pointShot();
    const AlgorithmRun clean = run(shot);
    AlgorithmRun o;
    {
        ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_CUT_LEAF_LOOP", "1"}});
        o = run(shot);
    }
    expectCutLoopsCappedAndShadowed(o, clean);
}

TEST_F(BvhRaytraceGLTest, CountersAndMemoryDescribeTheTree) {
    Shot s = pointShot();
    AlgorithmRun o = run(s);
    const double n = double(s.scene.triangleCount());
    // Leaves of at most 4 triangles: at least n / 4 leaves, one fewer inner node than leaves.
    EXPECT_GE(o.counters["bvh_leaves"], n / 4);
    EXPECT_EQ(o.counters["bvh_nodes"], o.counters["bvh_leaves"] - 1);
    // Nodes and the leaf-ordered triangles (three vec4 each); no index buffer, no scene positions.
    EXPECT_EQ(o.memory, size_t(o.counters["bvh_nodes"]) * 64 + size_t(n) * 48);
    // Any-hit early exit and the SAH keep a ray far below the tree size.
    EXPECT_LT(o.counters["nodes_visited_mean"], 0.05 * o.counters["bvh_nodes"]);
    EXPECT_GE(o.counters["nodes_visited_max"], o.counters["nodes_visited_mean"]);
    EXPECT_LE(o.counters["nodes_visited_max"], o.counters["bvh_nodes"]);
    EXPECT_EQ(o.counters["rays"], double(o.accuracy.litPixels)); // one ray per lit pixel for a point light
    // Where a ray's time goes: node visits and triangle tests, idle lanes included.
    expectSimdProbe(o, {{"node", "nodes_visited_mean"}, {"triangle", "triangles_tested_mean"}});
}

} // namespace
} // namespace shadowlab
