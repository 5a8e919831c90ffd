// The smallest complete plugin: a typed parameter struct whose schema rows show the three change
// kinds, per-scene work in setScene(), image-size work in resize(), one timed stage, a counter and
// a debug view, both compiled out in the host's timed pass (AlgorithmOptions::statistics off). What the framework does around it (light check, call order, timing, read-back) is
// in framework/algorithm/AlgorithmHost: a plugin only computes.
#include "algorithms/template/Template.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/SharedParams.h"
#include "framework/core/CheckedMath.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"
#include "shaders/template/layout.glsl"

#include <algorithm>
#include <numeric>

namespace shadowlab {
namespace {

/// 1. The parameters, read once per change into plain fields.
struct TemplateParams {
    bool largestFirst; ///< Rebuild: the triangle order uploaded in setScene()
    int groupSide;     ///< Recompile: a shader #define
    float rayOffset;   ///< Update: a uniform (the shared row, as the reference defines it)
    int samplesPerDispatch; ///< Update: how a frame is split over dispatches (GPU portability)
};

/// 2. The schema: key, member, default, range, unit, doc and change kind, written once. Configs,
/// `shadowlab list`, the GUI panel, results and docs/algorithms/template.md all come from it.
const ParamStruct<TemplateParams>& templateParams() {
    using P = TemplateParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        .boolean("largest_first", &P::largestFirst, true,
                 "test triangles in order of decreasing area: big occluders end most rays early", ParamChange::Rebuild)
        .integer("group_side", &P::groupSide, 8, 4, 16, "px", "side of the square workgroup of the per-pixel pass",
                 ParamChange::Recompile)
        .apply(rayOffsetRow(&P::rayOffset))
        // One sample costs a test against every triangle: 1 per dispatch keeps a dispatch one pass
        // over the scene however many samples the light has (docs/architecture.md, rule 9).
        .apply(samplesPerDispatchRow(&P::samplesPerDispatch, 1));
    return s;
}

const ParamSchema& templateSchema() { return templateParams().schema(); }

class Template final : public ShadowAlgorithm {
public:
    /// The host's options: with statistics off (the timed pass) they are compiled out.
    Template(const ParamValues& p, const AlgorithmOptions& o) : p_(templateParams().read(p)), options_(o) { compile(); }

    /// 3. Per-scene work (timed as `preprocess`): here, the order in which triangles are tested.
    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        const Scene& s = scene.cpu();
        std::vector<uint32_t> order(s.triangleCount());
        std::iota(order.begin(), order.end(), 0u);
        if (p_.largestFirst) {
            auto area = [&](uint32_t t) {
                const glm::vec3* v = &s.positions[3 * size_t(t)];
                return glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
            };
            std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return area(a) > area(b); });
        }
        if (order.empty()) order.push_back(0);  // an empty buffer cannot be bound
        order_ = GlBuffer::fromVector(order, 0);
        counters_.allocate();
    }

    /// 4. Image-size work: the debug view.
    void resize(glm::ivec2 resolution) override {
        if (options_.statistics) tests_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
    }

    /// 5. New values: uniforms are read each frame; a Recompile rebuilds the programs; a Rebuild is
    /// followed by setScene() (the host calls it).
    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = templateParams().read(p);
        if (change == ParamChange::Recompile) compile();
    }

    /// 6. One frame: stages are timed through f.timer; the host checked the light and sizes.
    void computeVisibility(const FrameInputs& f) override {
        const int samples = uploadLightSamples(samples_, f.light);
        f.timer.begin("trace");
        counters_.clear();
        setLightUniforms(trace_, f.light);
        trace_.set("uRayOffset", rayOffsetLength(p_.rayOffset, *scene_));
        trace_.set("uSampleCount", samples);
        trace_.set("uTriangleCount", unsigned(scene_->triangleCount()));
        scene_->bindStorage();
        order_.bindBase(GL_SHADER_STORAGE_BUFFER, TEMPLATE_ORDER_BINDING);
        samples_.bindBase(GL_SHADER_STORAGE_BUFFER, TEMPLATE_SAMPLE_BINDING);
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, TEMPLATE_COUNTER_BINDING);
        bindPixelPassInputs(f);
        if (options_.statistics) bindDebugImage(1, tests_);
        const glm::ivec2 r = f.gbuffer.resolution();
        // The light's samples over dispatches of at most samples_per_dispatch each (one when they
        // fit), each pixel's count carried between them in the accumulation image.
        batches_.begin(samples, p_.samplesPerDispatch, r, options_.statistics, TEMPLATE_ACCUM_UNIT);
        batches_.dispatch(trace_, r, {p_.groupSide, p_.groupSide});
        finishPixelPass();
        f.timer.end();
        counters_.markStale();
    }

    /// 7. What the frame cost, for results and the GUI.
    std::vector<Counter> counters() const override {
        if (!options_.statistics) return {};
        const auto& c = counters_.read();
        const double pixels = c[TEMPLATE_C_PIXELS];
        return {{"triangle_tests_mean", pixels > 0 ? double(counters_.wide(TEMPLATE_C_TESTS_LO)) / pixels : 0.0},
                {"traced_pixels", pixels},
                {"sample_dispatches", double(batches_.dispatches())},
                {"loop_capped_rays", double(c[TEMPLATE_C_CUT_LOOPS])}};
    }
    std::vector<DebugView> debugViews() const override {
        if (!options_.statistics) return {};
        return {{"triangle_tests", tests_.id(), 0.0f, "tests"}};
    }
    size_t memoryBytes() const override { return order_.size() + counters_.size(); }
    // No fixed-size structure (no stack, no pool) and every loop ends at a count; a loop the device
    // ends early (llvmpipe after 65,535 iterations) is counted, its ray taken as blocked.
    uint64_t overflowCount() const override { return counters_.read()[TEMPLATE_C_CUT_LOOPS]; }
    // Not in memoryBytes(), as in bvh_raytrace and line_space: the accumulation image (per pixel,
    // only when a frame takes several dispatches).

private:
    void compile() {
        trace_ = ShaderProgram::compute("template/trace.comp", {{"TEMPLATE_GROUP_SIDE", std::to_string(p_.groupSide)},
                                                                statisticsDefine(options_)});
    }

    TemplateParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    ShaderProgram trace_;
    GlBuffer order_, samples_;
    GpuCounters<TEMPLATE_COUNTER_WORDS> counters_;
    GlTexture tests_;
    SampleBatches batches_; ///< the light's samples over dispatches, and their state between them
};

} // namespace

/// 8. The registry entry: name (= folder, JSON "algorithm" value, results label), summary, lights,
/// exactness (exact algorithms are held to the reference's tiny mismatch by the conformance test).
/// The triangle order (4 bytes a triangle); the brute-force loop reads the scene positions as one
/// storage block.
Footprint templateFootprint(const FootprintQuery& q) {
    Footprint f;
    // The triangle order and the counter block: what memoryBytes() reports.
    f.bytes = saturatingSum({saturatingMul(4, q.triangles), size_t(TEMPLATE_COUNTER_WORDS) * 4});
    f.refusal = storageRefusal(q, "the scene positions it reads", saturatingMul(36, q.triangles));
    return f;
}
AlgorithmInfo templateInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<Template>("template", "example plugin: exact hard shadows, every pixel against every triangle",
                                       {LightType::Point, LightType::Spot, LightType::Directional, LightType::Area}, true,
                                       &templateSchema);
    info.footprint = &templateFootprint;
    return info;
}

} // namespace shadowlab
