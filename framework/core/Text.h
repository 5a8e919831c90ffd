#pragma once
// Text that comes from users (config names, ids, labels, sources, paths) on its way into files,
// terminal lines and reports. One rule decides what such text may hold (userTextProblem), and one
// function writes it into Markdown as literal text (markdownLiteral): a report shows what the user
// wrote, never a link, an image, a table cell boundary or markup made of it.
#include <cstddef>
#include <string>

namespace shadowlab {

/// Longest name or label a config may carry (a plot legend or table cell, not a document).
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

/// The rule for every piece of user text that reaches a report, a plot or a table (experiment and
/// sweep names, axis labels, merge entries, a paper's source): textProblem() at kMaxLabelChars,
/// and none of the characters that make a line read other than it is written: C1 controls
/// (U+0080–U+009F), bidirectional overrides, embeddings and isolates (U+202A–U+202E,
/// U+2066–U+2069, U+200E, U+200F, U+061C), zero-width and invisible formatting characters
/// (U+200B–U+200D, U+2060–U+2064, U+FEFF) and line or paragraph separators (U+2028, U+2029).
/// "" when `text` may be used.
std::string userTextProblem(const std::string& text);

/// The rule for a path the user names (a config, an output folder): UTF-8 without control
/// characters (summary.json and the reports hold it) and none of userTextProblem()'s invisible
/// characters (a U+202E in a folder's name makes every line that names it read backwards); any
/// length. "" when the path may be used.
std::string pathTextProblem(const std::string& path);

/// Whether `name` can be one component of a path (no '/' or '\\', not "." or ".."): a name that
/// forms the default output folder results/NAME must be.
bool isFileName(const std::string& name);

/// `text` as Markdown that renders as exactly `text`: every character CommonMark or a pipe table
/// could read as markup is backslash-escaped: \ ` * [ ] ( ) ! | < > # ~ & { } + - . = $ :
/// and '_' unless it stands between two letters or digits (CommonMark never emphasises there,
/// so ids such as psv_stack stay readable). Control characters become U+FFFD. Valid as a heading,
/// a paragraph or a table cell (scripts/report_html.py's literal() is the same rule).
std::string markdownLiteral(const std::string& text);

/// `v` in at most `digits` significant digits (printf's %g): numbers in lines, tables and reports.
std::string shortNumber(double v, int digits = 6);

/// The current time in UTC as ISO 8601 to the second ("2026-12-06T16:05:54Z"): sorts as it reads.
std::string utcTimestamp();

/// `text` as XML character data or an attribute value (JUnit files): & < > " ' escaped, bytes that
/// are not well-formed UTF-8, C0 controls but tab and newline, U+FFFE and U+FFFF (which XML 1.0
/// cannot hold) as '?'.
std::string xmlText(const std::string& text);

/// `text` for one line of output: control characters and invalid bytes shown as '?', cut to
/// `maxChars` with "..." after it.
std::string shortText(const std::string& text, size_t maxChars = kMaxEchoChars);

/// `text` with every byte that is not part of well-formed UTF-8 replaced by '?' (a log's tail, say,
/// before it goes into a JSON file), newlines kept.
std::string validUtf8(const std::string& text);

/// Whether `s` is a plain decimal number: sign, digits, an optional fraction and exponent; not
/// strtod's wider set (hex, inf, nan(...), leading spaces), which a spreadsheet or a reader takes
/// for a formula, a name or another number.
bool plainDecimal(const std::string& s);

/// `text` with its ASCII letters in lower case (ids and names compared as a case-insensitive file
/// system would compare the files they name).
std::string asciiLowerCase(std::string text);

} // namespace shadowlab
