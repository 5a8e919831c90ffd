#pragma once
// `sweep merge DIR`: every run's summary.json into one tidy table (DIR/sweep.csv), and through
// scripts/sweep_report.py the report (DIR/sweep.md: a table per axis, ratios, power-law fits)
// and the plots (DIR/sweep_<axis>.png).
#include <string>

namespace shadowlab {

struct MergeResult {
    size_t runs = 0, merged = 0, failed = 0; ///< failed: runs with an error record and no results
    bool reportWritten = false;              ///< sweep.md (and plots when asked) were written
};

/// Reads DIR/sweep.json (written by `sweep run` / `sweep slurm`) and DIR/runs/ID/summary.json;
/// writes DIR/plan.json, DIR/sweep.csv, DIR/sweep.md and, when `plots`, the plots. Runs without
/// results are left out of the tables and named in sweep.md and on stderr.
MergeResult mergeSweep(const std::string& dir, bool plots);

} // namespace shadowlab
