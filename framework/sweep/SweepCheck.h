#pragma once
// `sweep plan --check`: every run's config through `shadowlab validate` (the memory plan, the
// scene, each algorithm's fit on it), one run at a time, so a sweep that plans but would fail a
// run on bad input is refused before anything runs.
#include "framework/sweep/SweepFile.h"

#include <string>

namespace shadowlab {

/// Validates each run as `binary validate` would its config, in a child process each (a scene
/// built for one run is gone before the next). Returns "" when all pass, else one line naming the
/// run (index, id, labels) and validate's error for it; prints progress on stderr every few runs.
std::string checkSweepRuns(const Sweep& sweep, const std::string& binary);

} // namespace shadowlab
