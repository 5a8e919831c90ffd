#pragma once
// Checks on the text a sweep carries into files, shell-free child processes, job scripts and
// terminal lines: names, labels and paths end up in JSON (which must be UTF-8), in TSV and CSV rows
// (where a newline or tab breaks the table) and in progress lines (which must stay short), so they
// are refused at load rather than failing halfway through a sweep.
#include "framework/core/Text.h"

#include <cstddef>
#include <string>

namespace shadowlab {

/// A count on the command line: decimal digits only (no sign, no spaces, no hex), within
/// [minValue, maxValue]; otherwise InputError(option, "", "expected a whole number in [min, max]...").
size_t parseCount(const std::string& text, const std::string& option, size_t minValue, size_t maxValue);

/// Why `path` is not a dotted config path (`--set`'s and an axis's), "" when it is one: empty
/// components, an array index (a component of digits) past 999,999,999 (it would wrap in the walker),
/// or text textProblem() refuses (at most 1000 bytes).
std::string dottedPathProblem(const std::string& path);

} // namespace shadowlab
