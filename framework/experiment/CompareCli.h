#pragma once
// `shadowlab compare BASE NEW ...` (framework/experiment/Compare.h) and `shadowlab history DIR ...`
// (framework/experiment/History.h): the two commands that read runs already made.
#include <string>
#include <vector>

namespace shadowlab {

extern const char* kCompareUsage;
extern const char* kHistoryUsage;

/// args[0] is "compare". Returns the exit code: 0 no regression, 3 regressions (kRegressionExit).
int compareCommand(const std::vector<std::string>& args);

/// args[0] is "history". Returns the exit code: 0, or 3 (kRegressionExit) when the newest run
/// starts a step for the worse.
int historyCommand(const std::vector<std::string>& args);

} // namespace shadowlab
