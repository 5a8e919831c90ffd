#include "framework/experiment/OutputPlace.h"

#include "framework/core/Error.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

std::string pidSuffix() { return std::to_string(::getpid()); }

/// "results/run/" → "results/run"; "" stays "" (rejected by the caller).
std::string normalize(std::string dir) {
    while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
    return dir;
}

/// Whether `dir` is the working directory or one of its ancestors: it cannot be renamed away.
bool containsWorkingDir(const std::string& dir) {
    std::error_code ec;
    fs::path target = fs::weakly_canonical(fs::absolute(dir, ec), ec), cwd = fs::current_path(ec);
    if (ec) return false;
    for (fs::path p = cwd;; p = p.parent_path()) {
        if (p == target) return true;
        if (p == p.parent_path()) return false;
    }
}

bool isShadowlabOutput(const fs::path& dir) {
    std::error_code ec;
    return fs::exists(dir / "summary.json", ec) || fs::exists(dir / "config.resolved.json", ec) || fs::is_empty(dir, ec);
}

/// Takes the lock file's exclusive flock. The file is unlinked by its holder at the end, so after
/// locking, check that the path still names the file we locked (else a newer lock file exists).
int acquireLock(const std::string& lockPath, const std::string& dir) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        int fd = ::open(lockPath.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0)
            throw InputError(dir, "", "cannot create the lock file " + lockPath + ": " + std::strerror(errno) +
                                          " (is the output's parent directory writable?)");
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            char owner[32] = {0};
            ssize_t n = ::pread(fd, owner, sizeof owner - 1, 0);
            ::close(fd);
            std::string who = n > 0 ? " (pid " + std::string(owner, size_t(n)) + ")" : "";
            throw InputError(dir, "", "output directory is in use by another shadowlab run" + who +
                                          "; wait for it or choose another --out");
        }
        struct stat held {}, named {};
        if (::fstat(fd, &held) == 0 && ::stat(lockPath.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
            held.st_dev == named.st_dev) {
            std::string pid = pidSuffix();
            if (::ftruncate(fd, 0) == 0) (void)!::pwrite(fd, pid.data(), pid.size(), 0);
            return fd;
        }
        ::close(fd);  // the holder unlinked it meanwhile: lock the new one
    }
    throw RuntimeError("could not lock " + lockPath);
}

} // namespace

OutputPlace OutputPlace::open(const std::string& given, bool force, std::vector<std::string>* notes) {
    const std::string dir = normalize(given);
    if (dir.empty()) throw InputError("--out", "", "the output directory must not be empty");
    if (dir == "/" || containsWorkingDir(dir))
        throw InputError(dir, "", "the output directory cannot be the working directory or one above it "
                                  "(an output is a directory of its own, e.g. --out results/run1)");
    fs::path finalPath(dir);
    fs::path parent = finalPath.has_parent_path() ? finalPath.parent_path() : fs::path(".");
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) throw InputError(dir, "", "cannot create the parent directory " + parent.string() + ": " + ec.message());

    OutputPlace place;
    place.final_ = dir;
    place.lockPath_ = dir + ".lock";
    place.lockFd_ = acquireLock(place.lockPath_, dir);

    // Holding the lock, every DIR.partial-* and DIR.old-* is a leftover of a killed run.
    const std::string name = finalPath.filename().string();
    std::vector<fs::path> partials, olds;
    for (const auto& e : fs::directory_iterator(parent, ec)) {
        std::string n = e.path().filename().string();
        if (n.rfind(name + ".partial-", 0) == 0) partials.push_back(e.path());
        if (n.rfind(name + ".old-", 0) == 0) olds.push_back(e.path());
    }
    auto note = [&](const std::string& s) {
        if (notes) notes->push_back(s);
    };
    if (!fs::exists(fs::symlink_status(finalPath, ec)) && !olds.empty()) {
        // Killed between the two renames of a commit without RENAME_EXCHANGE: the old results are
        // complete and were never replaced, so put them back.
        fs::rename(olds.back(), finalPath, ec);
        if (!ec) {
            note("recovered " + dir + " from " + olds.back().string() + " (a run was killed while committing)");
            olds.pop_back();
        }
    }
    for (const auto& p : partials) {
        fs::remove_all(p, ec);
        note("removed " + p.string() + ", left by an interrupted run");
    }
    for (const auto& p : olds) {
        fs::remove_all(p, ec);
        note("removed " + p.string() + ", left by an interrupted run");
    }

    auto status = fs::symlink_status(finalPath, ec);
    if (fs::is_symlink(status))
        throw InputError(dir, "", "the output path is a symbolic link; give the directory it should name instead");
    if (fs::exists(status)) {
        if (!fs::is_directory(status)) throw InputError(dir, "", "the output path exists and is not a directory");
        if (!force)
            throw InputError(dir, "", "output directory already exists; pass --force to replace it once the new run "
                                      "completes, or --out DIR");
        if (!isShadowlabOutput(finalPath))
            throw InputError(dir, "", "the directory exists and is not a shadowlab output (no summary.json or "
                                      "config.resolved.json); --force replaces only outputs");
    }
    place.partial_ = dir + ".partial-" + pidSuffix();
    fs::create_directories(place.partial_ + "/images", ec);
    if (ec) throw InputError(dir, "", "cannot create " + place.partial_ + ": " + ec.message());
    return place;
}

OutputPlace::OutputPlace(OutputPlace&& o) noexcept
    : final_(std::move(o.final_)), partial_(std::move(o.partial_)), lockPath_(std::move(o.lockPath_)), lockFd_(o.lockFd_),
      committed_(o.committed_) {
    o.lockFd_ = -1;
    o.partial_.clear();
}

OutputPlace::~OutputPlace() {
    std::error_code ec;
    if (!committed_ && !partial_.empty()) fs::remove_all(partial_, ec);
    release();
}

void OutputPlace::release() {
    if (lockFd_ < 0) return;
    ::unlink(lockPath_.c_str());  // while still holding it: see acquireLock
    ::close(lockFd_);
    lockFd_ = -1;
}

void OutputPlace::commit() {
    std::error_code ec;
    bool exists = fs::exists(fs::symlink_status(final_, ec));
    if (exists) {
        if (::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
            committed_ = true;
            fs::remove_all(partial_, ec);  // now the previous results
        } else if (errno == EINVAL || errno == ENOSYS) {
            // A file system without exchange: two renames; open() recovers DIR.old-PID if killed between.
            std::string old = final_ + ".old-" + pidSuffix();
            fs::rename(final_, old, ec);
            if (ec) throw RuntimeError("cannot move " + final_ + " aside: " + ec.message());
            fs::rename(partial_, final_, ec);
            if (ec) throw RuntimeError("cannot rename " + partial_ + " to " + final_ + ": " + ec.message());
            committed_ = true;
            fs::remove_all(old, ec);
        } else {
            throw RuntimeError("cannot replace " + final_ + ": " + std::strerror(errno));
        }
    } else {
        if (::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, final_.c_str(), RENAME_NOREPLACE) != 0) {
            // RENAME_NOREPLACE is unsupported on some file systems; the lock still keeps other runs out.
            if (errno != EINVAL && errno != ENOSYS) throw RuntimeError("cannot rename " + partial_ + " to " + final_ + ": " + std::strerror(errno));
            fs::rename(partial_, final_, ec);
            if (ec) throw RuntimeError("cannot rename " + partial_ + " to " + final_ + ": " + ec.message());
        }
        committed_ = true;
    }
    release();
}

bool OutputPlace::isCompleteOutput(const std::string& dir) {
    std::error_code ec;
    return fs::is_regular_file(fs::path(dir) / "summary.json", ec);
}

} // namespace shadowlab
