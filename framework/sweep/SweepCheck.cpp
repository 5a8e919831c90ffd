#include "framework/sweep/SweepCheck.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/Text.h"
#include "framework/sweep/SweepProcess.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <unistd.h>

namespace shadowlab {

namespace {

/// A private folder for the runs' configs, removed with everything in it when done.
class ScratchFolder {
public:
    ScratchFolder() {
        // TMPDIR when it is an absolute path the runs' own check takes, else /tmp (probe 26: a line
        // break in TMPDIR refused every run of a valid sweep, naming the run).
        const char* tmp = std::getenv("TMPDIR");
        const bool usable = tmp && tmp[0] == '/' && pathTextProblem(tmp).empty();
        std::string pattern = std::string(usable ? tmp : "/tmp") + "/shadowlab-sweep-check-XXXXXX";
        if (!mkdtemp(pattern.data())) throw RuntimeError("sweep plan --check: cannot make a temporary folder in " + shortText(pattern, 200));
        path_ = pattern;
    }
    ~ScratchFolder() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    const std::string& path() const { return path_; }

private:
    std::string path_;
};

/// The last non-empty line of a child's output: validate's one error line.
std::string lastLine(const std::string& text) {
    size_t end = text.find_last_not_of("\n");
    if (end == std::string::npos) return "";
    const size_t start = text.rfind('\n', end);
    return text.substr(start == std::string::npos ? 0 : start + 1, end - (start == std::string::npos ? 0 : start + 1) + 1);
}

void replaceAll(std::string& s, const std::string& from, const std::string& to) {
    for (size_t at = s.find(from); !from.empty() && at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
}

} // namespace

std::string checkSweepRuns(const Sweep& sweep, const std::string& binary) {
    ScratchFolder scratch;
    const std::string file = scratch.path() + "/run.json";
    for (const SweepRun& run : sweep.runs) {
        Json config = sweep.runConfig(run.index);
        // The run's own output place is DIR/runs/ID, checked by `sweep run`; validate's check of
        // output.dir is kept off the user's folders.
        config["output"]["dir"] = scratch.path() + "/out";
        writeFileAtomic(file, config.dump(2) + "\n");
        std::string output;
        const int status = captureChild({binary, "validate", file}, output);
        if (status != 0) {
            std::string why = lastLine(output);
            // Named as `sweep config SWEEP K` prints it, not by the scratch file gone after this.
            replaceAll(why, file, "run " + std::to_string(run.index) + "'s config");
            for (const char* prefix : {"shadowlab: ", "error: "})
                if (why.starts_with(prefix)) why.erase(0, std::string(prefix).size());
            return "run " + std::to_string(run.index) + " (" + run.id + ", " + runLabel(sweep, run) + ") is refused" +
                   (status == 2 ? "" : " (validate exit " + std::to_string(status) + ")") + ": " + shortText(why, 600);
        }
        if ((run.index + 1) % 10 == 0 || run.index + 1 == sweep.runs.size())
            std::fprintf(stderr, "sweep plan --check: %zu of %zu runs valid\n", run.index + 1, sweep.runs.size());
    }
    return "";
}

} // namespace shadowlab
