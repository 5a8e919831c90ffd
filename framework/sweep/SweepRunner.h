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
    bool part = false;            ///< a part of the sweep (--index, --shard): other parts may run beside it
    std::string binary;           ///< the shadowlab binary that runs each point
};

/// Where a run's files go.
struct RunPaths {
    std::string id;
    std::string dir, config, log, error, lock; ///< lock: held by the sweep process running it
    RunPaths(const std::string& outputDir, const std::string& id);
    /// Whether this run finished here: DIR/runs/ID is a folder of its own (not a link), its
    /// summary.json (written last, see Runner.h) parses and says `"complete": true`, and its
    /// config.resolved.json is this run's config (its runId is ID), so another run's folder copied
    /// or linked into the slot, or a slot run from an edited config, is not taken for this run.
    /// When not, `why` (if given) gets the reason, "" when there is no summary.json at all (a run
    /// not done yet) and the cause when there is a broken or foreign one (a truncated, garbled or
    /// empty file, a directory in its place, another run's results).
    bool complete(std::string* why = nullptr) const;
    /// Whether the run's summary.json records expectations (its config's `expect`) not all met.
    bool expectationsFailed() const;
};

/// Writes DIR/sweep.json (the self-contained snapshot) unless it holds the same sweep already:
/// array tasks of one Slurm job all start from it and must not race to rewrite it. A DIR/sweep.json
/// of another sweep is an InputError naming both (the same sweep written to a moved DIR is the
/// same sweep). DIR must be a folder or absent (then it is made).
void writeSweepSnapshot(const Sweep& sweep, const std::string& outputDir);

/// The checks `sweep run` makes of its output folder before writing anything (`sweep plan` makes
/// them too): not empty, not a run's output, not inside a run's output or another sweep, not a
/// folder of the user's (OutputPlace::checkSweepPlace), and no file where DIR or DIR/runs go.
void checkSweepFolder(const std::string& outputDir);
/// Whether DIR/sweep.json is there (false: a new folder); InputError when it is not this sweep's
/// snapshot (another sweep's runs are there).
bool checkSweepSnapshot(const Sweep& sweep, const std::string& outputDir);

/// Runs the selected runs that are not complete and prints a line per run on stderr. A failed run
/// leaves DIR/runs/ID.error.json and the others go on. Returns the exit code: 0 when every
/// selected run is complete, 1 when one failed, 2 when one was being run by another sweep process,
/// 3 when all are complete but some run's expectations were not met (kExpectationsFailedExit),
/// 128 + signal when interrupted by SIGINT/SIGTERM (the running runs are stopped first; their
/// partial folders never look complete).
///
/// DIR/sweep.lock is held for the whole call: exclusively for a whole sweep, shared for a part
/// (--index, --shard: the array tasks of a Slurm job run side by side), so a second `sweep run`
/// of the whole sweep is refused (InputError) while anything runs there. Each run being run holds
/// DIR/runs/ID.sweep.lock (ID.lock is the run's own, taken by `shadowlab run`). The kernel releases both when the process dies, kill -9 included; the runs
/// it started get SIGTERM then.
int runSweep(const Sweep& sweep, const SweepRunOptions& options);

/// This process's own binary (/proc/self/exe), which also runs the points of a sweep.
std::string selfBinary();

} // namespace shadowlab
