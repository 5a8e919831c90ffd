#include "framework/experiment/OutputPlace.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/JsonNode.h"
#include "framework/core/Text.h"

#include <cerrno>
#include <cstdio>
#include <climits>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <set>
#include <vector>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

std::string pidSuffix() { return std::to_string(::getpid()); }

std::string shortPath(const fs::path& path) { return shadowlab::shortPath(path.string()); }

/// "results/run/" → "results/run"; "" stays "" (rejected by the caller); one ending in "." or ".." is refused: its parent would be made
/// for it and then found to be the output (left behind, empty, when the run is refused).
std::string normalize(std::string dir) {
    while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
    const std::string last = fs::path(dir).filename().string();
    if ((last == "." || last == "..") && dir != last) // "." alone: the working directory, refused as such
        throw InputError(shortPath(dir), "", "the output path ends in \"" + last + "\": name the output folder itself (e.g. --out results/run1)");
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

/// The file that marks `dir` as shadowlab's ("summary.json", "config.resolved.json": a run's
/// output; "sweep.json": a sweep's directory), or "" for none.
std::string markerOf(const fs::path& dir) {
    std::error_code ec;
    for (const char* name : {"summary.json", "config.resolved.json", "sweep.json"})
        if (fs::exists(fs::symlink_status(dir / name, ec))) return name;
    return "";
}

/// The mark every run's output carries (written into DIR.partial-PID, kept when it becomes DIR):
/// what --force relies on to call a directory a shadowlab output, rather than on the names of the
/// files in it, which anything can hold.
constexpr const char* kOutputMark = ".shadowlab-output";

bool isRegularFile(const fs::path& path) {
    struct stat st {};
    return ::lstat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

/// A run's output (or an empty directory, which holds nothing to lose). One without the mark (an
/// older build's, or one copied without its dot files) is not: what it holds beyond a run's files
/// cannot be told, and --force deleted a user's files in it (thirteenth probe).
bool isShadowlabOutput(const fs::path& dir) {
    std::error_code ec;
    if (fs::is_empty(dir, ec) && !ec) return true;
    return isRegularFile(dir / kOutputMark);
}

/// Whether another run holds `lockPath` now: its holder keeps an exclusive flock for the whole run,
/// so a shared non-blocking attempt fails. The probe holds its shared lock for microseconds, and
/// acquireLock() retries for a while before it calls a place busy, so probing never turns a run away.
bool lockIsLive(const std::string& lockPath) {
    const int fd = ::open(lockPath.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) return false;  // none (a run unlinks its lock when it ends), or not ours to read
    struct stat st {};
    bool live = false;
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
        if (::flock(fd, LOCK_SH | LOCK_NB) != 0) live = errno == EWOULDBLOCK;
        else ::flock(fd, LOCK_UN);
    }
    ::close(fd);
    return live;
}

/// What a lock file holds: this prefix and its holder's pid.
constexpr const char* kLockPrefix = "shadowlab-lock ";

/// The lock file's text ("" when unreadable, or not a regular file of at most 40 bytes).
std::string lockText(int fd, bool* regular = nullptr) {
    struct stat st {};
    const bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size <= 40;
    if (regular) *regular = ok;
    if (!ok) return "";
    char buf[41] = {0};
    const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
    return n > 0 ? std::string(buf, size_t(n)) : "";
}

/// The pid in a lock file's text "shadowlab-lock PID", or "" when the text is not that.
std::string lockPid(const std::string& text) {
    const size_t p = std::strlen(kLockPrefix);
    if (text.size() <= p || text.compare(0, p, kLockPrefix) != 0) return "";
    const std::string pid = text.substr(p);
    return pid.find_first_not_of("0123456789") == std::string::npos ? pid : "";
}

std::string lockOwner(const std::string& lockPath) {
    const int fd = ::open(lockPath.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) return "";
    const std::string pid = lockPid(lockText(fd, nullptr));
    ::close(fd);
    return pid.empty() ? "" : " (pid " + pid + ")";
}

/// The marks a run leaves in its temporary directories, so that only those are ever taken for a
/// killed run's leftovers: DIR.partial-PID (the run being written) and DIR.old-PID (the previous
/// results, moved aside for a moment on file systems without RENAME_EXCHANGE).
constexpr const char* kPartialMark = ".shadowlab-partial";
constexpr const char* kOldMark = ".shadowlab-old";

bool writeMark(const fs::path& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0) return false;
    return ::close(fd) == 0;
}

/// What an output wrote, every file and folder in it, listed in its mark when it is committed:
/// --force then replaces only an output that holds nothing else (eleventh and twelfth probes: a
/// user's notes.txt, folder, or file in images/ put into a run's output were deleted with it by
/// the next run --force).
constexpr const char* kManifestHeader = "shadowlab-output, entries:";

/// The paths inside `dir`, relative to it, its marks left out (links are listed, not followed).
std::vector<std::string> entriesOf(const fs::path& dir) {
    std::vector<std::string> out;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        const std::string name = it->path().lexically_relative(dir).string();
        if (name != kOutputMark && name != kPartialMark) out.push_back(name);
    }
    return out;
}

void writeManifest(const fs::path& dir) {
    std::string text = std::string(kManifestHeader) + "\n";
    for (const std::string& name : entriesOf(dir)) text += name + "\n";
    const int fd = ::open((dir / kOutputMark).c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) return;  // the mark stays empty: the output is then replaced whole, as before the list
    (void)!::write(fd, text.data(), text.size());
    ::close(fd);
}

/// The first path in the output `dir` that its mark does not list: "" when there is none, or when
/// the mark lists nothing (an output from before the list is replaced whole).
std::string foreignEntry(const fs::path& dir) {
    std::string text;
    try {
        text = readInputFile((dir / kOutputMark).string(), size_t(64) << 20);
    } catch (const std::exception&) {
        return "";
    }
    const std::string header = std::string(kManifestHeader) + "\n";
    if (text.compare(0, header.size(), header) != 0) return "";
    std::set<std::string> listed;
    for (size_t at = header.size(); at < text.size();) {
        const size_t end = text.find('\n', at);
        listed.insert(text.substr(at, end == std::string::npos ? std::string::npos : end - at));
        at = end == std::string::npos ? text.size() : end + 1;
    }
    for (const std::string& name : entriesOf(dir))
        if (!listed.count(name)) return name;
    return "";
}

/// `path` is PREFIX + digits, a real directory (no link) holding the regular file `mark`.
bool isLeftover(const fs::path& path, const std::string& prefix, const char* mark) {
    const std::string n = path.filename().string();
    if (n.size() <= prefix.size() || n.compare(0, prefix.size(), prefix) != 0 ||
        n.find_first_not_of("0123456789", prefix.size()) != std::string::npos)
        return false;
    std::error_code ec;
    struct stat st {};
    return fs::is_directory(fs::symlink_status(path, ec)) && ::lstat((path / mark).c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

/// "X.partial-123" or "X.old-123": a run's temporary directory beside its output.
bool isRunTemporary(const std::string& name) {
    for (const char* tag : {".partial-", ".old-", ".kept-"}) {
        const size_t at = name.rfind(tag);
        if (at != std::string::npos && at > 0 && at + std::strlen(tag) < name.size() &&
            name.find_first_not_of("0123456789", at + std::strlen(tag)) == std::string::npos)
            return true;
    }
    return false;
}

/// An output inside another run's output, inside a run in progress, or inside a sweep (other than a
/// sweep's own run slot, SWEEP/runs/ID) would be lost or corrupt when that one is replaced, or
/// would replace part of it: refused before anything is created.
/// `runConfig`: the config file of the run going there ("" for a sweep, or a run with --set): a
/// run may go to SWEEP/runs/ID only when it runs SWEEP/runs/ID.config.json itself, the config the
/// sweep wrote for that slot, so no other experiment's results land among the sweep's.
void checkAncestors(const std::string& dir, const std::string& runConfig) {
    std::error_code ec;
    const fs::path lexical = fs::absolute(dir, ec).lexically_normal();
    std::vector<fs::path> chains = {lexical};
    const fs::path real = fs::weakly_canonical(lexical, ec);  // through symbolic links, where they exist
    if (!ec && real != lexical) chains.push_back(real);
    for (const fs::path& target : chains) {
        int depth = 0;  // of `target` below `a`
        for (fs::path a = target.parent_path(); a.has_relative_path(); a = a.parent_path()) {
            ++depth;
            const std::string lock = a.string() + ".lock";
            if (lockIsLive(lock))
                throw InputError(shortPath(dir), "", "the output lies inside " + shortPath(a.string()) + ", the output of a shadowlab run in progress" +
                                              lockOwner(lock) + "; its commit would replace this one. Choose --out outside it");
            if (isRunTemporary(a.filename().string()))
                throw InputError(shortPath(dir), "", "the output lies inside " + shortPath(a.string()) +
                                              ", a shadowlab run's temporary directory; choose --out outside it");
            const std::string marker = fs::is_directory(fs::symlink_status(a, ec)) ? markerOf(a) : "";
            // Any output carrying the mark, a compare's or a history's too (twentieth probe: runs
            // went into them, and their next --force was refused for what it would delete).
            if (marker.empty() && fs::is_directory(fs::symlink_status(a, ec)) && isRegularFile(a / kOutputMark))
                throw InputError(shortPath(dir), "", "the output lies inside " + shortPath(a.string()) +
                                              ", a shadowlab output; replacing that one would delete this. Choose --out outside it");
            if (marker.empty()) continue;
            if (marker == "sweep.json") {
                // A sweep runs each of its runs into SWEEP/runs/ID, after writing ID.config.json
                // there; anything else inside it is not its.
                const std::string slotConfig = target.string() + ".config.json";
                if (depth == 2 && target.parent_path().filename() == "runs" && isRegularFile(slotConfig)) {
                    if (!runConfig.empty() && fs::equivalent(runConfig, slotConfig, ec)) continue;
                    throw InputError(shortPath(dir), "", "the output is the sweep " + shortPath(a.string()) + "'s run slot " +
                                                  target.filename().string() + ", which takes only a run of its own config, " +
                                                  shortPath(slotConfig) + ", without --set; choose --out outside the sweep");
                }
                throw InputError(shortPath(dir), "", "the output lies inside the sweep directory " + shortPath(a.string()) +
                                              " (it holds sweep.json); only the sweep's own runs go to its runs/ID. Choose --out outside it");
            }
            throw InputError(shortPath(dir), "", "the output lies inside " + shortPath(a.string()) + ", a shadowlab run's output (it holds " + marker +
                                          "); replacing that one would delete this. Choose --out outside it");
        }
    }
}

/// What inside `dir` must not be replaced along with it: a run in progress (a live DIR.lock) or
/// another shadowlab output or sweep in a subdirectory. "" when there is none. At most `limit`
/// entries are looked at; a directory larger than that is no single run's output.
std::string nestedInside(const fs::path& dir, size_t limit = 200000) {
    std::error_code ec;
    size_t seen = 0;
    for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (++seen > limit)
            return "more than " + std::to_string(limit) + " entries (more than one run's output)";
        const fs::path& p = it->path();
        const std::string name = p.filename().string();
        if (name.size() > 5 && name.compare(name.size() - 5, 5, ".lock") == 0 && lockIsLive(p.string()))
            return shortPath(p) + ", the lock of a shadowlab run in progress" + lockOwner(p.string());
        if (it.depth() >= 1 && (name == "summary.json" || name == "config.resolved.json" || name == "sweep.json"))
            return shortPath(p.parent_path()) + ", another shadowlab " + (name == "sweep.json" ? "sweep" : "output") +
                   " (it holds " + name + ")";
    }
    if (ec) return "an unreadable entry (" + ec.message() + ")";
    return "";
}

/// Whether fd is a shadowlab lock: "shadowlab-lock PID", or empty while its creator is writing it
/// (that creator holds its flock from the start, so an empty file nobody holds is looked at again
/// 50 ms later; still empty and free, it is somebody else's file).
bool isLockFile(int fd) {
    bool regular = false;
    for (int look = 0; look < 10; ++look) {
        const std::string text = lockText(fd, &regular);
        if (!regular) return false;
        if (!text.empty()) return !lockPid(text).empty();
        if (::flock(fd, LOCK_SH | LOCK_NB) != 0) return errno == EWOULDBLOCK; // held: being written
        ::flock(fd, LOCK_UN);
        ::usleep(5000);
    }
    return false;
}

/// Takes the lock file's exclusive flock. The file is unlinked by its holder at the end, so after
/// locking, check that the path still names the file we locked (else a newer lock file exists).
int acquireLock(const std::string& lockPath, const std::string& dir) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        // Created here: ours (empty, and locked at once below); found: it must be a shadowlab lock.
        int fd = ::open(lockPath.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
        const bool created = fd >= 0;
        if (!created && errno == EEXIST) fd = ::open(lockPath.c_str(), O_RDWR | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
        if (fd < 0) {
            const int err = errno;
            throw InputError(shortPath(dir), "", "cannot create the lock file " + shortPath(lockPath) + ": " + std::strerror(err) +
                                          " (is the output's parent directory writable?)");
        }
        // A lock file holds nothing but its holder's pid (or nothing yet): anything else at that
        // path (a FIFO, a user's file) is not ours to lock, truncate or unlink.
        if (!created && !isLockFile(fd)) {
            ::close(fd);
            throw InputError(shortPath(dir), "", shortPath(lockPath) + " exists and is not a shadowlab lock file; move it away or "
                                          "choose another --out");
        }
        // Another run's lockIsLive() probe holds a shared lock for an instant: wait that out (50 ms)
        // before calling the place busy; a run in progress holds its lock for the whole run.
        bool locked = false;
        for (int wait = 0; wait < 10 && !(locked = ::flock(fd, LOCK_EX | LOCK_NB) == 0) && errno == EWOULDBLOCK; ++wait)
            ::usleep(5000);
        if (!locked) {
            const std::string pid = lockPid(lockText(fd, nullptr));
            ::close(fd);
            const std::string who = pid.empty() ? "" : " (pid " + pid + ")";
            throw InputError(shortPath(dir), "", "output directory is in use by another shadowlab run" + who +
                                          "; wait for it or choose another --out");
        }
        struct stat held {}, named {};
        if (::fstat(fd, &held) == 0 && ::stat(lockPath.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
            held.st_dev == named.st_dev) {
            const std::string text = kLockPrefix + pidSuffix();
            if (::ftruncate(fd, 0) == 0) (void)!::pwrite(fd, text.data(), text.size(), 0);
            return fd;
        }
        ::close(fd);  // the holder unlinked it meanwhile: lock the new one
    }
    throw RuntimeError("could not lock " + shortPath(lockPath));
}

} // namespace

namespace {
/// What check() and checkSweepPlace() share: a path that can name a folder of its own, and is
/// not a link or something other than a directory. Returns whether the directory exists.
bool checkPlace(const std::string& dir, const std::string& runConfig, const char* example) {
    if (dir.empty()) throw InputError("--out", "", "the output directory must not be empty");
    if (dir == "/" || containsWorkingDir(dir))
        throw InputError(shortPath(dir), "", std::string("the output directory cannot be the working directory or one above it "
                                                         "(an output is a directory of its own, e.g. --out ") + example + ")");
    checkAncestors(dir, runConfig);
    // A run's DIR.partial-PID, DIR.old-PID or DIR.kept-PID: replacing it with --force would mix two
    // runs' results (fourth probe: the running one then committed the other's images as its own).
    if (isRunTemporary(fs::path(dir).filename().string()))
        throw InputError(shortPath(dir), "", "the output path is a shadowlab run's temporary directory (DIR.partial-PID, "
                                             "DIR.old-PID or DIR.kept-PID); choose another --out");
    std::error_code ec;
    const auto status = fs::symlink_status(dir, ec);
    if (fs::is_symlink(status))
        throw InputError(shortPath(dir), "", "the output path is a symbolic link; give the directory it should name instead");
    if (fs::exists(status) && !fs::is_directory(status))
        throw InputError(shortPath(dir), "", "the output path exists and is not a directory");
    return fs::exists(status);
}
} // namespace

namespace {
/// A name that `sweep run`, `sweep slurm` or `sweep merge` writes in its folder.
bool isSweepMade(const fs::path& entry) {
    const std::string n = entry.filename().string();
    std::error_code ec;
    const auto status = fs::symlink_status(entry, ec);
    if (n == "runs" || n == "slurm") return fs::is_directory(status);
    if (!fs::is_regular_file(status)) return false;
    for (const char* name : {"sweep.lock", "plan.json", "sweep.csv", "sweep.md", "sweep.html", "sweep_report.log", "sweep.sbatch"})
        if (n == name) return true;
    return n.starts_with("sweep_") && n.ends_with(".png");  // the report's plots
}

/// The folder a merged sweep left once its sweep.json was removed (as the refusal of another
/// sweep's folder advises): runs/, a plan.json of a sweep's runs, and nothing but what a sweep writes.
bool isFormerSweep(const fs::path& dir) {
    std::error_code ec;
    if (!fs::is_directory(fs::symlink_status(dir / "runs", ec)) || !isRegularFile(dir / "plan.json")) return false;
    std::set<std::string> ids;
    try {
        const Json plan = JsonNode::parseFile((dir / "plan.json").string());
        if (!plan.is_object() || !plan.contains("axes") || !plan.contains("runs") || !plan["runs"].is_array()) return false;
        for (const Json& r : plan["runs"])
            if (r.is_object() && r.contains("id") && r["id"].is_string()) ids.insert(r["id"].get<std::string>());
    } catch (const InputError&) {
        return false;
    }
    for (const auto& e : fs::directory_iterator(dir, ec))
        if (!isSweepMade(e.path())) return false;
    // And runs/ holds that plan's runs, nothing else (a plan.json copied beside a folder of the
    // user's does not make it a sweep's): each entry an ID or ID.config.json, ID.log, ...
    size_t slots = 0;
    for (const auto& e : fs::directory_iterator(dir / "runs", ec)) {
        const std::string n = e.path().filename().string();
        if (!ids.count(n.substr(0, n.find('.')))) return false;
        ++slots;
    }
    return !ec && slots > 0;
}
} // namespace

void OutputPlace::checkSweepPlace(const std::string& given) {
    const std::string dir = normalize(given);
    if (!checkPlace(dir, "", "results/sweep1")) return;
    std::error_code ec;
    if (isRegularFile(fs::path(dir) / "sweep.json")) return;
    // Empty, or nothing but what `sweep run` makes before it writes sweep.json: runs/ and the lock.
    bool skeleton = true;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string n = e.path().filename().string();
        std::error_code ec2;
        skeleton = skeleton && ((n == "runs" && fs::is_directory(fs::symlink_status(e.path(), ec2))) ||
                                (n == "sweep.lock" && isRegularFile(e.path())));
    }
    if (skeleton && !ec) return;
    if (isFormerSweep(dir)) return;
    throw InputError(shortPath(dir), "", "exists and is not a sweep's folder (it holds no sweep.json): a sweep writes sweep.json, "
                                         "runs/, plan.json, sweep.csv and sweep.md there; choose another --out or an empty folder");
}

void OutputPlace::checkReplaceable(const std::string& given) {
    const std::string dir = normalize(given);
    const fs::path finalPath(dir);
    std::error_code ec;
    const auto status = fs::symlink_status(finalPath, ec);
    if (!fs::exists(status)) return;
    if (fs::is_symlink(status))
        throw InputError(shortPath(dir), "", "the output path is a symbolic link; give the directory it should name instead");
    if (!fs::is_directory(status)) throw InputError(shortPath(dir), "", "the output path exists and is not a directory");
    if (markerOf(finalPath) == "sweep.json")
        throw InputError(shortPath(dir), "", "the directory is a sweep (it holds sweep.json); --force replaces only one run's output");
    const bool output = isShadowlabOutput(finalPath);
    // Whatever it is, a run in progress or another output inside it is never replaced with it.
    if (const std::string inside = nestedInside(finalPath, output ? 200000 : 10000); !inside.empty() &&
                                                                                 (output || inside.find(".lock") != std::string::npos))
        throw InputError(shortPath(dir), "", "the directory holds " + inside + "; --force replaces only a single run's output");
    if (!output)
        throw InputError(shortPath(dir), "", "the directory exists and is not a shadowlab output (no " + std::string(kOutputMark) +
                                  " mark: a folder of yours, or an output copied without it); --force replaces only outputs");
    if (const std::string foreign = foreignEntry(finalPath); !foreign.empty())
        throw InputError(shortPath(dir), "", "the output holds \"" + shortText(foreign, 80) +
                                                 "\", which it did not write; --force would delete it with the rest: move it out first");
}

void OutputPlace::refuseOtherKind(const std::string& given, const std::string& ownFile, const std::string& command) {
    const fs::path dir(normalize(given));
    std::error_code ec;
    if (!fs::is_directory(fs::symlink_status(dir, ec)) || fs::is_empty(dir, ec) || !isShadowlabOutput(dir) ||
        isRegularFile(dir / ownFile))
        return;
    std::string whose = "not " + command + "'s";
    for (const auto& [file, kind] : {std::pair<const char*, const char*>{"summary.json", "a run's"}, {"compare.md", "compare's"},
                                     {"history.md", "history's"}})
        if (isRegularFile(dir / file)) whose = std::string(kind) + ": it holds " + file;
    throw InputError(shortPath(dir.string()), "",
                     "is another command's output (" + whose + "); --force replaces only an earlier " + command +
                         " output: choose another --out");
}

void OutputPlace::check(const std::string& given, const std::string& runConfig) {
    const std::string dir = normalize(given);
    checkPlace(dir, runConfig, "results/run1");
    // Every name the run makes fits the file system's limits (twentieth probe: a 245-byte folder
    // name validated, and run could not make DIR.partial-PID): the folder's own name with the
    // longest suffix a run adds (".partial-" and a pid), and the whole path with the deepest file
    // a run writes (images/ID_fNNNN_difference.png and the like, ids 64 bytes).
    std::error_code pathEc;
    const fs::path absolute = fs::absolute(fs::path(dir), pathEc);
    const std::string last = absolute.filename().string();
    constexpr size_t kSuffix = 20, kDeepestFile = 160;
    if (last.size() + kSuffix > NAME_MAX)
        throw InputError(shortPath(dir), "", "the folder name is " + std::to_string(last.size()) + " bytes; a run adds up to " +
                                              std::to_string(kSuffix) + " to it, and a name holds at most " + std::to_string(NAME_MAX));
    if (absolute.string().size() + kSuffix + kDeepestFile > PATH_MAX)
        throw InputError(shortPath(dir), "", "the path is " + std::to_string(absolute.string().size()) + " bytes; with the files a run "
                                              "writes inside it, it would pass the system's " + std::to_string(PATH_MAX) + "-byte limit");
    // The lock a run takes beside its output must be takeable, and no output may take a lock's
    // name (twenty-fourth probe: validate accepted output.dir=fresh beside a folder fresh.lock that
    // run then could not lock; --out fo.lock made an output that blocked every later run into fo).
    if (last.size() > 5 && last.compare(last.size() - 5, 5, ".lock") == 0)
        throw InputError(shortPath(dir), "", "the folder name ends in .lock, the name of a run's lock file beside its output");
    {
        const std::string lock = absolute.string() + ".lock";
        struct stat st {};
        bool takeable = ::lstat(lock.c_str(), &st) != 0;
        if (!takeable && S_ISREG(st.st_mode)) {
            const int fd = ::open(lock.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
            takeable = fd >= 0 && isLockFile(fd);
            if (fd >= 0) ::close(fd);
        }
        if (!takeable)
            throw InputError(shortPath(dir), "", shortPath(lock) + " is not a shadowlab lock file (a folder, a link or a file of "
                                                  "yours), and a run locks its output under that name: move it or choose another output");
    }
    // What run will do first, tried: make a folder beside DIR, in the nearest folder that exists
    // (sixth probe: validate accepted output.dir=/proc/x, which run then could not make).
    std::error_code ec;
    fs::path parent = fs::absolute(fs::path(dir), ec).parent_path();
    while (!parent.empty() && !fs::exists(fs::symlink_status(parent, ec)) && parent != parent.parent_path()) parent = parent.parent_path();
    std::string probe = (parent / ".shadowlab-probe-XXXXXX").string();
    if (!::mkdtemp(probe.data()))
        throw InputError(shortPath(dir), "", "cannot create folders in " + shortPath(parent.string()) + ": " + std::strerror(errno));
    ::rmdir(probe.c_str());
}

namespace {
/// Each folder in turn, deepest first, if it is (still) empty: rmdir never removes anything else.
void removeEmptyFolders(const std::vector<std::string>& folders) {
    for (const std::string& f : folders) ::rmdir(f.c_str());
}
} // namespace

void OutputPlace::refuseInputsInside(const std::string& dir, const std::vector<std::string>& inputs, const std::string& what) {
    std::error_code ec;
    const fs::path root = fs::weakly_canonical(fs::absolute(dir), ec);
    auto within = [](const fs::path& outer, const fs::path& inner) {
        const auto [a, b] = std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end());
        return a == outer.end();
    };
    for (const std::string& input : inputs) {
        const fs::path p = fs::weakly_canonical(fs::absolute(input), ec);
        if (within(root, p))
            throw InputError(shortPath(dir), "", "the output would replace the folder with everything in it, and " + what + " reads " +
                                                     shortPath(input) + " from inside it: choose another --out");
        if (within(p, root))
            throw InputError(shortPath(dir), "", "the output lies inside " + shortPath(input) + ", which " + what +
                                                     " reads: choose an --out outside it");
    }
}

OutputPlace OutputPlace::open(const std::string& given, bool force, std::vector<std::string>* notes, const std::string& runConfig) {
    const std::string dir = normalize(given);
    check(dir, runConfig);  // before anything is created
    fs::path finalPath(dir);
    fs::path parent = finalPath.has_parent_path() ? finalPath.parent_path() : fs::path(".");
    std::error_code ec;
    // The folders made for it, deepest first: a run that stops before its commit removes them again
    // (when still empty), so a refused run leaves no trace.
    std::vector<std::string> made;
    for (fs::path p = parent; !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path()) {
        made.push_back(p.string());
        if (p == p.parent_path()) break;
    }
    fs::create_directories(parent, ec);
    if (ec) {
        removeEmptyFolders(made);
        throw InputError(shortPath(dir), "", "cannot create the parent directory " + shortPath(parent.string()) + ": " + ec.message());
    }

    OutputPlace place;
    place.madeParents_ = std::move(made);
    place.final_ = dir;
    place.lockPath_ = dir + ".lock";
    place.lockFd_ = acquireLock(place.lockPath_, dir);

    // Holding the lock, a DIR.partial-PID or DIR.old-PID directory that carries the mark its run
    // left in it is a leftover of a killed run. Anything else beside DIR (a user's notes.old-2023,
    // a finished run made with --out DIR.partial-9, a file) is not ours and is left alone.
    const std::string name = finalPath.filename().string();
    std::vector<fs::path> partials, olds;
    for (const auto& e : fs::directory_iterator(parent, ec)) {
        std::string n = e.path().filename().string();
        if (isLeftover(e.path(), name + ".partial-", kPartialMark)) partials.push_back(e.path());
        if (isLeftover(e.path(), name + ".old-", kOldMark)) olds.push_back(e.path());
    }
    auto note = [&](const std::string& s) {
        if (notes) notes->push_back(s);
    };
    if (!fs::exists(fs::symlink_status(finalPath, ec)) && !olds.empty()) {
        // Killed between the two renames of a commit without RENAME_EXCHANGE: the old results are
        // complete and were never replaced, so put them back.
        fs::rename(olds.back(), finalPath, ec);
        if (!ec) {
            fs::remove(finalPath / kOldMark, ec);
            note("recovered " + shortPath(dir) + " from " + shortPath(olds.back().string()) + " (a run was killed while committing)");
            olds.pop_back();
        }
    }
    for (const auto& p : partials) {
        fs::remove_all(p, ec);
        note("removed " + shortPath(p.string()) + ", left by an interrupted run");
    }
    for (const auto& p : olds) {
        fs::remove_all(p, ec);
        note("removed " + shortPath(p.string()) + ", left by an interrupted run");
    }

    auto status = fs::symlink_status(finalPath, ec);
    if (fs::is_symlink(status))
        throw InputError(shortPath(dir), "", "the output path is a symbolic link; give the directory it should name instead");
    if (fs::exists(status)) {
        if (!fs::is_directory(status)) throw InputError(shortPath(dir), "", "the output path exists and is not a directory");
        if (!force)
            throw InputError(shortPath(dir), "", "output directory already exists; pass --force to replace it once the new run "
                                      "completes, or --out DIR");
        checkReplaceable(dir);
        place.oldFd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        struct stat st {};
        if (place.oldFd_ >= 0 && ::fstat(place.oldFd_, &st) == 0)
            place.existed_ = true, place.dev_ = uint64_t(st.st_dev), place.ino_ = uint64_t(st.st_ino);
    }
    place.partial_ = dir + ".partial-" + pidSuffix();
    fs::create_directories(place.partial_ + "/images", ec);
    if (ec) throw InputError(shortPath(dir), "", "cannot create " + shortPath(place.partial_) + ": " + ec.message());
    if (!writeMark(fs::path(place.partial_) / kPartialMark) || !writeMark(fs::path(place.partial_) / kOutputMark))
        throw InputError(shortPath(dir), "", "cannot write in " + shortPath(place.partial_));
    return place;
}

OutputPlace::OutputPlace(OutputPlace&& o) noexcept
    : final_(std::move(o.final_)), partial_(std::move(o.partial_)), lockPath_(std::move(o.lockPath_)),
      madeParents_(std::move(o.madeParents_)), lockFd_(o.lockFd_), committed_(o.committed_), kept_(o.kept_),
      existed_(o.existed_), dev_(o.dev_), ino_(o.ino_), oldFd_(o.oldFd_) {
    o.lockFd_ = -1;
    o.oldFd_ = -1;
    o.partial_.clear();
    o.madeParents_.clear();
}

OutputPlace::~OutputPlace() {
    std::error_code ec;
    if (!committed_ && !kept_ && !partial_.empty()) fs::remove_all(partial_, ec);
    release();
    if (!committed_ && !kept_) removeEmptyFolders(madeParents_);
}

void OutputPlace::release() {
    if (oldFd_ >= 0) ::close(oldFd_);
    oldFd_ = -1;
    if (lockFd_ < 0) return;
    ::unlink(lockPath_.c_str());  // while still holding it: see acquireLock
    ::close(lockFd_);
    lockFd_ = -1;
}

void OutputPlace::refuseCommit(const std::string& why) {
    // Both are kept: what is at the place now, and this run's results under a name no later run
    // cleans up (only DIR.partial-* and DIR.old-* are a killed run's leftovers).
    const std::string kept = final_ + ".kept-" + pidSuffix();
    std::error_code ec;
    fs::rename(partial_, kept, ec);
    if (!ec) partial_ = kept;
    kept_ = true;
    release();
    throw RuntimeError("not replacing " + shortPath(final_) + ": " + why + "; it is left as it is and this run's results are in " +
                       shortPath(partial_));
}

void OutputPlace::commit() {
    std::error_code ec;
    struct stat st {};
    const bool exists = ::lstat(final_.c_str(), &st) == 0;
    // Only what open() checked is replaced: a directory that appeared since (a run into a folder
    // inside this place creates it), or one swapped in for the checked one, is somebody else's.
    if (exists && !existed_) refuseCommit("it appeared while this run was working and was not created by it");
    if (exists && (uint64_t(st.st_dev) != dev_ || uint64_t(st.st_ino) != ino_))
        refuseCommit("it was replaced by another directory while this run was working");
    // The same directory, emptied and refilled by someone, is not the output open() checked either.
    if (exists && !isShadowlabOutput(fs::path(final_)))
        refuseCommit("it no longer carries the mark of a shadowlab output (its content was replaced while this run was working)");
    if (exists)
        if (const std::string inside = nestedInside(final_); !inside.empty())
            refuseCommit("it now holds " + inside);
    if (exists)
        if (const std::string foreign = foreignEntry(fs::path(final_)); !foreign.empty())
            refuseCommit("it now holds \"" + shortText(foreign, 80) + "\", which the output there did not write");
    writeManifest(fs::path(partial_));
    if (exists) {
        // The previous results get the leftover mark first: after the exchange they sit at
        // DIR.partial-PID while they are deleted, and a run killed meanwhile must leave them
        // marked for the next run to remove (twenty-third probe: half-deleted previous results
        // stayed, unmarked, and history counted them as a run). Killed before the exchange, the
        // output keeps a stray mark, which no check reads there.
        (void)writeMark(fs::path(final_) / kPartialMark);
        if (::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
            committed_ = true;
            if (afterExchangeForTests) afterExchangeForTests(partial_);
            fs::remove_all(partial_, ec);  // now the previous results
        } else if (errno == EINVAL || errno == ENOSYS) {
            // A file system without exchange: two renames; open() recovers DIR.old-PID if killed between.
            std::string old = final_ + ".old-" + pidSuffix();
            (void)writeMark(fs::path(final_) / kOldMark); // without it a leftover is kept, not recovered
            fs::rename(final_, old, ec);
            if (ec) throw RuntimeError("cannot move " + shortPath(final_) + " aside: " + ec.message());
            fs::rename(partial_, final_, ec);
            if (ec) throw RuntimeError("cannot rename " + shortPath(partial_) + " to " + shortPath(final_) + ": " + ec.message());
            committed_ = true;
            fs::remove_all(old, ec);
        } else {
            const int err = errno;
            throw RuntimeError("cannot replace " + shortPath(final_) + ": " + std::strerror(err));
        }
    } else {
        if (::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, final_.c_str(), RENAME_NOREPLACE) != 0) {
            if (errno == EEXIST || errno == ENOTEMPTY) refuseCommit("it appeared while this run was working and was not created by it");
            // RENAME_NOREPLACE is unsupported on some file systems; the lock still keeps other runs out.
            const int err = errno;
            if (err != EINVAL && err != ENOSYS)
                throw RuntimeError("cannot rename " + shortPath(partial_) + " to " + shortPath(final_) + ": " + std::strerror(err));
            if (fs::exists(fs::symlink_status(final_, ec))) refuseCommit("it appeared while this run was working and was not created by it");
            fs::rename(partial_, final_, ec);
            if (ec) throw RuntimeError("cannot rename " + shortPath(partial_) + " to " + shortPath(final_) + ": " + ec.message());
        }
        committed_ = true;
    }
    // The mark goes once the rename is done: a run killed before it leaves DIR.partial-PID marked,
    // and the next run into DIR removes it (a sweep killed mid-commit left a complete-looking
    // unmarked runs/ID.partial-PID that nothing removed). Killed after the rename, the output keeps
    // a stray mark, which no check reads there.
    fs::remove(fs::path(final_) / kPartialMark, ec);
    release();
}

bool OutputPlace::isRunOutput(const std::string& dir) {
    const std::string m = markerOf(fs::path(dir));
    return m == "summary.json" || m == "config.resolved.json";
}

bool OutputPlace::isRunTemporary(const std::string& name) { return shadowlab::isRunTemporary(name); }

void OutputPlace::checkFileOutsideOutputs(const std::string& file) { checkAncestors(file, ""); }

bool OutputPlace::isCompleteOutput(const std::string& dir) {
    std::error_code ec;
    return fs::is_regular_file(fs::path(dir) / "summary.json", ec);
}

} // namespace shadowlab
