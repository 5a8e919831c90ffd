#pragma once
// `shadowlab compare BASE NEW`: what changed between two runs of one experiment (two commits, two
// machines, two parameter choices), per algorithm id: each stage's time as a ratio with its 95 %
// bootstrap interval and a verdict (faster, slower, within noise), accuracy, overflow, memory,
// counters, and the pixels of the saved images that changed. A change is a regression when the
// total time is slower beyond the threshold and outside the noise, accuracy worse, or overflow
// more; the exit code says whether there was one (kRegressionExit).
#include "framework/core/JsonNode.h"

#include <string>

namespace shadowlab {

constexpr int kRegressionExit = 3;

struct CompareOptions {
    /// The smallest relative change that counts (time, accuracy, memory): 10 %, past what the same
    /// build's runs on a shared 2-core machine differ by (results/ci/compare_noise_llvmpipe.md).
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

/// Reads BASE/summary.json and NEW/summary.json (InputError naming the file when either is not a
/// complete run's) and compares them.
Comparison compareRuns(const std::string& baseDir, const std::string& newDir, const CompareOptions& options);

/// The comparison as Markdown (every user text literal) and as JUnit XML (a test case per id and
/// check: total time, accuracy, overflow).
std::string comparisonMarkdown(const Comparison& c, const std::string& baseDir, const std::string& newDir, const CompareOptions& options);
std::string comparisonJUnit(const Comparison& c);

} // namespace shadowlab
