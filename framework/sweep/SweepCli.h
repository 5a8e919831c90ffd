#pragma once
// `shadowlab sweep plan|config|run|slurm|merge`: the command line of sweeps (docs/sweep.md).
#include <string>
#include <vector>

namespace shadowlab {

/// The usage text of the sweep commands (part of `shadowlab --help`).
extern const std::string kSweepUsage;

/// Runs `shadowlab sweep ...` (args[0] == "sweep"); returns the exit code. Bad input throws InputError.
/// `sweep --help` and `sweep COMMAND --help` (or -h) print the usage on stdout and return 0.
int sweepCommand(const std::vector<std::string>& args);

} // namespace shadowlab
