#pragma once
// The interface every shadow algorithm implements, and its lifecycle:
//
//   1. create(params)      the registry's factory builds it from validated ParamValues.
//   2. setScene(scene)     per-scene work (acceleration structures, caches); timed as `preprocess`.
//   3. resize(resolution)  (re)allocates what depends on the image size; called after setScene()
//                          and whenever the resolution changes.
//   4. paramsChanged(p, c) new values; c = Rebuild means setScene() and resize() follow, c = Update
//                          means only uniforms change.
//   5. per frame:          sceneMoved(frame) first when moving parts changed pose since the last
//                          frame (or since setScene(), built at the rest pose); then
//                          computeVisibility(frame) writes visibility in [0, 1] per pixel into
//                          frame.visibility, timing its stages through frame.timer;
//                          then counters(), debugViews() and memoryBytes() describe that frame.
//
// The G-buffer and the shading pass are shared: an algorithm only produces visibility.
#include "framework/core/Params.h"
#include "framework/gl/StageTimer.h"
#include "framework/render/GBuffer.h"
#include "framework/render/SceneGpu.h"
#include "framework/view/Camera.h"
#include "framework/view/Light.h"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

/// Everything an algorithm may read for one frame.
struct FrameInputs {
    const GBuffer& gbuffer;
    /// The G-buffer on the CPU (CPU algorithms only; read back once per frame, shared).
    const std::function<const CpuGBuffer&()> cpuGBuffer;
    const Camera& camera;
    const Light& light;
    int frameIndex;
    GLuint visibility; ///< R32F texture of gbuffer.resolution() to write (image unit or FBO attachment)
    StageTimer& timer;
};

/// A named per-frame scalar gathered by the algorithm (e.g. nodes visited per pixel, mean and max).
struct Counter {
    std::string name;
    double value = 0;
};

/// A per-pixel debug image (e.g. a cost heat map): R32F texture, shown with a colour map over [0, maxValue].
struct DebugView {
    std::string name;
    GLuint texture = 0;
    float maxValue = 0; ///< 0 = use the image's maximum
    std::string unit;
};

/// How an algorithm follows moving geometry. The scene's shared buffers are always posed for the
/// frame (SceneGpu::setTime, the runner's `scene_update` stage); what else must move depends on
/// what the algorithm precomputed.
enum class MotionHandling {
    PerFrame,   ///< builds or renders everything from the posed scene buffers each frame: nothing more to do
    Rigid,      ///< moves its precomputed per-part structures with the parts' matrices (sceneMoved)
    Refit,      ///< refits its acceleration structure to the posed triangles (sceneMoved)
    StaticOnly, ///< precomputes over static geometry: a moving scene is bad input unless its
                ///< AlgorithmInfo::rebuildParam is true, when sceneMoved() rebuilds (and times) it all
};
const char* toString(MotionHandling m);

/// How the host runs every algorithm, fixed at creation (one mechanism for all plugins).
struct AlgorithmOptions {
    /// Statistics: counters, per-pixel debug images (heat maps) and the atomics that gather them.
    /// Off (every timed frame of an experiment; the runner's untimed statistics pass turns them on),
    /// they are compiled out of the shaders and counters()
    /// and debugViews() report only what is still measured; overflow and error detection stay
    /// (overflowCount() is exact in both modes) and the visibility is bit-identical.
    bool statistics = true;
};

/// A scene as an algorithm's memory estimate sees it, before the scene exists (checkMemoryPlan).
struct FootprintQuery {
    size_t triangles = 0;           ///< an upper bound of the scene's triangles
    glm::ivec2 resolution{0};
    float fovYDeg = 60, nearPlane = 0.05f, farPlane = 100; ///< the config's camera (fixed for a run)
    bool moving = false;            ///< the scene has moving parts
    const ParamValues* params = nullptr;
    size_t storageBlockBytes = 0;   ///< what one storage block addresses on this device, measured (MemoryPlan.cpp)
    size_t reportedStorageBlockBytes = 0; ///< GL_MAX_SHADER_STORAGE_BLOCK_SIZE, for plugins that check it themselves
    size_t textureBufferTexels = 0; ///< GL_MAX_TEXTURE_BUFFER_SIZE of this device
};

/// What an algorithm will hold for a FootprintQuery's scene, or why it cannot take it here.
struct Footprint {
    size_t bytes = 0;     ///< held for the run: its structures, copies of the scene, per-pixel images (host + GPU:
                          ///< a software renderer keeps GPU buffers in host memory)
    size_t peakBytes = 0; ///< held only while setScene() runs, on top of `bytes` (e.g. a clustering's working set)
    /// Of `bytes`, what lies in textures: freed by the driver as soon as the algorithm is destroyed
    /// (llvmpipe keeps a destroyed algorithm's buffers, not its textures, until the run ends).
    size_t textureBytes = 0;
    /// CPU threads it starts (0: none beyond one per core): under `ulimit -v` each maps a stack,
    /// which the plan sets aside (SystemMemory.cpp covers two per core).
    size_t threads = 0;
    std::string refusal;  ///< not empty: this algorithm cannot run the scene on this device, and why
};

/// The usual refusals of a Footprint: "" when `bytes` fit one storage block / `texels` one
/// buffer-texture view of the query's device, else a sentence naming `what` and the limit.
std::string storageRefusal(const FootprintQuery& q, const char* what, size_t bytes, bool reportedLimit = false);
std::string texelRefusal(const FootprintQuery& q, const char* what, size_t texels);

class ShadowAlgorithm {
public:
    virtual ~ShadowAlgorithm() = default;

    virtual void setScene(const SceneGpu& scene) = 0;
    virtual void resize(glm::ivec2 resolution) { (void)resolution; }
    virtual void paramsChanged(const ParamValues& params, ParamChange change) = 0;
    virtual void computeVisibility(const FrameInputs& frame) = 0;
    /// The scene's moving parts changed pose (SceneGpu::pose()) since the algorithm last saw it;
    /// called just before computeVisibility() and timed with it, so stages go through frame.timer.
    /// PerFrame algorithms need not override it.
    virtual void sceneMoved(const FrameInputs& frame) { (void)frame; }

    virtual std::vector<Counter> counters() const { return {}; }
    virtual std::vector<DebugView> debugViews() const { return {}; }
    /// Bytes of GPU (or CPU, for CPU algorithms) memory the algorithm holds for its structures.
    virtual size_t memoryBytes() const { return 0; }
    /// Every byte it holds (host and GPU) for the memory report: memoryBytes() plus copies of the
    /// scene and per-pixel images that the paper's figure leaves out.
    virtual size_t residentBytes() const { return memoryBytes(); }
    /// Fixed-size structures that overflowed in the last frame (0 = the image is trustworthy).
    virtual uint64_t overflowCount() const { return 0; }
    /// The value each parameter whose choice depends on the device ("auto", "0 = ...") resolved to
    /// on this device with the current values, as (key, value) text in schema order, e.g.
    /// {"traversal", "packet"}; empty when it has none. `shadowlab info` and summary.json report it.
    virtual std::vector<std::pair<std::string, std::string>> resolvedParams() const { return {}; }
};

/// One registered algorithm: the registry key is also its folder, JSON "algorithm" value and label.
struct AlgorithmInfo {
    std::string name;
    std::string summary;          ///< one line for `shadowlab list`
    std::vector<LightType> lights; ///< light types it supports
    bool exact = false;           ///< exact hard shadows: held to the reference's tiny mismatch
    MotionHandling motion = MotionHandling::PerFrame;
    std::string rebuildParam;     ///< StaticOnly: the bool parameter that allows moving scenes (rebuilt each frame)
    const ParamSchema& (*schema)();
    std::unique_ptr<ShadowAlgorithm> (*create)(const ParamValues& params, const AlgorithmOptions& options);
    /// Its memory estimate for a scene, before the scene exists; nullptr: nothing that grows with the
    /// scene. The runner refuses a run up front when one refuses or the sum exceeds the machine.
    Footprint (*footprint)(const FootprintQuery& query) = nullptr;
    /// Once the scene exists, before anything is built for it: "" when the algorithm's structures
    /// for `scene` fit this device (current GL context) with `params`, else why not (the refusal
    /// setScene() would throw as SceneRefusal). nullptr: the footprint decides everything. Run by
    /// `validate`, so that what it accepts, run runs.
    std::string (*sceneCheck)(const Scene& scene, const ParamValues& params) = nullptr;
    /// Whether it honours material opacity below 1 (translucent casters) with these parameters;
    /// nullptr: never (its shadows are opaque). An exact algorithm that does not is refused a scene
    /// with translucent triangles, whose reference shadows it could not match.
    bool (*takesOpacity)(const ParamValues& params) = nullptr;

    bool supports(LightType t) const;
    /// "" when the algorithm can run on a scene that moves with these parameter values, else why not.
    std::string motionRefusal(const ParamValues& params) const;
};

/// Every registered algorithm, in registration order (algorithms/Registry.cpp).
const std::vector<AlgorithmInfo>& algorithmRegistry();
/// The entry called `name`, or nullptr.
const AlgorithmInfo* findAlgorithm(const std::string& name);

} // namespace shadowlab
