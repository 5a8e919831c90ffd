#include "algorithms/bvh_raytrace/BvhRaytrace.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/SharedParams.h"
#include "framework/accel/SceneBvh.h"
#include "framework/core/CheckedMath.h"
#include "framework/core/Error.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"
#include "shaders/bvh_raytrace/layout.glsl"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>

namespace shadowlab {

namespace bvh {

void checkStorageBlock(const char* what, size_t bytes, size_t limit) {
    if (bytes <= limit) return;
    auto mib = [](size_t b) { return std::to_string((b + (1u << 20) - 1) >> 20); };
    throw RuntimeError(std::string("bvh_raytrace: ") + what + " need " + mib(bytes) +
                       " MiB, more than GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" + mib(limit) + " MiB) of this GL context");
}

} // namespace bvh

namespace {

struct BvhParams {
    int stackSize;       ///< traversal stack, nodes
    int leafSize;        ///< most triangles per leaf
    bool shortStack;     ///< top of the stack in registers
    int sahBins;         ///< split candidates per axis
    float traversalCost; ///< × triangle test
    float rayOffset;     ///< × scene radius
    int samplesPerDispatch; ///< most light samples per pixel one dispatch traces
};

const ParamStruct<BvhParams>& bvhParams() {
    using P = BvhParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        // A binned-SAH tree over n triangles is rarely deeper than ~2 log2(n) (≈ 45 for 2 M); 64 leaves
        // headroom, and an overflow is reported, never hidden.
        .apply(stackSizeRow(&P::stackSize, 64))
        .integer("leaf_size", &P::leafSize, 4, 1, BVH_MAX_LEAF, "triangles", "most triangles per BVH leaf",
                 ParamChange::Rebuild)
        // Off: on llvmpipe the shifts cost more than the scratch-memory stack they avoid (~10-20 %
        // slower on the engine scenes, results/reference/line_space/earlier.md); a GPU may differ.
        .boolean("short_stack", &P::shortStack, false,
                 "keep the top 16 stack entries in registers (shifted on push/pop), spilling deeper ones to memory",
                 ParamChange::Recompile)
        .integer("sah_bins", &P::sahBins, 32, 4, 256, "bins", "SAH candidate split planes per axis in the CPU build",
                 ParamChange::Rebuild)
        // Aila & Laine's GPU ratio is near 1: a node fetch costs about what a triangle fetch does.
        .real("traversal_cost", &P::traversalCost, 1.0, 0.1, 10.0, "× triangle test",
              "SAH cost of visiting a node, relative to one ray-triangle test", ParamChange::Rebuild)
        .apply(rayOffsetRow(&P::rayOffset))
        // 16: one sample of every pixel of a 4K frame costs ~8 ms on a GPU (~0.8 s on llvmpipe here,
        // ~100x slower), ~15 ms on a 2 M-triangle scene: at most ~0.25 s a dispatch, 8x under 2 s
        // (docs/algorithms/bvh_raytrace.md, "Dispatches"). The default light (16 samples) takes one.
        .apply(samplesPerDispatchRow(&P::samplesPerDispatch, 16));
    return s;
}

const ParamSchema& bvhSchema() { return bvhParams().schema(); }

using Clock = std::chrono::steady_clock;

class BvhRaytrace final : public ShadowAlgorithm {
public:
    BvhRaytrace(const ParamValues& p, const AlgorithmOptions& o) : p_(bvhParams().read(p)), options_(o) { compile(); }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        auto t0 = Clock::now();
        bvh::BuildOptions opt;
        opt.maxLeafSize = p_.leafSize;
        opt.bins = p_.sahBins;
        opt.traversalCost = p_.traversalCost;
        const bvh::BvhStats tree = bvh_.build(scene, opt, maxShaderStorageBlockBytes(), "bvh_raytrace");
        buildMs_ = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        counters_.allocate();
        nodeCount_ = tree.nodes;
        depth_ = tree.depth;
        leaves_ = tree.leaves;
        sahCost_ = tree.sahCost;
    }

    // Moving parts: the tree refitted to the posed triangles (SceneBvh); a GPU refit would beat this
    // on big moving sets.
    void sceneMoved(const FrameInputs& f) override { bvh_.refit(*scene_, f.timer); }

    void resize(glm::ivec2 resolution) override {
        if (!options_.statistics) return; // the timed pass: no debug images
        nodesVisited_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
        overflow_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
    }

    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = bvhParams().read(p);
        if (change == ParamChange::Recompile) compile();  // a Rebuild (the tree) is followed by setScene()
    }

    void computeVisibility(const FrameInputs& f) override {
        const int sampleCount = uploadLightSamples(samples_, f.light);
        const int budget = p_.samplesPerDispatch;
        const glm::ivec2 res = f.gbuffer.resolution();

        // One stage over every dispatch: the frame's cost, however it is split.
        f.timer.begin("trace");
        counters_.clear();
        setLightUniforms(trace_, f.light);
        trace_.set("uRayOffset", rayOffsetLength(p_.rayOffset, *scene_));
        trace_.set("uSampleCount", sampleCount);
        trace_.set("uBvhStepCap", unsigned(bvh_.gpu().stepCap));
        bvh_.gpu().bind(BVH_NODE_UNIT, BVH_TRI_UNIT);
        samples_.bindBase(GL_SHADER_STORAGE_BUFFER, BVH_SAMPLE_BINDING);
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, BVH_COUNTER_BINDING);
        bindPixelPassInputs(f);
        if (options_.statistics) bindDebugImage(1, nodesVisited_), bindDebugImage(2, overflow_);
        // The state between dispatches (layout.glsl); a single dispatch never touches it.
        batches_.begin(sampleCount, budget, res, options_.statistics, BVH_ACCUM_UNIT);
        batches_.dispatch(trace_, res);
        finishPixelPass();
        f.timer.end();
        counters_.markStale();
    }

    std::vector<Counter> counters() const override {
        const auto& c = counters_.read();
        auto wide = [&](size_t lo) { return double(counters_.wide(lo)); };
        const double rays = wide(BVH_C_RAYS_LO);
        auto perRay = [&](double v) { return rays > 0 ? v / rays : 0.0; };
        // The structure and what is measured in both modes; the timed pass compiles the rest out.
        std::vector<Counter> out = {{"stack_overflow_rays", double(c[BVH_C_OVERFLOW_RAYS])},
                                    {"stack_overflow_pixels", double(c[BVH_C_OVERFLOW_PIXELS])},
                                    {"truncated_pixels", double(c[BVH_C_TRUNCATED_PIXELS])},
                                    {"loop_capped_pixels", double(c[BVH_C_CAPPED_PIXELS])},
                                    {"sample_dispatches", double(batches_.dispatches())},
                                    {"bvh_nodes", double(nodeCount_)},
                                    {"bvh_leaves", double(leaves_)},
                                    {"bvh_depth", double(depth_)},
                                    {"bvh_sah_cost", sahCost_},
                                    {"bvh_build_ms", buildMs_},
                                    {"node_bytes", double(bvh_.gpu().nodes.size())},
                                    {"triangle_bytes", double(bvh_.gpu().triangles.size())}};
        if (!options_.statistics) return out;
        out.insert(out.begin(), {{"nodes_visited_mean", perRay(wide(BVH_C_VISITED_LO))},
                                 {"nodes_visited_max", double(c[BVH_C_VISITED_MAX])},
                                 {"triangles_tested_mean", perRay(wide(BVH_C_TRIS_LO))},
                                 {"rays", rays},
                                 {"traced_pixels", double(c[BVH_C_PIXELS])}});
        // Where a ray's time goes, idle lanes included (the same probe as line_space's).
        static_assert(BVH_SIMD_SECTIONS == 2);
        appendSimdProbeCounters(out, {"node", "triangle"}, BVH_C_SIMD_BASE, c[BVH_C_SIMD_WIDTH], rays, wide);
        return out;
    }

    std::vector<DebugView> debugViews() const override {
        if (!options_.statistics) return {};
        return {{"nodes_visited", nodesVisited_.id(), 0.0f, "nodes/pixel"}, {"stack_overflow", overflow_.id(), 1.0f, "flag"}};
    }

    /// Nodes + the leaf-ordered triangles the rays read (a ray tracer needs them and line_space does
    /// not: the paper's Table 1 compares sizes on that basis, "the BVH needs the triangle
    /// information in addition"). Per-pixel debug images and the sample list are not counted.
    size_t memoryBytes() const override { return bvh_.gpu().bytes(); }

    /// Pixels with a ray whose stack overflowed or whose walk reached its step cap, or whose sample
    /// loop the driver cut short (all written shadowed): 0 means the image is exact.
    uint64_t overflowCount() const override {
        const auto& c = counters_.read();
        return uint64_t(c[BVH_C_OVERFLOW_PIXELS]) + c[BVH_C_TRUNCATED_PIXELS] + c[BVH_C_CAPPED_PIXELS];
    }

private:
    void compile() {
        const ShaderDefines defines = {{"BVH_STACK_SIZE", std::to_string(p_.stackSize)},
                                       {"BVH_SHORT_STACK", p_.shortStack ? "1" : "0"},
                                       simdProbeDefine(options_), statisticsDefine(options_)};
        trace_ = ShaderProgram::compute("bvh_raytrace/trace.comp", defines);
    }

    BvhParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    ShaderProgram trace_;
    bvh::SceneBvh bvh_; ///< the tree as the trace reads it, refitted as the scene moves
    GlBuffer samples_;
    GpuCounters<BVH_COUNTER_WORDS> counters_;
    GlTexture nodesVisited_, overflow_;
    SampleBatches batches_; ///< the light's samples over dispatches, and their state between them
    size_t nodeCount_ = 0, leaves_ = 0;
    int depth_ = 0;
    double sahCost_ = 0, buildMs_ = 0;
};

} // namespace

/// Leaf-ordered triangles (48 bytes) and nodes (64 bytes, one per leaf of at least two triangles on
/// average: at most 32 a triangle) on the GPU, the triangles checked against the reported
/// storage-block size as setScene does (the nodes, fewer bytes, pass where they pass); ~150 bytes a
/// triangle while the binned SAH builder runs on the host; a moving scene keeps its tree and posed copy.
Footprint bvhRaytraceFootprint(const FootprintQuery& q) {
    Footprint f;
    const size_t n = q.triangles;
    // Leaves hold leaf_size triangles at most and about half that on average: 2 n / leaf_size nodes.
    const size_t nodes = std::min(n, saturatingMul(2, n) / size_t(std::max(1, std::get<int>(q.params->get("leaf_size")))) + 1);
    f.bytes = saturatingSum({saturatingMul(48, n), saturatingMul(64, nodes), q.moving ? saturatingMul(152, n) : 0});
    f.peakBytes = saturatingMul(152, n);
    f.refusal = storageRefusal(q, "its leaf-ordered triangles", saturatingMul(48, n), true);
    if (f.refusal.empty()) f.refusal = storageRefusal(q, "its nodes", saturatingMul(64, nodes), true);
    return f;
}
AlgorithmInfo bvhRaytraceInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<BvhRaytrace>(
        "bvh_raytrace", "GLSL ray tracing of the reference's shadow rays through a binned-SAH BVH built on the CPU",
        {LightType::Point, LightType::Spot, LightType::Directional, LightType::Area}, true, &bvhSchema);
    info.motion = MotionHandling::Refit;
    info.footprint = &bvhRaytraceFootprint;
    return info;
}

} // namespace shadowlab
