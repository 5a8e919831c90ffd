#pragma once
// The child processes and locks of sweeps. Children are started from argv arrays (fork + exec),
// never through a shell, so no name, label or path of a sweep is ever parsed as a command.
#include <string>
#include <sys/types.h>
#include <vector>

namespace shadowlab {

/// Starts `argv` (argv[0] a path) with stdout and stderr in `logFile` (truncated; a symbolic link
/// there is refused). The child gets SIGTERM when this process dies, even by SIGKILL
/// (PR_SET_PDEATHSIG), so a killed sweep leaves no run rendering on. RuntimeError when fork fails.
pid_t startLoggedChild(const std::vector<std::string>& argv, const std::string& logFile);

/// Runs `argv` (argv[0] looked up on PATH) and waits for it; its stdout and stderr together, at
/// most `maxBytes` of them, go to `output`. Returns the exit status, 127 when it could not be
/// started, 128 + signal when it died of one.
int captureChild(const std::vector<std::string>& argv, std::string& output, size_t maxBytes = 1 << 16);

/// An advisory lock (flock) on a lock file, held until destruction; the kernel drops it when the
/// process dies however it dies, so a killed sweep never leaves its folder locked. The file is
/// opened close-on-exec: the runs a sweep starts do not inherit (and so do not prolong) the lock.
class FileLock {
public:
    enum class Mode { Shared, Exclusive };
    /// Takes the lock without waiting. false when another process holds it (a conflicting mode);
    /// InputError when `path` is not a regular file. Where the file system has no locks (some
    /// Lustre mounts), warns on stderr once and returns true without one.
    bool tryLock(const std::string& path, Mode mode);
    FileLock() = default;
    FileLock(const FileLock&) = delete;
    FileLock& operator=(const FileLock&) = delete;
    FileLock(FileLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
    ~FileLock();

private:
    int fd_ = -1;
};

} // namespace shadowlab
