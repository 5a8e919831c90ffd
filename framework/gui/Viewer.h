#pragma once
// The GUI's model: one scene, one active algorithm and the per-frame pipeline of Runner.cpp
// (G-buffer → algorithm → visibility → shading), with the camera, light and fly-through state the
// panels edit. It holds no ImGui code, so automation and widgets drive it through the same calls.
#include "framework/algorithm/AlgorithmHost.h"
#include "framework/experiment/Config.h"
#include "framework/render/ShadingPass.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace shadowlab {

/// One entry of the algorithm switcher: a config entry or a registered algorithm with its defaults.
struct AlgorithmChoice {
    std::string label;      ///< config entry id, or the registered name
    bool fromConfig = false;
    const AlgorithmInfo* info = nullptr;
    ParamValues params;     ///< current values; edits survive switching away and back
};

/// The switcher's list: the config's entries (its reference included), then every registered algorithm.
std::vector<AlgorithmChoice> algorithmChoices(const ExperimentConfig& config);
/// The choice labelled `idOrName` (config ids first, then registered names), or -1.
int findChoice(const std::vector<AlgorithmChoice>& choices, const std::string& idOrName);

/// Playback of the config's camera and light paths: frame i is sampled exactly as `shadowlab run`
/// samples it (ExperimentConfig::cameraAt/lightAt), so what is seen here is what gets measured.
struct Playback {
    int frame = 0;            ///< in [0, config.frames)
    bool playing = false;     ///< advance one path frame per rendered frame
    bool followCamera = true; ///< the camera path drives the camera (when the config has one)
    bool followLight = true;  ///< the light path drives the light (when the config has one)
    bool loop = true;
};

class Viewer {
public:
    /// `source` is the config JSON as written: recorded paths are saved with the same scene.
    /// Needs a current GL context; uploads the scene and instantiates the first choice.
    Viewer(ExperimentConfig config, Json source);
    ~Viewer();

    const ExperimentConfig& config() const { return config_; }
    const Json& source() const { return source_; }
    /// Replaces the camera path the playback follows (e.g. with a freshly recorded one).
    void setCameraPath(Path path);

    // Algorithm switching. Config entries come first, then every registered algorithm.
    const std::vector<AlgorithmChoice>& choices() const { return choices_; }
    int activeIndex() const { return active_; }
    const AlgorithmChoice& active() const { return choices_[size_t(active_)]; }
    int findChoice(const std::string& idOrName) const { return shadowlab::findChoice(choices_, idOrName); }
    void selectAlgorithm(int index);
    /// Why the active algorithm cannot run under the current light; empty when it can.
    std::string unsupportedReason() const;
    const ShadowAlgorithm* algorithm() const { return host_ ? &host_->algorithm() : nullptr; }

    Camera camera; ///< edited by the camera controller and panels; overwritten by a followed path
    Light light;   ///< edited by the light panel; overwritten by a followed path
    Playback playback;
    /// Sets camera and light from the followed paths at playback.frame.
    void applyPlayback();
    /// Advances playback.frame by one when playing (wrapping or stopping at the end).
    void stepPlayback();

    /// Reallocates everything that depends on the image size (G-buffer, shading, visibility, algorithm).
    void setResolution(glm::ivec2 resolution);
    /// The scene clock of the last rendered frame (moving parts are posed at it).
    double sceneTime() const { return sceneTime_; }
    glm::ivec2 resolution() const { return resolution_; }

    /// Renders one frame: G-buffer, the active algorithm's visibility (timed), shading.
    void renderFrame();
    /// Runs another hosted algorithm on the frame last rendered (the reference view).
    FrameMeasurement runOn(AlgorithmHost& host, StageTimer& timer);

    const SceneGpu& sceneGpu() const { return *sceneGpu_; }
    GLuint shadedTexture() const { return shading_->output(); }
    GLuint visibilityTexture() const { return host_->visibility(); }
    /// The G-buffer of the last frame on the CPU (read back once per frame, on first use).
    const CpuGBuffer& cpuGBuffer();
    /// Stages of the last frame (GPU and CPU ms), as StageTimer::collect() returned them.
    const std::vector<StageTime>& lastStages() const { return lastStages_; }
    double lastAlgorithmWallMs() const { return lastWallMs_; }
    /// True where stage times come from the wall clock instead of GL timer queries (CPU rasterisers).
    bool wallClockStages() const { return timer_.synchronous(); }
    int renderedFrames() const { return renderedFrames_; }

private:
    friend void applyParamChanges(Viewer& viewer, const std::vector<std::pair<std::string, ParamValue>>& changes);
    void instantiate();

    ExperimentConfig config_;
    Json source_;
    std::unique_ptr<SceneGpu> sceneGpu_;
    std::vector<AlgorithmChoice> choices_;
    int active_ = 0;
    std::unique_ptr<AlgorithmHost> host_;

    glm::ivec2 resolution_{0, 0};
    double sceneTime_ = 0;
    std::unique_ptr<GBuffer> gbuffer_;
    std::unique_ptr<ShadingPass> shading_;
    StageTimer timer_;
    std::optional<CpuGBuffer> cpuG_;
    std::vector<StageTime> lastStages_;
    double lastWallMs_ = 0;
    int renderedFrames_ = 0;
};

/// The one way parameters change, shared by the widgets and the automation (--set): validates
/// every value through ParamValues::set (InputError when unknown or out of range, leaving all the
/// old values), then applies them all at once through AlgorithmHost::setParams (one update,
/// recompile or rebuild, the costliest the changed keys need).
void applyParamChanges(Viewer& viewer, const std::vector<std::pair<std::string, ParamValue>>& changes);
/// One parameter: applyParamChanges() with a single change.
void applyParamChange(Viewer& viewer, const std::string& key, const ParamValue& value);

} // namespace shadowlab
