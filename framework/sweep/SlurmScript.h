#pragma once
// `sweep slurm`: an sbatch array script that runs a sweep on a Slurm cluster, one array task per
// run (or per shard), each task an ordinary `shadowlab sweep run --index K` on a compute node.
#include "framework/sweep/SweepFile.h"

#include <string>

namespace shadowlab {

struct SlurmOptions {
    std::string outputDir;   ///< DIR; must be on a file system the compute nodes share (docs/cluster.md)
    std::string outputFrom = "--out"; ///< where DIR was given, for errors: "--out", or the sweep file
    std::string outputJsonPath;       ///< and its JSON path there ("/output/dir"), empty for --out
    std::string partition;   ///< --partition, empty: the cluster's default
    int gpusPerTask = 0;     ///< --gpus-per-task (0..64); > 0 runs shadowlab-egl (GPU, no display) instead of shadowlab (OSMesa)
    int cpusPerTask = 0;     ///< --cpus-per-task (0..1024), 0: the cluster's default
    std::string time;        ///< --time per task, e.g. 01:00:00; empty: the partition's default
    size_t maxParallel = 0;  ///< the array's %K throttle, 0: none
    size_t shards = 0;       ///< 0: one task per run; N: N tasks, task i doing runs i, i+N, i+2N, ...
};

/// Checks every value that goes into an #SBATCH line, so that none can end the line or add an
/// option: the partition (Slurm names: letters, digits, _ . - and commas between names), the time
/// (Slurm's formats: M, M:S, H:M:S, D-H, D-H:M, D-H:M:S, or UNLIMITED), the output folder (no
/// control character, and no % or \, which --output would read as a file name pattern).
/// InputError naming the option (or the sweep file's output.dir) otherwise.
void checkSlurmOptions(const SlurmOptions& options);

/// The sbatch script text for `sweep` (its snapshot at DIR/sweep.json), run by `binary`. Calls
/// checkSlurmOptions; the job name is made of the sweep's name, characters outside Slurm names
/// replaced by '_'; the paths are quoted both for sbatch's reading of #SBATCH lines and for bash.
std::string slurmScript(const Sweep& sweep, const SlurmOptions& options, const std::string& binary);

/// Writes DIR/sweep.json and DIR/sweep.sbatch (and DIR/slurm/ for the tasks' logs); returns the
/// script's path. `binary` is the shadowlab that wrote it; the tasks run it, or shadowlab-egl
/// beside it when GPUs are requested.
std::string writeSlurmScript(const Sweep& sweep, const SlurmOptions& options, const std::string& binary);

/// Submits the script: `sbatch --parsable SCRIPT` (argv, no shell; sbatch found on PATH); returns the
/// job id. RuntimeError when sbatch fails or prints no job id.
std::string submitSlurmScript(const std::string& script);

} // namespace shadowlab
