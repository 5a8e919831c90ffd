#include "framework/algorithm/AlgorithmHost.h"

#include "framework/core/Error.h"
#include "framework/gl/GlObjects.h"

#include <chrono>

namespace shadowlab {

std::vector<StageTime> FrameMeasurement::stagesWithTotal() const {
    std::vector<StageTime> out = stages;
    out.push_back({"total", sumGpuMs(stages), wallMs});
    return out;
}

AlgorithmHost::AlgorithmHost(const AlgorithmInfo& info, ParamValues params, AlgorithmOptions options)
    : info_(&info), params_(std::move(params)), options_(options), algorithm_(info.create(params_, options_)) {}

AlgorithmHost::~AlgorithmHost() = default;

void AlgorithmHost::setScene(const SceneGpu& scene) {
    auto start = std::chrono::steady_clock::now();
    scene_ = &scene;
    algorithm_->setScene(scene);
    seenPose_ = 0;  // setScene() builds from Scene::positions, the rest pose
    if (resolution_.x > 0) algorithm_->resize(resolution_);
    glFinish();
    preprocessMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void AlgorithmHost::resize(glm::ivec2 resolution) {
    if (resolution == resolution_ && visibility_) return;
    resolution_ = resolution;
    visibility_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
    if (scene_) algorithm_->resize(resolution);
}

ParamChange AlgorithmHost::setParams(const ParamValues& next) {
    bool changed = false;
    ParamChange kind = ParamChange::Update;
    for (const ParamSpec& s : info_->schema().specs())
        if (next.get(s.key) != params_.get(s.key)) {
            changed = true;
            kind = std::max(kind, s.change);
        }
    if (!changed) return ParamChange::Update;
    params_ = next;
    algorithm_->paramsChanged(params_, kind);
    if (kind == ParamChange::Rebuild && scene_) setScene(*scene_);
    return kind;
}

std::string AlgorithmHost::unsupportedReason(const Light& light) const {
    if (!info_->supports(light.type)) return info_->name + " does not support " + toString(light.type) + " lights";
    return scene_ && scene_->dynamic() ? info_->motionRefusal(params_) : "";
}

FrameMeasurement AlgorithmHost::computeFrame(const FrameView& view, StageTimer& timer) {
    if (!scene_) throw RuntimeError(info_->name + ": a frame was requested before setScene()");
    if (view.gbuffer.resolution() != resolution_) resize(view.gbuffer.resolution());
    if (std::string why = unsupportedReason(view.light); !why.empty()) throw RuntimeError(why);
    const FrameInputs inputs{view.gbuffer, view.cpuGBuffer, view.camera, view.light, view.frameIndex, visibility_.id(), timer};
    const bool moved = scene_->poseVersion() != seenPose_;
    seenPose_ = scene_->poseVersion();
    TimedWork timed = timeWork(timer, [&] {
        if (moved) algorithm_->sceneMoved(inputs);
        algorithm_->computeVisibility(inputs);
    });
    FrameMeasurement m;
    m.stages = std::move(timed.stages);
    m.wallMs = timed.wallMs;
    m.counters = algorithm_->counters();
    m.overflow = algorithm_->overflowCount();
    m.memoryBytes = algorithm_->memoryBytes();
    m.residentBytes = algorithm_->residentBytes();
    return m;
}

std::vector<float> AlgorithmHost::readVisibility() const { return readTextureR32F(visibility_.id(), resolution_.x, resolution_.y); }

} // namespace shadowlab
