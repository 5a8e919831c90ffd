#include "algorithms/reference/Reference.h"

#include "algorithms/AlgorithmSupport.h"
#include "algorithms/reference/EmbreeTracer.h"

#include <chrono>
#include <memory>

namespace shadowlab {
namespace {

const ParamSchema& referenceSchema() {
    static const ParamSchema schema = ParamSchema()
        .integer("threads", 0, 0, 256, "",
                 "CPU threads tracing rays (0 = all hardware threads)", ParamChange::Update)
        // Relative to the scene so one default suits scenes of any scale; 1e-4 of the radius clears
        // float error of the G-buffer positions without visibly detaching contact shadows.
        .real("ray_offset", 1e-4, 0.0, 1e-2, "× scene radius",
              "shadow ray origin offset along the surface normal, against self-intersection", ParamChange::Update);
    return schema;
}

class Reference final : public ShadowAlgorithm {
public:
    explicit Reference(const ParamValues& params) { read(params); }

    void setScene(const SceneGpu& scene) override {
        tracer_.reset(); // free the old BVH before building the new one
        tracer_ = std::make_unique<EmbreeTracer>(scene.cpu());
        sceneRadius_ = scene.bounds().empty() ? 1.0f : scene.bounds().radius();
    }

    void paramsChanged(const ParamValues& params, ParamChange) override { read(params); }

    void computeVisibility(const FrameInputs& frame) override {
        const CpuGBuffer& g = frame.cpuGBuffer();
        frame.timer.begin("trace", false); // CPU stage: no GPU query
        auto t0 = std::chrono::steady_clock::now();
        tracer_->traceVisibility(g, frame.light, rayOffset_ * sceneRadius_, threads_, visibility_);
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

    /// The visibility of the last frame (row-major, width * height), as uploaded.
    const std::vector<float>& lastVisibility() const { return visibility_; }

private:
    void read(const ParamValues& params) {
        threads_ = params.getInt("threads");
        rayOffset_ = float(params.getFloat("ray_offset"));
    }

    std::unique_ptr<EmbreeTracer> tracer_;
    float sceneRadius_ = 1.0f;
    int threads_ = 0;
    float rayOffset_ = 1e-4f;
    std::vector<float> visibility_;
    double rays_ = 0, mraysPerS_ = 0;
};

} // namespace

AlgorithmInfo referenceInfo() {
    return makeAlgorithmInfo<Reference>("reference",
                                        "ground truth: exact shadows ray-traced on the CPU with Embree (multi-threaded)",
                                        {LightType::Point, LightType::Spot, LightType::Directional, LightType::Area},
                                        true, &referenceSchema);
}

} // namespace shadowlab
