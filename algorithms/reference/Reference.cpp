#include "algorithms/reference/Reference.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/SharedParams.h"
#include "framework/core/CheckedMath.h"
#include "framework/reference/EmbreeTracer.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <thread>

namespace shadowlab {
namespace {

enum class ReferenceBvh { Auto, Fast, Compact };

struct ReferenceParams {
    int threads;     ///< 0 = all hardware threads
    float rayOffset; ///< × scene radius
    EmbreeTracer::MotionUpdate motionUpdate; ///< how the BVH follows moving parts
    ReferenceBvh bvh;                    ///< Embree's data layout
};

/// `bvh: auto` takes the compact layout from this many triangles (docs/memory.md: it saves about
/// 40 bytes a triangle, and the reference's time per frame is small next to any GPU algorithm's).
constexpr size_t kCompactBvhTriangles = 10'000'000;

bool compactLayout(ReferenceBvh bvh, size_t triangles) {
    return bvh == ReferenceBvh::Compact || (bvh == ReferenceBvh::Auto && triangles >= kCompactBvhTriangles);
}

const ParamStruct<ReferenceParams>& referenceParams() {
    using P = ReferenceParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        .integer("threads", &P::threads, 0, 0, 256, "", "CPU threads tracing rays (0 = one per 65,536 pixels, at most all hardware threads)",
                 ParamChange::Update)
        .apply(rayOffsetRow(&P::rayOffset))
        .choice("motion_update", &P::motionUpdate, EmbreeTracer::MotionUpdate::Refit,
                {{"refit", EmbreeTracer::MotionUpdate::Refit}, {"rebuild", EmbreeTracer::MotionUpdate::Rebuild}},
                "how the Embree BVH follows moving parts each frame: refit its boxes (fast; the tree degrades as "
                "parts travel) or rebuild it (the CPU alternative's full cost); either is exact",
                ParamChange::Rebuild)
        .choice("bvh", &P::bvh, ReferenceBvh::Auto,
                {{"auto", ReferenceBvh::Auto}, {"fast", ReferenceBvh::Fast}, {"compact", ReferenceBvh::Compact}},
                "Embree's node layout: fast, or compact (compact nodes: less memory, slower rays); auto: compact from "
                "10 M triangles; either is exact (the triangles are decided by the shaders' own test either way)",
                ParamChange::Rebuild);
    return s;
}

const ParamSchema& referenceSchema() { return referenceParams().schema(); }

class Reference final : public ShadowAlgorithm {
public:
    explicit Reference(const ParamValues& params) : p_(referenceParams().read(params)) {}

    bool compactBvh(size_t triangles) const { return compactLayout(p_.bvh, triangles); }

    void setScene(const SceneGpu& scene) override {
        tracer_.reset(); // free the old BVH before building the new one
        scene_ = &scene;
        posed_.clear();
        tracer_ = std::make_unique<EmbreeTracer>(scene.cpu(), p_.motionUpdate,
                                               // the SceneGpu's Scene lives as long as this scene is set
                                               EmbreeTracer::Vertices::Share, compactBvh(scene.triangleCount()));
    }

    // The moving triangles are read back from the GPU rather than posed again here, so the ground
    // truth intersects the very floats the G-buffer rasterised.
    void sceneMoved(const FrameInputs& frame) override {
        frame.timer.begin("read_scene");
        if (posed_.empty()) posed_ = scene_->cpu().positions;
        scene_->readMovingPositions(posed_);
        frame.timer.end();
        frame.timer.begin(p_.motionUpdate == EmbreeTracer::MotionUpdate::Rebuild ? "rebuild" : "refit", false);
        for (const MovingPart& part : scene_->cpu().moving)
            tracer_->moveTriangles(part.firstTriangle, &posed_[3 * part.firstTriangle], part.triangleCount);
        tracer_->commitMoves();
        frame.timer.end();
    }

    void paramsChanged(const ParamValues& params, ParamChange) override { p_ = referenceParams().read(params); }

    void computeVisibility(const FrameInputs& frame) override {
        const CpuGBuffer& g = frame.cpuGBuffer();
        frame.timer.begin("trace", false); // CPU stage: no GPU query
        auto t0 = std::chrono::steady_clock::now();
        tracer_->traceVisibility(g, frame.light, rayOffsetLength(p_.rayOffset, *scene_), p_.threads, visibility_);
        double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        frame.timer.end();
        rays_ = double(tracer_->lastRayCount());
        mraysPerS_ = seconds > 0 ? rays_ / seconds * 1e-6 : 0.0;

        frame.timer.begin("upload");
        glTextureSubImage2D(frame.visibility, 0, 0, 0, g.width, g.height, GL_RED, GL_FLOAT, visibility_.data());
        frame.timer.end();
    }

    std::vector<Counter> counters() const override { return {{"rays", rays_}, {"mrays_per_s", mraysPerS_}}; }
    size_t memoryBytes() const override { return tracer_ ? tracer_->memoryBytes() : 0; }

    /// The threads tracing rays (EmbreeTracer::threadsFor's rule for 0, at the last frame's size).
    std::vector<std::pair<std::string, std::string>> resolvedParams() const override {
        return {{"threads", std::to_string(EmbreeTracer::threadsFor(p_.threads, visibility_.size()))},
                {"bvh", scene_ && compactBvh(scene_->triangleCount()) ? "compact" : "fast"}};
    }

    /// The visibility of the last frame (row-major, width * height), as uploaded.
    const std::vector<float>& lastVisibility() const { return visibility_; }

private:
    const SceneGpu* scene_ = nullptr;
    std::unique_ptr<EmbreeTracer> tracer_;
    std::vector<glm::vec3> posed_; ///< moving scenes: the positions as last read back
    ReferenceParams p_;
    std::vector<float> visibility_;
    double rays_ = 0, mraysPerS_ = 0;
};

} // namespace

/// Embree's BVH and index buffer: kEmbreeBytesPerTriangle measured (docs/memory.md; the vertices
/// are the Scene's own for a static scene, copied, 36 bytes more, for a moving one), plus the
/// reference's visibility and G-buffer copies per pixel.
/// Bounds, not typical values: random triangle soups fill Embree's leaves worst of the scenes
/// measured, models and grids of shapes take 20-40 % less (results/reference/memory_bounds_llvmpipe.md).
constexpr size_t kEmbreeBytesPerTriangle = 125;
constexpr size_t kEmbreeCompactBytesPerTriangle = 92;
Footprint referenceFootprint(const FootprintQuery& q) {
    Footprint f;
    const size_t pixels = size_t(q.resolution.x) * size_t(q.resolution.y);
    const bool compact = compactLayout(referenceParams().read(*q.params).bvh, q.triangles);
    const size_t perTriangle = (compact ? kEmbreeCompactBytesPerTriangle : kEmbreeBytesPerTriangle) + (q.moving ? 36 + 36 : 0);
    f.bytes = saturatingSum({saturatingMul(q.triangles, perTriangle), 48 * pixels});
    // Embree's builder holds primitive references and temporary nodes while it builds: at 74 M
    // triangles the run's peak stayed within 0.4 GiB of what was held after setup, so this is margin.
    f.peakBytes = saturatingMul(q.triangles, 32);
    f.threads = size_t(EmbreeTracer::threadsFor(std::get<int>(q.params->get("threads")), pixels));
    return f;
}

AlgorithmInfo referenceInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<Reference>(
        "reference", "ground truth: exact shadows ray-traced on the CPU with Embree (multi-threaded)",
        {LightType::Point, LightType::Spot, LightType::Directional, LightType::Area}, true, &referenceSchema);
    info.motion = MotionHandling::Refit;
    info.footprint = &referenceFootprint;
    info.takesOpacity = [](const ParamValues&) { return true; }; // the definition of a translucent shadow
    return info;
}

} // namespace shadowlab
