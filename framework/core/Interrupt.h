#pragma once
// Ctrl-C and SIGTERM stop a run cleanly: the handlers only record the signal, and the run checks
// it between units of work (throwIfInterrupted), so that destructors remove half-written outputs
// and the previous results stay as they were.
#include <stdexcept>
#include <string>
#include <vector>

namespace shadowlab {

/// Thrown by throwIfInterrupted(); main() turns it into exit code 128 + signal.
class Interrupted : public std::runtime_error {
public:
    explicit Interrupted(int signal);
    int signal() const { return signal_; }

private:
    int signal_;
};

/// Installs the SIGINT/SIGTERM handlers (idempotent).
void installInterruptHandlers();
/// The signal received since installInterruptHandlers(), or 0.
int pendingInterrupt();
/// Throws Interrupted when a signal was received.
void throwIfInterrupted();

/// Runs `argv` (argv[0] found on PATH) with stdout and stderr appended to `logFile`, and waits for it.
/// Unlike std::system, an interrupt stops the child (SIGTERM) and throws Interrupted instead of being
/// swallowed. Returns the child's exit status (-1 when it could not start or died of a signal).
int runChildProcess(const std::vector<std::string>& argv, const std::string& logFile);

} // namespace shadowlab
