#pragma once
// Runs an experiment: scene → G-buffer → each algorithm → visibility → shading → metrics → results.
#include "framework/experiment/Config.h"
#include "framework/experiment/OutputPlace.h"
#include "framework/experiment/Results.h"

#include <string>

namespace shadowlab {

struct RunOptions {
    std::string outputDir;  ///< overrides the config's output.dir when not empty
    bool force = false;     ///< replace an existing output directory (only once the new run is complete)
    bool progress = true;   ///< progress bar on stderr
    bool writeOutputs = true;
    /// The output place, already opened (checked and locked) by the caller before the scene was
    /// loaded; when null and writeOutputs, runExperiment opens it itself.
    OutputPlace* place = nullptr;
    /// The memory plan checked before the scene was made (MemoryPlan::toJson), written to
    /// summary.json beside what was measured; null when the caller made none.
    Json memoryPlan;
};

/// Runs the experiment on the current GL context and writes its output directory.
/// The directory is assembled under DIR.partial-PID and swapped into place at the end (OutputPlace),
/// so an interrupted run never leaves a summary that looks complete, and an existing DIR is never
/// replaced unless `force` (an InputError otherwise). SIGINT/SIGTERM (installInterruptHandlers)
/// stop it between frames with Interrupted, the previous results kept.
ExperimentResults runExperiment(const ExperimentConfig& config, const RunOptions& options, const std::string& backend);

} // namespace shadowlab
