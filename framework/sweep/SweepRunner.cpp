#include "framework/sweep/SweepRunner.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/Interrupt.h"
#include "framework/experiment/Compare.h"
#include "framework/experiment/Expectations.h"
#include "framework/experiment/OutputPlace.h"
#include "framework/sweep/SweepFile.h"
#include "framework/sweep/SweepProcess.h"
#include "framework/sweep/SweepText.h"

#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <map>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

/// A run's log is read only for the end of it, into its error record; a larger one is named instead.
constexpr size_t kMaxLogBytes = size_t(8) << 20;

std::string lastLines(const std::string& text, size_t n) {
    size_t pos = text.size();
    while (pos > 0 && text[pos - 1] == '\n') --pos;
    size_t end = pos;
    for (size_t k = 0; k < n && pos > 0; ++k) {
        pos = text.rfind('\n', pos - 1);
        if (pos == std::string::npos) {
            pos = 0;
            break;
        }
    }
    return text.substr(pos == 0 ? 0 : pos + 1, end - (pos == 0 ? 0 : pos + 1));
}

std::string logTail(const std::string& log) {
    try {
        // Each line cut, so a run that printed one huge line does not make a huge record.
        std::string tail, lines = lastLines(readInputFile(log, kMaxLogBytes), 8);
        for (size_t start = 0; start <= lines.size();) {
            size_t nl = lines.find('\n', start);
            if (nl == std::string::npos) nl = lines.size();
            if (!tail.empty()) tail += '\n';
            tail += validUtf8(lines.substr(start, std::min<size_t>(nl - start, 1000)));
            start = nl + 1;
        }
        return tail;
    } catch (const InputError& e) {
        return "(" + e.cause() + ")";
    }
}

std::string describeStatus(int status) {
    if (WIFEXITED(status)) return "exit code " + std::to_string(WEXITSTATUS(status));
    if (WIFSIGNALED(status)) return std::string("killed by signal ") + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
    return "status " + std::to_string(status);
}

/// DIR and DIR/runs, made where absent; InputError where something else than a folder is there.
void makeFolders(const std::string& outputDir) {
    checkSweepFolder(outputDir);
    for (const std::string& d : {outputDir, outputDir + "/runs"}) {
        std::error_code ec;
        fs::create_directories(d, ec);
        if (ec) throw InputError(shortText(d, 300), "", "cannot create the folder: " + ec.message());
    }
}

} // namespace

void checkSweepFolder(const std::string& outputDir) {
    if (outputDir.empty()) throw InputError("--out", "", "the output folder must not be empty");
    // A run's output is not a sweep's folder: writing runs/ and plan.json into it would leave a
    // mixture that neither a run's --force nor a sweep can use. Inside a run's output or another
    // sweep a sweep would be deleted by that run's next --force, or mix its runs with the other's;
    // a folder of the user's would be written over (checkSweepPlace).
    if (OutputPlace::isRunOutput(outputDir))
        throw InputError(shortText(outputDir, 300), "", "is a run's output (it holds summary.json or config.resolved.json); "
                                                       "a sweep needs a folder of its own");
    OutputPlace::checkSweepPlace(outputDir);
    for (const std::string& d : {outputDir, outputDir + "/runs"}) {
        std::error_code ec;
        const fs::file_status st = fs::status(d, ec);
        if (fs::exists(st) && !fs::is_directory(st)) throw InputError(shortText(d, 300), "", "is not a folder (the sweep's output folder goes there)");
    }
    // The runs go into the sweep's own folder, never through a link into someone else's
    // (twenty-third probe: a linked runs/ had a user's files there replaced by the runs' logs).
    std::error_code ec;
    if (fs::is_symlink(fs::symlink_status(outputDir + "/runs", ec)))
        throw InputError(shortText(outputDir + "/runs", 300), "", "is a symbolic link; a sweep writes its runs into a folder of its own");
}

RunPaths::RunPaths(const std::string& outputDir, const std::string& id)
    : id(id), dir(outputDir + "/runs/" + id), config(dir + ".config.json"), log(dir + ".log"), error(dir + ".error.json"),
      lock(dir + ".sweep.lock") {}

bool RunPaths::complete(std::string* why) const {
    if (why) why->clear();
    const std::string summary = dir + "/summary.json";
    std::error_code ec;
    const fs::file_status slot = fs::symlink_status(dir, ec);
    if (!fs::exists(slot)) return false;
    auto fail = [&](const std::string& reason) {
        if (why) *why = reason;
        return false;
    };
    if (!fs::is_directory(slot)) return fail("runs/" + id + " is not a folder of its own (a link or a file)");
    const fs::file_status summaryStatus = fs::symlink_status(summary, ec);
    if (!fs::exists(summaryStatus)) return fail("the run's folder has no summary.json");
    // A run writes its summary itself: a link there is another file's, not this run's result.
    if (fs::is_symlink(summaryStatus)) return fail("summary.json is a symbolic link, not the run's own file");
    Json s;
    try {
        s = JsonNode::parseFile(summary);
        if (!(s.is_object() && s.contains("complete") && s["complete"] == true)) return fail("summary.json does not say \"complete\": true");
    } catch (const InputError& e) {
        return fail("summary.json " + e.cause());
    }
    Json resolved;
    try {
        // The results are this run's only if the config they were made from is this run's config.
        resolved = JsonNode::parseFile(dir + "/config.resolved.json");
        const std::string made = runId(resolved);
        if (made != id) return fail("the folder holds the results of another config (run " + made + "), not of this run");
    } catch (const InputError& e) {
        return fail("config.resolved.json " + e.cause());
    }
    // And under the ids that config gives them (eleventh probe: an id rewritten as a formula,
    // =HYPERLINK(...), reached sweep.csv from a summary.json that was taken as complete).
    std::set<std::string> ids;
    collectIds(resolved, ids);
    if (s.contains("algorithms") && s["algorithms"].is_object())
        for (const auto& [name, entry] : s["algorithms"].items()) {
            if (!ids.count(name))
                return fail("summary.json has results under the id \"" + shortText(name, 60) +
                            "\", which its config.resolved.json does not give");
            // And of the algorithm the config runs under that id (seventeenth probe: a formula
            // written as the algorithm reached sweep.csv).
            if (const std::string algorithm = algorithmOf(resolved, name); entry.is_object() && entry.value("algorithm", Json()) != Json(algorithm))
                return fail("summary.json names another algorithm for \"" + shortText(name, 60) + "\" than its config.resolved.json (" +
                            shortText(algorithm, 60) + ")");
        }
    return true;
}

bool RunPaths::expectationsFailed() const {
    try {
        const Json s = JsonNode::parseFile(dir + "/summary.json");
        return s.contains("expectations") && !allPassed(s["expectations"]);
    } catch (const InputError&) {
        return false;  // complete() decided already whether the summary can be read
    }
}

std::string selfBinary() { return fs::read_symlink("/proc/self/exe").string(); }

bool checkSweepSnapshot(const Sweep& sweep, const std::string& outputDir) {
    const std::string path = outputDir + "/sweep.json";
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(path, ec))) return false;
    Json old;
    try {
        old = JsonNode::parseFile(path);
    } catch (const InputError& e) {
        throw InputError(shortText(path, 300), "", e.cause() + " (not a sweep's snapshot: remove it, or choose another --out)");
    }
    // The same sweep, whatever folder it was written from: resume. Another one: refuse, since
    // replacing sweep.json would make the runs already there belong to a sweep they are not of.
    Json a = old, b = sweep.snapshot(outputDir);
    if (a.is_object()) a.erase("output");
    b.erase("output");
    if (a != b) {
        const std::string oldName = old.is_object() && old.contains("name") && old["name"].is_string() ? old["name"].get<std::string>() : "?";
        throw InputError(shortText(path, 300), "",
                         "holds another sweep (\"" + shortText(oldName, 60) + "\") than " + shortText(sweep.file, 200) + " (\"" +
                             shortText(sweep.name, 60) + "\"): choose another --out, or remove " + shortText(path, 200) +
                             " to give the folder to the new sweep (its complete runs with equal ids are kept)");
    }
    return true;
}

void writeSweepSnapshot(const Sweep& sweep, const std::string& outputDir) {
    makeFolders(outputDir);
    const std::string path = outputDir + "/sweep.json";
    const std::string text = sweep.snapshot(outputDir).dump(2) + "\n";
    if (checkSweepSnapshot(sweep, outputDir) && readInputFile(path) == text) return;
    writeFileAtomic(path, text);
}

int runSweep(const Sweep& sweep, const SweepRunOptions& opt) {
    makeFolders(opt.outputDir);
    const std::string where = shortText(opt.outputDir, 300);
    FileLock folderLock;
    if (!folderLock.tryLock(opt.outputDir + "/sweep.lock", opt.part ? FileLock::Mode::Shared : FileLock::Mode::Exclusive))
        throw InputError(where, "", opt.part ? "a `sweep run` of the whole sweep is running in this folder (sweep.lock is held): wait for it"
                                             : "another `sweep run` is running in this folder (sweep.lock is held): wait for it, or stop it");
    writeSweepSnapshot(sweep, opt.outputDir);
    // SIGINT/SIGTERM (a Slurm cancel, Ctrl-C) only set the flag: the runs in flight are stopped first.
    installInterruptHandlers();
    const size_t n = opt.indices.size();
    const int width = int(std::to_string(n).size());
    size_t reported = 0, failed = 0, busy = 0, unmet = 0, next = 0;
    struct Running {
        size_t index;
        Clock::time_point start;
        FileLock lock;
    };
    std::map<pid_t, Running> running;

    auto report = [&](const SweepRun& run, const char* what, const std::string& detail) {
        ++reported;
        std::fprintf(stderr, "sweep: [%*zu/%zu] %-7s run %zu %s  %s%s\n", width, reported, n, what, run.index, run.id.c_str(),
                     runLabel(sweep, run).c_str(), detail.c_str());
        std::fflush(stderr);
    };

    while (!pendingInterrupt() && (next < n || !running.empty())) {
        // Fill the free slots; complete runs are skipped without taking one.
        while (!pendingInterrupt() && next < n && running.size() < std::max<size_t>(1, opt.jobs)) {
            const SweepRun& run = sweep.runs.at(opt.indices[next++]);
            RunPaths p(opt.outputDir, run.id);
            FileLock runLock;
            if (!runLock.tryLock(p.lock, FileLock::Mode::Exclusive)) {
                ++busy;
                report(run, "BUSY", "  (another sweep process is running it)");
                continue;
            }
            std::string why;
            std::error_code ec;
            if (p.complete(&why)) {
                // An error record of an earlier failed attempt says nothing about a complete run.
                const bool stale = fs::remove(p.error, ec);
                const bool unmetHere = p.expectationsFailed();
                unmet += unmetHere ? 1 : 0;
                report(run, "skip", std::string(stale ? "  (complete already; removed its stale error record)" : "  (complete already)") +
                                        (unmetHere ? "; its expectations failed (report.md)" : ""));
                continue;
            }
            if (!why.empty())
                std::fprintf(stderr, "sweep: run %zu %s is not complete: %s; running it again\n", run.index, run.id.c_str(),
                             shortText(why, 300).c_str());
            writeFileAtomic(p.config, sweep.runConfig(run.index).dump(2) + "\n");
            const pid_t pid = startLoggedChild({opt.binary, "run", p.config, "--out", p.dir, "--force", "--no-progress"}, p.log);
            running.emplace(pid, Running{run.index, Clock::now(), std::move(runLock)});
        }
        if (running.empty()) continue;
        int status = 0;
        // Polled, so a stop signal is acted on at once rather than when a run ends.
        pid_t pid = waitpid(-1, &status, WNOHANG);
        if (pid == 0 || (pid < 0 && errno == EINTR)) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            continue;
        }
        if (pid < 0) throw RuntimeError(std::string("waitpid failed: ") + std::strerror(errno));
        auto it = running.find(pid);
        if (it == running.end()) continue;
        const SweepRun& run = sweep.runs[it->second.index];
        const double seconds = std::chrono::duration<double>(Clock::now() - it->second.start).count();
        RunPaths p(opt.outputDir, run.id);
        char took[64];
        std::snprintf(took, sizeof took, "  (%.1f s)", seconds);
        std::string why;
        // Exit 3: every result written, some of the config's expectations not met (Expectations.h).
        const bool ran = WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == kExpectationsFailedExit);
        if (ran && p.complete(&why)) {
            std::error_code ec;
            fs::remove(p.error, ec);
            const bool unmetHere = p.expectationsFailed();
            unmet += unmetHere ? 1 : 0;
            report(run, "done", std::string(took) + (unmetHere ? "; its expectations failed (report.md)" : ""));
            running.erase(it);
            continue;
        }
        ++failed;
        const std::string cause = describeStatus(status) + (ran ? "; " + why : "");
        Json error = {{"id", run.id},
                      {"index", run.index},
                      {"axes", runLabel(sweep, run)},
                      {"status", cause},
                      {"seconds", seconds},
                      {"log", p.log},
                      {"log_tail", logTail(p.log)}};
        // replace: a byte of the log that is not UTF-8 must not lose the record.
        writeFileAtomic(p.error, error.dump(2, ' ', false, Json::error_handler_t::replace) + "\n");
        report(run, "FAILED", std::string(took) + ": " + shortText(cause, 300) + "; see " + shortText(p.log, 300));
        running.erase(it);
    }

    if (pendingInterrupt()) {
        // Stop the runs in flight and wait for them: nothing is left writing once this returns.
        for (const auto& [pid, r] : running) kill(pid, SIGTERM);
        for (const auto& [pid, r] : running) {
            waitpid(pid, nullptr, 0);
            // A run assembles its folder under ID.partial-PID (Runner.h); a stopped one never finishes it.
            std::error_code ec;
            fs::remove_all(RunPaths(opt.outputDir, sweep.runs[r.index].id).dir + ".partial-" + std::to_string(pid), ec);
        }
        std::fprintf(stderr, "sweep: stopped by signal %d; %zu of %zu runs reported; run the same command again to finish\n",
                     int(pendingInterrupt()), reported, n);
        return 128 + int(pendingInterrupt());
    }
    std::fprintf(stderr, "sweep: %zu runs: %zu complete, %zu failed%s%s (%s)\n", n, n - failed - busy, failed,
                 busy ? (", " + std::to_string(busy) + " run by another sweep process").c_str() : "",
                 unmet ? (", " + std::to_string(unmet) + " complete with expectations not met").c_str() : "", where.c_str());
    return failed ? 1 : busy ? 2 : unmet ? kExpectationsFailedExit : 0;
}

} // namespace shadowlab
