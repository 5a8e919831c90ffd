#include "tests/AlgorithmHarness.h"

#include "framework/algorithm/AlgorithmHost.h"
#include "framework/algorithm/SharedParams.h"
#include "framework/reference/EmbreeTracer.h"
#include "framework/gl/GlObjects.h"
#include "framework/gl/Shader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <ostream>

namespace shadowlab::test {

AlgorithmRun runAlgorithm(const AlgorithmInfo& info, const Shot& shot, const std::map<std::string, ParamValue>& overrides,
                          const RunOptions& options) {
    ParamValues params(info.schema());
    for (const auto& [k, v] : overrides) params.set(k, v);
    const int res = options.resolution;
    SceneGpu gpu(shot.scene);
    GBuffer gbuffer({res, res});
    gbuffer.render(gpu, shot.camera);
    AlgorithmHost host(info, params, AlgorithmOptions{options.statistics});
    host.resize({res, res});
    host.setScene(gpu);
    StageTimer timer;
    timer.setSynchronous(options.synchronousStages);
    AlgorithmRun o;
    o.gbuffer = gbuffer.readBack();
    const FrameView frame{gbuffer, [&]() -> const CpuGBuffer& { return o.gbuffer; }, shot.camera, shot.light, 0};
    if (options.warmUp) host.computeFrame(frame, timer);
    const FrameMeasurement m = host.computeFrame(frame, timer);
    o.stages = m.stages;
    o.visibility = host.readVisibility();
    for (const Counter& c : m.counters) o.counters.set(c.name, c.value);
    o.overflow = m.overflow;
    o.memory = m.memoryBytes;
    for (const DebugView& v : host.algorithm().debugViews())
        if (v.name == "stack_overflow") o.overflowMask = readTextureR32F(v.texture, res, res);
        else if (std::find(options.debugViews.begin(), options.debugViews.end(), v.name) != options.debugViews.end())
            o.views[v.name] = readTextureR32F(v.texture, res, res);
    if (options.inspect) options.inspect(o);
    o.lit = litMask(o.gbuffer, shot.light);
    if (options.withReference) {
        EmbreeTracer tracer(shot.scene);
        // The algorithm's own offset, so both trace from the same points and only the tests differ.
        tracer.traceVisibility(o.gbuffer, shot.light, rayOffsetLength(float(rayOffsetOf(params)), shot.scene.bounds), 0, o.reference);
        o.accuracy = compareVisibility(o.visibility, o.reference, o.lit);
    }
    return o;
}

Shot withLight(Shot shot, LightType type) {
    const glm::vec3 from = shot.light.position, to = shot.scene.bounds.center();
    Light l;
    l.type = type;
    l.position = from;
    l.target = to;
    l.coneDeg = 40.0f;
    l.size = glm::vec2(0.2f * shot.scene.bounds.radius());
    l.samples = 4;  // a few: the brute-force template traces each against every triangle
    shot.light = l;
    return shot;
}

void expectSimdProbe(const AlgorithmRun& o, const std::vector<std::pair<std::string, std::string>>& sectionWork) {
    const int width = querySubgroupSize();
    if (width == 0) {
        EXPECT_EQ(o.counters.count("simd_width"), 0u) << "a SIMD probe without a ballot";
        return;
    }
    ASSERT_EQ(o.counters.count("simd_width"), 1u);
    EXPECT_EQ(o.counters.at("simd_width"), double(width));
    for (const auto& [section, work] : sectionWork) {
        SCOPED_TRACE(section);
        const double slots = o.counters.at("simd_" + section + "_slots_per_ray");
        const double use = o.counters.at("simd_" + section + "_utilisation");
        EXPECT_GT(use, 0.0);
        EXPECT_LE(use, 1.0);
        // Two 64-bit integer sums divided by the ray count: equal up to the doubles' rounding.
        EXPECT_NEAR(slots * use, o.counters.at(work), 1e-9 * o.counters.at(work));
    }
}

void printCase(std::ostream& os, const char* name, const std::map<std::string, ParamValue>& params) {
    os << name;
    const char* sep = " {";
    for (const auto& [k, v] : params) {
        os << sep << k << "=" << toString(v);
        sep = ", ";
    }
    if (!params.empty()) os << "}";
}

void PrintTo(const AccuracyCase& c, std::ostream* os) {
    printCase(*os, c.name, c.params);
    *os << " mismatch ≤ " << c.maxMismatch;
}

void expectOverflowedPixelsShadowed(const AlgorithmRun& o, double pixels) {
    size_t marked = 0;
    for (size_t i = 0; i < o.visibility.size(); ++i)
        if (o.overflowMask[i] > 0.5f) {
            ++marked;
            EXPECT_EQ(o.visibility[i], 0.0f) << "pixel " << i << " overflowed but is not written shadowed";
        }
    EXPECT_EQ(double(marked), pixels);
}

void expectAccurateRow(const AlgorithmRun& o, double maxMismatch) {
    EXPECT_GT(o.accuracy.litPixels, o.lit.size() / 8) << "the view should show lit surfaces";
    EXPECT_LE(o.accuracy.mismatchRatio, maxMismatch);
    EXPECT_EQ(o.overflow, 0u);
    size_t shadowed = 0;
    for (size_t i = 0; i < o.lit.size(); ++i) shadowed += o.lit[i] && o.reference[i] < 0.5f;
    EXPECT_GT(shadowed, size_t(50)) << "the scene should cast shadows on what the camera sees";
    EXPECT_LT(shadowed + 50, o.accuracy.litPixels);
}

std::vector<AccuracyCase> hardSceneTable(double maxMismatch, std::vector<AccuracyCase> rows) {
    std::vector<AccuracyCase> out = {
        {"intersecting_triangles", intersectingTriangles, {}, maxMismatch},
        {"omni_inside_shell", omniInsideShell, {}, maxMismatch},
        {"directional", directionalObjects, {}, maxMismatch},
        {"camera_inside_shadow", cameraInsideShadow, {}, maxMismatch},
        {"thousands", thousandsOfTriangles, {}, maxMismatch},
        {"spot", smokeSpotShot, {}, maxMismatch},
        {"light_amid_clutter", lightAmidClutter, {}, maxMismatch},
        {"grazing_over_thin", grazingOverThin, {}, maxMismatch},
        {"open_meshes", openMeshes, {}, maxMismatch},
        {"fins_and_soup", finsAndSoup, {}, maxMismatch},
        {"engine", engineOnGround, {}, maxMismatch},
        {"edge_on_wall", [] { return withEdgeOnWall(thousandsOfTriangles()); }, {}, maxMismatch},
    };
    out.insert(out.end(), rows.begin(), rows.end());
    return out;
}

void expectCutLoopsCappedAndShadowed(const AlgorithmRun& o, const AlgorithmRun& clean) {
    const double capped = o.counters.at("loop_capped_pixels");
    EXPECT_GT(capped, 0.0);
    EXPECT_EQ(o.overflow, uint64_t(capped));
    expectOverflowedPixelsShadowed(o, capped);
    size_t lighter = 0;
    for (size_t i = 0; i < o.visibility.size(); ++i) lighter += o.visibility[i] > clean.visibility[i];
    EXPECT_EQ(lighter, 0u) << "pixels lit by mistake";
}

} // namespace shadowlab::test
