#pragma once
// The memory a run will need, estimated before the scene exists: the scene on the host and on the
// GPU, what loading it holds at its peak, and each algorithm's own Footprint. A run that cannot fit
// (or that an algorithm refuses on this device) stops with a one-line InputError (exit 2) before
// anything large is allocated; the plan is also written to summary.json beside what was measured.
#include "framework/core/Error.h"
#include "framework/core/JsonNode.h"
#include "framework/core/SystemMemory.h"
#include "framework/experiment/Config.h"
#include "framework/scene/SceneConfig.h"

#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

/// The framework's bytes per image pixel (G-buffer and its host copy, masks, shading, each
/// algorithm's visibility read back, the images written), a bound of what was measured on llvmpipe
/// (results/reference/memory_bounds_llvmpipe.md).
constexpr size_t kFrameBytesPerPixel = 64;

/// The device's limits an algorithm's estimate depends on (read from the current GL context).
struct DeviceLimits {
    size_t storageBlockBytes = 0; ///< what one storage block addresses, measured (see MemoryPlan.cpp)
    size_t textureBufferTexels = 0;
    size_t reportedStorageBlockBytes = 0; ///< GL_MAX_SHADER_STORAGE_BLOCK_SIZE
};
/// The limits for a scene of up to `triangles` (which decides whether the storage probe runs).
DeviceLimits currentDeviceLimits(size_t triangles);

struct MemoryPlan {
    size_t triangles = 0;
    bool moving = false;
    std::vector<std::pair<std::string, size_t>> held; ///< what stays for the run, by part: "scene", "scene_gpu", "frame buffers", then ids
    size_t loadPeak = 0;   ///< bytes while the scene is made (a grid's copies and the scene they go into)
    size_t peak = 0;       ///< the estimated peak: the load's, or the held parts' with each setScene() transient on
                           ///< top of what is held when it runs (entries are set up in order)
    size_t available = 0;  ///< MemAvailable when planned
    size_t machine = 0;    ///< MemTotal
    Json toJson() const;
    /// "13.2 GiB estimated of 22.1 GiB available (scene 3.6, scene_gpu 3.6, reference 2.9, ...)".
    std::string summary() const;
};

/// The plan for `cfg` with the predicted `scene` (predictScene: its triangles are at most these);
/// throws InputError naming cfg.file and the JSON path (the algorithm entry that refuses, or /scene)
/// when an algorithm refuses the scene on this device or the plan's peak exceeds the memory available.
MemoryPlan checkMemoryPlan(const ExperimentConfig& cfg, const ScenePrediction& scene, const DeviceLimits& limits);
/// As above against `machine` instead of this machine's /proc/meminfo (tests).
MemoryPlan checkMemoryPlan(const ExperimentConfig& cfg, const ScenePrediction& scene, const DeviceLimits& limits,
                           const SystemMemory& machine);
/// What the predicted scene holds on the host (Scene::bytes()) and on the GPU (SceneGpu::bytes()).
size_t predictedSceneBytes(const ScenePrediction& scene);
size_t predictedSceneGpuBytes(const ScenePrediction& scene);

/// Once cfg.scene exists: every algorithm entry's sceneCheck on it (current GL context); throws
/// InputError at the first entry that refuses, naming its JSON path (`validate`, so that what it
/// accepts, run runs).
void checkAlgorithmsTakeScene(const ExperimentConfig& cfg);
/// The InputError for an algorithm entry whose setScene() threw SceneRefusal.
InputError sceneRefusalError(const ExperimentConfig& cfg, const AlgorithmEntry& entry, std::string why);

/// One line per algorithm entry: its estimate, or why it refuses the scene here (never throws):
/// what `shadowlab plan` prints, to find the size where each algorithm stops.
std::vector<std::string> describeFootprints(const ExperimentConfig& cfg, size_t triangles, bool moving, const DeviceLimits& limits);

/// "1.23 GiB", or "45.6 MiB" below a tenth of a GiB.
std::string formatMemorySize(size_t bytes);

} // namespace shadowlab
