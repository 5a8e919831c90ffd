#pragma once
// Checks on the text a sweep carries into files, shell-free child processes, job scripts and
// terminal lines: names, labels and paths end up in JSON (which must be UTF-8), in TSV and CSV rows
// (where a newline or tab breaks the table) and in progress lines (which must stay short), so they
// are refused at load rather than failing halfway through a sweep.
#include <cstddef>
#include <string>

namespace shadowlab {

/// Longest name or label a sweep may carry (a plot legend or table cell, not a document).
constexpr size_t kMaxLabelChars = 200;
/// Longest text echoed back in a progress line or message.
constexpr size_t kMaxEchoChars = 200;

/// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points past U+10FFFF).
bool isValidUtf8(const std::string& text);

/// The first control character (below U+0020, or DEL) of `text`, or -1.
int firstControlChar(const std::string& text);

/// Why `text` cannot be a name, label or path shown in tables and lines ("" when it can): not
/// UTF-8, a control character (newline, tab, ...), or longer than `maxChars` bytes (0: no cap).
std::string textProblem(const std::string& text, size_t maxChars);

/// `text` for one line of output: control characters and invalid bytes shown as '?', cut to
/// `maxChars` with "..." after it.
std::string shortText(const std::string& text, size_t maxChars = kMaxEchoChars);

/// `text` with every byte that is not part of well-formed UTF-8 replaced by '?' (a log's tail, say,
/// before it goes into a JSON file), newlines kept.
std::string validUtf8(const std::string& text);

/// A count on the command line: decimal digits only (no sign, no spaces, no hex), within
/// [minValue, maxValue]; otherwise InputError(option, "", "expected a whole number in [min, max]...").
size_t parseCount(const std::string& text, const std::string& option, size_t minValue, size_t maxValue);

/// Why `path` is not a dotted config path (`--set`'s and an axis's), "" when it is one: empty
/// components, an array index (a component of digits) past 999,999,999 (it would wrap in the walker),
/// or text textProblem() refuses (at most 1000 bytes).
std::string dottedPathProblem(const std::string& path);

} // namespace shadowlab
