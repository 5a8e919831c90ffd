#pragma once
// The one place an algorithm's lifecycle runs (ShadowAlgorithm.h describes it from the plugin's
// side). The runner, the GUI, its reference view and the tests all hold their algorithms through
// an AlgorithmHost, so the order of calls, the light check, the change kinds of parameters and the
// way a frame is timed and read back exist once:
//
//   AlgorithmHost host(info, params);        create
//   host.setScene(sceneGpu);                 preprocessing, timed (preprocessMs())
//   host.resize(resolution);                 the visibility target and image-size resources
//   host.setParams(next);                    Update / Recompile / Rebuild, whichever the changed keys need
//   FrameMeasurement m = host.computeFrame({gbuffer, cpuG, camera, light, frame}, timer);
//   std::vector<float> v = host.readVisibility();
#include "framework/algorithm/ShadowAlgorithm.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace shadowlab {

/// What one frame needs besides the algorithm and its target.
struct FrameView {
    const GBuffer& gbuffer;
    std::function<const CpuGBuffer&()> cpuGBuffer; ///< read back once per frame, on first use
    const Camera& camera;
    const Light& light;
    int frameIndex = 0;
};

/// What one frame of an algorithm cost and reported.
struct FrameMeasurement {
    std::vector<StageTime> stages; ///< the algorithm's stages, in the order it ran them
    double wallMs = 0;             ///< wall time of the whole frame, GL finished (timeWork)
    std::vector<Counter> counters;
    uint64_t overflow = 0;
    size_t memoryBytes = 0;
    size_t residentBytes = 0; ///< ShadowAlgorithm::residentBytes(): everything it holds
    /// stages plus the "total" row: summed GPU time, and the frame's wall time.
    std::vector<StageTime> stagesWithTotal() const;
};

class AlgorithmHost {
public:
    /// Creates the algorithm from validated values of info's schema; `options` hold for its life
    /// (statistics off = the timed pass, see AlgorithmOptions).
    AlgorithmHost(const AlgorithmInfo& info, ParamValues params, AlgorithmOptions options = {});
    ~AlgorithmHost();

    const AlgorithmInfo& info() const { return *info_; }
    const ParamValues& params() const { return params_; }
    const AlgorithmOptions& options() const { return options_; }
    const ShadowAlgorithm& algorithm() const { return *algorithm_; }

    /// Preprocessing for `scene` (kept by reference: it must outlive the host); then resize() again
    /// when a resolution is set. Its wall time, GL finished, is preprocessMs().
    void setScene(const SceneGpu& scene);
    double preprocessMs() const { return preprocessMs_; }
    /// Allocates the visibility target (R32F) and the algorithm's image-size resources.
    void resize(glm::ivec2 resolution);
    glm::ivec2 resolution() const { return resolution_; }

    /// Applies new values (of the same schema): the costliest change kind among the keys whose
    /// value differs; a Rebuild re-runs setScene() and resize(). Returns the kind applied, or
    /// nothing changed (returns Update with no call when no value differs).
    ParamChange setParams(const ParamValues& next);

    /// "" when the algorithm can run under `light` (and, for a moving scene, with its parameters), else the reason.
    std::string unsupportedReason(const Light& light) const;

    /// Runs one frame into the visibility target, timed with `timer` as the runner times every
    /// frame (timeWork). Throws RuntimeError when called before setScene()/resize() or with a
    /// light the algorithm does not support: a plugin never has to check either.
    FrameMeasurement computeFrame(const FrameView& view, StageTimer& timer);

    GLuint visibility() const { return visibility_.id(); }
    /// The visibility target on the CPU (row-major, width × height).
    std::vector<float> readVisibility() const;

private:
    const AlgorithmInfo* info_;
    ParamValues params_;
    AlgorithmOptions options_;
    std::unique_ptr<ShadowAlgorithm> algorithm_;
    const SceneGpu* scene_ = nullptr;
    glm::ivec2 resolution_{0, 0};
    GlTexture visibility_;
    double preprocessMs_ = 0;
    uint64_t seenPose_ = 0; ///< the scene's poseVersion() the algorithm last followed
};

} // namespace shadowlab
