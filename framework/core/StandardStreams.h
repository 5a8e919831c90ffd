#pragma once
// The standard streams of a command-line program: a closed one reopened so no file takes its
// number, and what was printed checked to have arrived (both binaries, shadowlab and shadowlab-gui).

#include <string>

namespace shadowlab {

/// A standard stream the caller closed is opened again, so that no file this process opens takes
/// its number (a results file receiving the summary table): standard input and error on
/// /dev/null, standard output on /dev/full, where every write fails and checkStandardOutput()
/// reports it.
void reopenClosedStandardStreams();

/// Whatever the program printed reached standard output: a full disk or a closed stream is an
/// output place that cannot take the result, reported on stderr as "`program`: error: standard
/// output: ..." with exit 2 (or `rc` when that already says a failure), never exit 0 with nothing
/// written.
int checkStandardOutput(const char* program, int rc);

/// Writes `text` to standard output and flushes it; a write that fails is an InputError
/// ("standard output: cannot be written ..."), reported once: checkStandardOutput() then adds no
/// second line about the same stream.
void writeStandardOutput(const std::string& text);

} // namespace shadowlab
