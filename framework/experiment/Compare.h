#pragma once
// `shadowlab compare BASE NEW`: what changed between two runs of one experiment (two commits, two
// machines, two parameter choices), per algorithm id: each stage's time as a ratio with its 95 %
// bootstrap interval and a verdict (faster, slower, within noise), accuracy, overflow, memory,
// counters, and the pixels of the saved images that changed. A change is a regression when the
// total time is slower beyond the threshold and outside the noise, accuracy worse, or overflow
// more; the exit code says whether there was one (kRegressionExit).
#include "framework/core/JsonNode.h"
#include "framework/metrics/Noise.h"

#include <set>
#include <string>

namespace shadowlab {

constexpr int kRegressionExit = 3;

struct CompareOptions {
    /// The smallest relative change that counts (time, accuracy, memory): 10 %, past what 9 in 10
    /// pairs of one build's runs differ by relative to '*' on a shared 2-core machine (results/reference/compare_noise_llvmpipe.md).
    double threshold = 0.10;
    std::string imagesDir;    ///< where pictures of changed pixels go ("" none)
    /// An id whose total time, pass by pass, every other id's times are divided by before they are
    /// compared ("" none): what a shared machine's load does to both cancels out.
    std::string relativeTo;
};

struct Comparison {
    Json records = Json::array();  ///< one per id: {id, present, time, accuracy, overflow, memory, counters, images, regressions}
    std::vector<std::string> notes; ///< what makes the comparison weaker (configs differ, few samples)
    size_t regressions = 0;
};

/// DIR/summary.json, which must be a complete run's (InputError naming the file otherwise): not a
/// run's temporary folder (DIR.partial-PID, DIR.old-PID, DIR.kept-PID), and, where the folder holds
/// its config.resolved.json, results for exactly the ids that config gives, each of the algorithm
/// it names, at its resolution.
Json readRunSummary(const std::string& dir);

/// Adds the algorithm ids a resolved run config gives results under (its algorithms' and the reference's).
void collectIds(const Json& resolvedConfig, std::set<std::string>& ids);
/// The algorithm a resolved run config runs under `id` ("reference" for the reference), "" when
/// it gives no such id.
std::string algorithmOf(const Json& resolvedConfig, const std::string& id);
/// The top-level keys in which two runs' config.resolved.json differ (output.dir aside), or one
/// entry saying a file cannot be read.
std::vector<std::string> configDifferences(const std::string& baseDir, const std::string& newDir);

/// What `--relative-to ID` divides by in `summary`: ID's entry, or for "*" an entry made of the
/// median over the ids of each one's total time over its scale (`scales`: id → ms, the same for
/// every run compared), pass by pass and frame by frame.
Json yardstickOf(const Json& summary, const std::string& id, const Json& scales);

/// Each id's median total time in `summary` (its passes', else its frames'): the scales of "*".
Json yardstickScales(const Json& summary);

/// One id's total time as samples: the passes' means when it ran 3 or more (`repeats`), else its
/// frames' totals; each divided by the yardstick's of the same pass or frame when one is given.
std::vector<double> totalTimeSamples(const Json& entry, const Json* yardstick);

/// "slower" or "faster" when the ratio's interval lies wholly on one side of 1, its median is past
/// `threshold` and the U test's `p` is below 0.05 (negative: no test, no change); else "within
/// noise", or "no interval" when `ci` is not valid.
std::string timeVerdict(const Interval& ci, double p, double threshold);

/// Reads BASE/summary.json and NEW/summary.json (InputError naming the file when either is not a
/// complete run's) and compares them.
Comparison compareRuns(const std::string& baseDir, const std::string& newDir, const CompareOptions& options);

/// The comparison as Markdown (every user text literal) and as JUnit XML (a test case per id and
/// check: total time, accuracy, overflow).
std::string comparisonMarkdown(const Comparison& c, const std::string& baseDir, const std::string& newDir, const CompareOptions& options);
std::string comparisonJUnit(const Comparison& c);

} // namespace shadowlab
