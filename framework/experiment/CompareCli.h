#pragma once
// `shadowlab compare BASE NEW [--threshold PCT] [--out DIR] [--force]` (framework/experiment/Compare.h).
#include <string>
#include <vector>

namespace shadowlab {

extern const char* kCompareUsage;

/// args[0] is "compare". Returns the exit code: 0 no regression, 3 regressions (kRegressionExit).
int compareCommand(const std::vector<std::string>& args);

} // namespace shadowlab
