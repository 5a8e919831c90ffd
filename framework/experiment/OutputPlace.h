#pragma once
// Where an experiment's results go, and the promise that they are never lost or half-written.
//
//   open():   checks the place before any rendering (a usable path, writable, not a file or link,
//             replaceable only with force and only if it is a shadowlab output), takes an exclusive
//             lock (DIR.lock, flock: released by the kernel even on SIGKILL), removes what earlier
//             killed runs left behind (DIR.partial-PID, DIR.old-PID), and creates DIR.partial-PID.
//             An output inside another run's output, inside a run in progress or inside a sweep
//             (but a sweep's own SWEEP/runs/ID, where it wrote ID.config.json) is refused, and so
//             is --force on a directory that holds a run in progress or another output or sweep,
//             or that is not marked as an output (.shadowlab-output, written into every output).
//             DIR.lock holds "shadowlab-lock PID"; a file there that is anything else is refused.
//   commit(): swaps the finished DIR.partial-PID with DIR in one step (renameat2 RENAME_EXCHANGE),
//             so DIR always holds either the previous or the new results, then drops the old ones.
//             It replaces only the directory open() checked: one that appeared since, or now holds
//             a run or an output, is kept, and the new results are kept beside it as DIR.kept-PID
//             (RuntimeError, exit 1).
//   ~OutputPlace(): without commit (an error, an interrupt), removes the partial directory; the
//             previous DIR is untouched.
#include <cstdint>
#include <string>
#include <vector>

namespace shadowlab {

class OutputPlace {
public:
    /// `dir` as given (--out or output.dir); `force` allows replacing an existing shadowlab output.
    /// Throws InputError (exit 2) for a place that cannot be used; `notes` receives what was
    /// cleaned up or recovered, one line each, for the user. `runConfig`: the config file the run
    /// runs, unchanged by --set (else ""): a sweep's run slot SWEEP/runs/ID takes only ID.config.json.
    static OutputPlace open(const std::string& dir, bool force, std::vector<std::string>* notes = nullptr,
                            const std::string& runConfig = "");
    /// InputError when `dir` can never hold an output, whatever --force says: empty, "/", the
    /// working directory or one above it, nested (inside a run in progress, a run's temporary folder,
    /// another run's output or a sweep, but for a sweep's own runs/ID), a link or a non-directory.
    /// open() checks it first; `validate` checks a config's output.dir with it.
    static void check(const std::string& dir, const std::string& runConfig = "");
    /// InputError when `dir` cannot be a sweep's folder: as check() (but no place inside a sweep at
    /// all, not even its runs/ID), and an existing folder must be empty or hold a sweep (sweep.json).
    static void checkSweepPlace(const std::string& dir);
    /// InputError when a file some command writes (shadowlab-gui's --screenshot, --report,
    /// --save-config) lies inside a run's output, a run in progress, a run's temporary folder, a
    /// sweep or a compare's or history's output: it would corrupt what is there, or be deleted with it.
    static void checkFileOutsideOutputs(const std::string& file);
    /// InputError when `dir` exists and `run --force` could not replace it: not a directory, a link,
    /// a sweep, not a shadowlab output, or holding another output or a run in progress. `validate`
    /// checks a config's output.dir with it, so that what it accepts a run can write.
    static void checkReplaceable(const std::string& dir);
    /// For a command that writes `ownFile` (compare: compare.md; history: history.md): an existing
    /// `dir` that holds another command's output (a run's, another report's) is not its to replace,
    /// with or without --force (tenth probe: `compare A B --out RUN --force` deleted a run).
    static void refuseOtherKind(const std::string& dir, const std::string& ownFile, const std::string& command);
    /// InputError when `dir`, once replaced with everything in it, would take an input with it: a
    /// file or folder the command reads that lies inside `dir`, is `dir`, or holds it (a command's
    /// output inside its input folder would land among the runs it reads). `what`: "this run",
    /// "compare", ...
    static void refuseInputsInside(const std::string& dir, const std::vector<std::string>& inputs, const std::string& what);

    OutputPlace(OutputPlace&& other) noexcept;
    OutputPlace& operator=(OutputPlace&&) = delete;
    ~OutputPlace();

    const std::string& finalDir() const { return final_; }
    /// The directory to write into until commit().
    const std::string& partialDir() const { return partial_; }
    /// Makes the partial directory the output, atomically replacing a previous one.
    void commit();

    /// Whether `dir` holds a finished experiment (its summary.json, written last, is present).
    static bool isCompleteOutput(const std::string& dir);
    /// Whether `dir` is a run's output, finished or not (summary.json or config.resolved.json).
    static bool isRunOutput(const std::string& dir);
    /// Whether a folder's name is that of a run's temporary folder (X.partial-PID, X.old-PID,
    /// X.kept-PID), which no run's output may take.
    static bool isRunTemporary(const std::string& name);

    /// Tests only: called between the exchange of a commit that replaces an output and the removal
    /// of the previous results (at `previous`), where a run killed at that moment leaves them.
    static inline void (*afterExchangeForTests)(const std::string& previous) = nullptr;

private:
    OutputPlace() = default;
    void release();
    [[noreturn]] void refuseCommit(const std::string& why);

    std::string final_, partial_, lockPath_;
    std::vector<std::string> madeParents_; ///< folders open() made above DIR, deepest first
    int lockFd_ = -1;
    bool committed_ = false;
    bool kept_ = false;  ///< the results were moved to DIR.kept-PID by a refused commit
    /// DIR as open() found it (the directory --force may replace).
    bool existed_ = false;
    uint64_t dev_ = 0, ino_ = 0;
    /// DIR held open from open() to commit(): while it is open its inode number cannot be given to
    /// a directory made in its place (a folder of the user's, made after DIR was removed, once
    /// got the same number and was replaced as if it were the checked output).
    int oldFd_ = -1;
};

} // namespace shadowlab
