#pragma once
// Driving the app without a person: the command line's actions, applied through the same
// functions as the widgets (selectAlgorithm, applyParamChange, PathRecorder, saveRecordedConfig),
// and a JSON log of every rendered frame for tests to compare with the experiment runner.
#include "framework/core/Params.h"
#include "framework/experiment/Config.h"
#include "framework/gui/GuiOptions.h"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

struct GuiState;
class Viewer;

/// The command line checked against the config before any window opens.
struct AutomationPlan {
    int choice = 0;                                         ///< index into algorithmChoices(config)
    std::vector<std::pair<std::string, ParamValue>> sets;   ///< parsed and validated --set values
    std::optional<ParamValues> params;                      ///< the chosen algorithm's parameters with the --set values
};

/// The config as the session starts it: the chosen algorithm (a config entry, or one added as
/// --algorithm names it) with its --set values, for the checks run and validate make (the memory
/// plan, each algorithm's fit on the scene), so that what validate refuses the GUI refuses too,
/// as bad input, before the first frame.
ExperimentConfig configAsStarted(const ExperimentConfig& config, const AutomationPlan& plan);

/// Validates --algorithm, --set and --frame; throws InputError (one line) on the first problem.
AutomationPlan planAutomation(const GuiOptions& opts, const ExperimentConfig& config);

/// Applies the plan and the other options to the running app (selection, parameters, view, playback,
/// recorded keyframes, saved config). Throws InputError when the recorded config does not validate.
void applyAutomation(GuiState& s, const GuiOptions& opts, const AutomationPlan& plan);

/// Per rendered frame: the fly-through frame, camera and light poses, and stage times.
class FrameReport {
public:
    void add(const Viewer& viewer);
    void write(const std::string& file, const GuiState& s) const;

private:
    Json frames_ = Json::array();
};

} // namespace shadowlab
