#pragma once
// Runs the runs of a sweep on this machine, each as its own `shadowlab run` process (isolated: a
// crash or a GL error in one run leaves the others alone), several at once with `jobs`.
#include "framework/sweep/SweepFile.h"

#include <string>
#include <vector>

namespace shadowlab {

struct SweepRunOptions {
    std::string outputDir;        ///< DIR: DIR/sweep.json, DIR/runs/ID/, DIR/runs/ID.{config.json,log,error.json}
    size_t jobs = 1;              ///< runs at once
    std::vector<size_t> indices;  ///< the runs to do (indices into Sweep::runs)
    std::string binary;           ///< the shadowlab binary that runs each point
};

/// Where a run's files go.
struct RunPaths {
    std::string dir, config, log, error;
    RunPaths(const std::string& outputDir, const std::string& id);
    bool complete() const; ///< the run directory has its summary.json (written last, see Runner.h)
};

/// Writes DIR/sweep.json (the self-contained snapshot) unless it holds the same sweep already:
/// array tasks of one Slurm job all start from it and must not race to rewrite it.
void writeSweepSnapshot(const Sweep& sweep, const std::string& outputDir);

/// Runs the selected runs that are not complete and prints a line per run on stderr. A failed run
/// leaves DIR/runs/ID.error.json and the others go on. Returns the exit code: 0 when every
/// selected run is complete, 1 when one failed, 128 + signal when interrupted by SIGINT/SIGTERM
/// (the running runs are stopped first; their partial folders never look complete).
int runSweep(const Sweep& sweep, const SweepRunOptions& options);

/// This process's own binary (/proc/self/exe), which also runs the points of a sweep.
std::string selfBinary();

} // namespace shadowlab
