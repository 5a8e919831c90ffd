#include "framework/gui/Viewer.h"

#include "framework/core/Error.h"
#include "framework/gl/GlContext.h"

#include <chrono>

namespace shadowlab {

Viewer::Viewer(ExperimentConfig config, Json source) : config_(std::move(config)), source_(std::move(source)) {
    camera = config_.camera;
    light = config_.light;
    sceneGpu_ = std::make_unique<SceneGpu>(*config_.scene);
    // As in the runner: a CPU rasteriser's timer queries misattribute compute work, so its stages
    // are timed by their wall clock, each run to completion.
    timer_.setSynchronous(isSoftwareRenderer(glRendererString()));

    choices_ = algorithmChoices(config_);
    applyPlayback();
    instantiate();
}

Viewer::~Viewer() = default;

void Viewer::setCameraPath(Path path) {
    config_.cameraPath = std::move(path);
    playback.frame = 0;
    applyPlayback();
}

std::vector<AlgorithmChoice> algorithmChoices(const ExperimentConfig& config) {
    std::vector<AlgorithmChoice> choices;
    // Config entries keep their ids and tuned params; the reference is listed like any entry.
    for (const AlgorithmEntry& e : config.algorithms) choices.push_back({e.id, true, e.info, e.params});
    if (config.reference)
        choices.push_back({config.referenceEntry.id, true, config.referenceEntry.info, config.referenceEntry.params});
    for (const AlgorithmInfo& a : algorithmRegistry()) choices.push_back({a.name, false, &a, ParamValues(a.schema())});
    return choices;
}

int findChoice(const std::vector<AlgorithmChoice>& choices, const std::string& idOrName) {
    for (bool fromConfig : {true, false})
        for (size_t i = 0; i < choices.size(); ++i)
            if (choices[i].fromConfig == fromConfig && choices[i].label == idOrName) return int(i);
    return -1;
}

void Viewer::selectAlgorithm(int index) {
    if (index < 0 || size_t(index) >= choices_.size()) throw InputError("", "", "no algorithm choice " + std::to_string(index));
    if (index == active_ && host_) return;
    active_ = index;
    instantiate();
}

std::string Viewer::unsupportedReason() const { return host_->unsupportedReason(light); }

void Viewer::instantiate() {
    const AlgorithmChoice& c = active();
    // Drop the old instance first: two sets of shadow maps or trees need not fit at once.
    host_.reset();
    host_ = std::make_unique<AlgorithmHost>(*c.info, c.params);
    if (resolution_.x > 0) host_->resize(resolution_);
    host_->setScene(*sceneGpu_);
}

void Viewer::applyPlayback() {
    if (playback.followCamera && !config_.cameraPath.empty()) {
        Camera c = config_.cameraAt(playback.frame);
        camera.position = c.position;
        camera.target = c.target;
    }
    if (playback.followLight && !config_.lightPath.empty()) {
        Light l = config_.lightAt(playback.frame);
        light.position = l.position;
        light.target = l.target;
    }
}

void Viewer::stepPlayback() {
    if (!playback.playing) return;
    if (playback.frame + 1 < config_.frames) ++playback.frame;
    else if (playback.loop) playback.frame = 0;
    else playback.playing = false;
}

void Viewer::setResolution(glm::ivec2 res) {
    if (res == resolution_ || res.x <= 0 || res.y <= 0) return;
    resolution_ = res;
    gbuffer_ = std::make_unique<GBuffer>(res);
    shading_ = std::make_unique<ShadingPass>(res);
    cpuG_.reset();
    if (host_) host_->resize(res);
}

const CpuGBuffer& Viewer::cpuGBuffer() {
    if (!cpuG_) cpuG_ = gbuffer_->readBack();
    return *cpuG_;
}

FrameMeasurement Viewer::runOn(AlgorithmHost& host, StageTimer& timer) {
    return host.computeFrame({*gbuffer_, [this]() -> const CpuGBuffer& { return cpuGBuffer(); }, camera, light, playback.frame},
                             timer);
}

void Viewer::renderFrame() {
    if (resolution_.x <= 0) return;
    // Moving parts follow the playback frame (and so the scrubber) on the runner's clock.
    sceneTime_ = config_.sceneTimeAt(playback.frame);
    TimedWork sceneUpdate = sceneGpu_->setTime(sceneTime_, timer_);
    gbuffer_->render(*sceneGpu_, camera);
    cpuG_.reset();
    lastStages_.clear();
    if (unsupportedReason().empty()) {
        FrameMeasurement m = runOn(*host_, timer_);  // measured as the runner measures a frame
        lastWallMs_ = m.wallMs + sceneUpdate.wallMs;
        lastStages_ = std::move(sceneUpdate.stages);
        lastStages_.insert(lastStages_.end(), m.stages.begin(), m.stages.end());
    } else {
        // Shown unshadowed rather than with stale visibility; the panel says why.
        const float one = 1.0f;
        glClearTexImage(host_->visibility(), 0, GL_RED, GL_FLOAT, &one);
        lastWallMs_ = 0;
    }
    shading_->run(*gbuffer_, host_->visibility(), light);
    ++renderedFrames_;
}

void applyParamChanges(Viewer& viewer, const std::vector<std::pair<std::string, ParamValue>>& changes) {
    if (changes.empty()) return;
    AlgorithmChoice& choice = viewer.choices_[size_t(viewer.active_)];
    ParamValues next = choice.params;
    for (const auto& [key, value] : changes) next.set(key, value);  // throws on a bad value; nothing changed yet
    next.checkRules("", "");  // a combination no config could hold is refused too, before anything changes
    choice.params = next;
    viewer.host_->setParams(choice.params);
}

void applyParamChange(Viewer& viewer, const std::string& key, const ParamValue& value) {
    applyParamChanges(viewer, {{key, value}});
}

} // namespace shadowlab
