#pragma once
// An experiment config (see docs/config.md): scene, camera and light paths, algorithm entries,
// outputs. Parsing is strict: unknown keys are errors naming their JSON path; missing keys take
// defaults; `resolved` holds every value actually used (written as config.resolved.json).
#include "framework/algorithm/ShadowAlgorithm.h"
#include "framework/experiment/Expectations.h"
#include "framework/scene/Scene.h"
#include "framework/scene/SceneConfig.h"
#include "framework/view/Camera.h"
#include "framework/view/Light.h"
#include "framework/view/Path.h"

#include <memory>
#include <string>
#include <vector>

namespace shadowlab {

struct AlgorithmEntry {
    std::string id;              ///< unique label in results (defaults to the algorithm name)
    const AlgorithmInfo* info = nullptr;
    ParamValues params;
    std::string jsonPath;        ///< where it was declared, for error messages
};

struct ExperimentConfig {
    std::string file;            ///< the config file
    std::string name = "experiment";
    glm::ivec2 resolution{256, 256};
    int frames = 30;
    int warmupFrames = 3;
    /// Times the timed pass is run (every frame, every algorithm), the algorithms' order rotated
    /// each time so a load spike on a shared machine falls on all of them alike; the first one's
    /// images and accuracy are reported, every one's times (Results.h).
    int repeats = 1;
    /// Which frames the untimed statistics pass runs on (counters, heat maps). Timed frames always
    /// run with the statistics compiled out (AlgorithmOptions::statistics off).
    enum class Statistics { Images, All, None };
    Statistics statistics = Statistics::Images;

    std::shared_ptr<Scene> scene;
    Camera camera;               ///< fov/near/far, and the static pose when there is no path
    Path cameraPath;
    Light light;                 ///< type and shape, and the static pose when there is no path
    Path lightPath;

    bool reference = true;       ///< compare against the `reference` algorithm
    AlgorithmEntry referenceEntry;
    std::vector<AlgorithmEntry> algorithms;

    std::vector<Expectation> expectations; ///< `expect`: bounds checked once the results are written

    std::string outputDir;       ///< resolved against the config's folder
    /// Why results/NAME cannot be the output folder when output.dir is not given ("" when it can):
    /// refused where that default is used, not where `--out` names another (twenty-fourth probe).
    std::string defaultOutputProblem;
    std::vector<int> imagesAtFrames;
    bool plots = true;

    Json resolved;

    Camera cameraAt(int frame) const;
    /// The scene's clock at `frame`: uniformly over scene.time_range when given, else over the
    /// camera path's times, else the light path's, else the span of the scene's own motion.
    double sceneTimeAt(int frame) const;
    Light lightAt(int frame) const;
    /// The frames of the statistics pass, in order: images_at_frames, every frame, or none.
    std::vector<int> statisticsFrames() const;
    /// The ids an expectation can name: the algorithms', which of them are exact, and the reference.
    ExpectationIds expectationIds() const;
};
const char* toString(ExperimentConfig::Statistics s);

/// Whether `id` can label an algorithm's results: 1 to 64 letters, digits, '_', '-' or '.',
/// starting with a letter or digit. Ids name result files (images/ID_f0000_shaded.png), columns (a
/// '-' first would make "-A1" a formula in sweep.csv) and plot legends (matplotlib hides a label
/// starting with '_'), so a summary.json whose ids break it is no run's (compare, history and
/// sweep merge refuse it).
bool isAlgorithmId(const std::string& id);
/// Whether `name` can be a stage's or a counter's name in summary.json: the same rule as an id
/// (they are columns, table rows and measure names; the algorithms' own are lower-case words).
inline bool isMeasureName(const std::string& name) { return isAlgorithmId(name); }

/// "frame F (time T s)", as errors about one frame name it.
std::string frameText(const ExperimentConfig& config, int frame);

/// InputError unless the scene posed for `frame` (its bounds `b`) lies within ±1e15 scene units.
void checkPoseBounds(const ExperimentConfig& config, int frame, const Bounds& b);

/// Limits of camera and light values, shared by the parser and the GUI's widgets (so whatever the
/// widgets allow can be saved as a config).
namespace configlimits {
// Doubles, as the parser reads numbers: a float 0.1 is 0.100000001, and "cone_deg": 0.1 was out of
// its own range [0.1, 89] (twelfth probe).
constexpr double kFovMinDeg = 1.0, kFovMaxDeg = 179.0;
constexpr double kConeMinDeg = 0.1, kConeMaxDeg = 89.0;
constexpr int kAreaSamplesMin = 1, kAreaSamplesMax = 1024;
constexpr int kResolutionMin = 8, kResolutionMax = 8192; ///< each side of a frame, pixels
} // namespace configlimits

/// Reads and validates a config file (and loads its scene unless `loadScene` is false).
/// `overrides` are "dotted.path=VALUE" assignments applied before validation (applyOverride).
ExperimentConfig loadConfig(const std::string& file, bool loadScene = true,
                            const std::vector<std::string>& overrides = {});
/// Applies one command-line override "a.b.2.c=VALUE" to a config: object keys by name (created when
/// missing), array elements by index; VALUE is JSON (`[64,64]`, `3`, `true`, `"x"`) or else a plain
/// string. The result is validated like the file itself, so a typo still fails loudly.
void applyOverride(Json& config, const std::string& assignment);
/// Same, from JSON already in memory; `file` names it in errors and anchors relative paths.
ExperimentConfig parseConfig(const Json& json, const std::string& file, bool loadScene = true);
/// The config's scene counted without making it (predictScene), with the same overrides.
ScenePrediction predictConfigScene(const std::string& file, const std::vector<std::string>& overrides = {});
/// The same for a config already read (`file` names it in errors).
ScenePrediction predictConfigScene(const Json& config, const std::string& file);

} // namespace shadowlab
