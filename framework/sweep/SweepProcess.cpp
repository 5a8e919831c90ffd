#include "framework/sweep/SweepProcess.h"

#include "framework/core/Error.h"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace shadowlab {

namespace {

/// argv as execv wants it; built before fork, since the child may only make async-signal-safe calls.
std::vector<char*> cArgs(const std::vector<std::string>& argv) {
    std::vector<char*> out;
    for (const auto& a : argv) out.push_back(const_cast<char*>(a.c_str()));
    out.push_back(nullptr);
    return out;
}

/// write(2) of a C string: what a forked child may use to report an exec failure.
void say(int fd, const char* text) {
    size_t n = std::strlen(text);
    while (n > 0) {
        const ssize_t w = ::write(fd, text, n);
        if (w <= 0) return;
        text += w;
        n -= size_t(w);
    }
}

} // namespace

pid_t startLoggedChild(const std::vector<std::string>& argv, const std::string& logFile) {
    std::vector<char*> args = cArgs(argv);
    const std::string failText = "cannot run " + argv.at(0) + ": ";
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) throw RuntimeError(std::string("fork failed: ") + std::strerror(errno));
    if (pid == 0) {
        // SIGTERM when the sweep dies, so that its runs stop (and clean up) with it. A parent that
        // died before the prctl took effect is caught by the getppid check.
        ::prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (::getppid() != parent) ::_exit(143);
        const int fd = ::open(logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (fd < 0) {
            say(2, "cannot open the run's log file\n");
            ::_exit(127);
        }
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        ::signal(SIGPIPE, SIG_DFL); // shadowlab ignores it (main); an ignored signal survives exec
        ::execv(args[0], args.data());
        say(2, failText.c_str());
        say(2, std::strerror(errno));
        say(2, "\n");
        ::_exit(127);
    }
    return pid;
}

int captureChild(const std::vector<std::string>& argv, std::string& output, size_t maxBytes) {
    output.clear();
    std::vector<char*> args = cArgs(argv);
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw RuntimeError(std::string("pipe failed: ") + std::strerror(errno));
    const pid_t pid = ::fork();
    if (pid < 0) {
        ::close(fds[0]);
        ::close(fds[1]);
        throw RuntimeError(std::string("fork failed: ") + std::strerror(errno));
    }
    if (pid == 0) {
        ::dup2(fds[1], 1);
        ::dup2(fds[1], 2);
        ::signal(SIGPIPE, SIG_DFL); // shadowlab ignores it (main); an ignored signal survives exec
        ::execvp(args[0], args.data());
        ::_exit(127);
    }
    ::close(fds[1]);
    char buf[4096];
    while (true) {
        const ssize_t n = ::read(fds[0], buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        // Read to the end whatever the cap, so the child never blocks on a full pipe.
        if (output.size() < maxBytes) output.append(buf, std::min(size_t(n), maxBytes - output.size()));
    }
    ::close(fds[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw RuntimeError(std::string("waitpid failed: ") + std::strerror(errno));
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 1;
}

bool FileLock::tryLock(const std::string& path, Mode mode) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
    if (fd < 0) {
        if (errno == ELOOP) throw InputError(path, "", "is a symbolic link, not a lock file");
        throw RuntimeError("cannot open " + path + ": " + std::strerror(errno));
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        throw InputError(path, "", "is not a regular file (a lock file belongs there)");
    }
    while (::flock(fd, (mode == Mode::Shared ? LOCK_SH : LOCK_EX) | LOCK_NB) != 0) {
        const int err = errno;
        if (err == EINTR) continue;
        if (err == EWOULDBLOCK) {
            ::close(fd);
            return false;
        }
        if (err == ENOLCK || err == ENOSYS || err == EOPNOTSUPP || err == EINVAL) {
            // Some cluster file systems (Lustre without -o flock) have no locks: go on unlocked
            // rather than refuse every sweep there, and say so.
            static bool warned = false;
            if (!warned) std::fprintf(stderr, "sweep: warning: %s cannot be locked (%s): nothing stops two sweeps from writing here at once\n",
                                      path.c_str(), std::strerror(err));
            warned = true;
            break;
        }
        ::close(fd);
        throw RuntimeError("cannot lock " + path + ": " + std::strerror(err));
    }
    if (fd_ >= 0) ::close(fd_);
    fd_ = fd;
    return true;
}

FileLock::~FileLock() {
    if (fd_ >= 0) ::close(fd_);
}

} // namespace shadowlab
