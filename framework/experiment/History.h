#pragma once
// `shadowlab history DIR`: the runs of one experiment kept across commits (one run folder each in
// DIR, as a CI job leaves them), in the order they ran: each algorithm id's total time and
// worst-frame mismatch run by run, and the runs where a step happened, named by commit (as
// airspeed velocity does). A time step at run k: the median of the runs after it (up to `window`,
// k included) over that of the runs before, past the threshold and past a multiple of the id's
// run-to-run noise (runs of one build differ by more than their passes do, so the run is the
// unit); of neighbouring boundaries that all see one step, the L1 change point names it. An
// accuracy step is any change past the threshold from one run to the next (accuracy is
// deterministic on one renderer).
#include "framework/core/JsonNode.h"

#include <string>
#include <vector>

namespace shadowlab {

struct HistoryOptions {
    double threshold = 0.10;  ///< the smallest relative change that counts, as in compare
    std::string relativeTo;   ///< as compare's --relative-to ("" none, an id, or "*")
    size_t window = 3;        ///< runs pooled on each side of a boundary
    bool byName = false;      ///< order runs by folder name instead of start time
};

struct History {
    Json runs = Json::array();   ///< per run, in order: {folder, commit, dirty, label, started_utc, renderer}
    Json ids = Json::object();   ///< per id: {time: [{median, low, high} | null per run], mismatch: [number | null per run]}
    Json steps = Json::array();  ///< {id, measure ("time" | "accuracy"), run, label, direction, ratio, low, high, p, before, after}
    std::vector<std::string> notes;
    size_t newestRegressions = 0; ///< steps for which isNewestRegression()
};

/// Whether `step` (one of h.steps) starts at the newest run and is for the worse (slower, less
/// accurate): what fails the command, its JUnit case and its stderr line.
bool isNewestRegression(const History& h, const Json& step);

/// Reads every complete run folder directly inside `dir` (InputError when there are fewer than 2;
/// other entries are named in notes) and finds the steps.
History readHistory(const std::string& dir, const HistoryOptions& options);

/// The history as Markdown (every user text literal), with the plots history_time.png and
/// history_accuracy.png referenced when `withPlots`.
std::string historyMarkdown(const History& h, const std::string& dir, const HistoryOptions& options, bool withPlots);

/// The history as JSON (history.json: what scripts/history_plot.py draws).
Json historyJson(const History& h, const HistoryOptions& options);

} // namespace shadowlab
