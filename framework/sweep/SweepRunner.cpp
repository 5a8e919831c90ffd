#include "framework/sweep/SweepRunner.h"

#include "framework/core/Error.h"
#include "framework/core/Interrupt.h"
#include "framework/experiment/Results.h"

#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

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

/// Starts `binary run CONFIG --out DIR --force --no-progress` with its output in the run's log.
pid_t startRun(const std::string& binary, const RunPaths& p) {
    std::vector<std::string> args = {binary, "run", p.config, "--out", p.dir, "--force", "--no-progress"};
    pid_t pid = fork();
    if (pid < 0) throw RuntimeError(std::string("fork failed: ") + std::strerror(errno));
    if (pid == 0) {
        int fd = open(p.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
            close(fd);
        }
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        execv(binary.c_str(), argv.data());
        std::fprintf(stderr, "cannot run %s: %s\n", binary.c_str(), std::strerror(errno));
        _exit(127);
    }
    return pid;
}

std::string describeStatus(int status) {
    if (WIFEXITED(status)) return "exit code " + std::to_string(WEXITSTATUS(status));
    if (WIFSIGNALED(status)) return std::string("killed by signal ") + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
    return "status " + std::to_string(status);
}

} // namespace

RunPaths::RunPaths(const std::string& outputDir, const std::string& id)
    : dir(outputDir + "/runs/" + id), config(dir + ".config.json"), log(dir + ".log"), error(dir + ".error.json") {}

bool RunPaths::complete() const { return fs::exists(dir + "/summary.json"); }

std::string selfBinary() { return fs::read_symlink("/proc/self/exe").string(); }

void writeSweepSnapshot(const Sweep& sweep, const std::string& outputDir) {
    fs::create_directories(outputDir + "/runs");
    const std::string path = outputDir + "/sweep.json", text = sweep.snapshot(outputDir).dump(2) + "\n";
    if (fs::exists(path) && readFile(path) == text) return;
    writeFileAtomic(path, text);
}

int runSweep(const Sweep& sweep, const SweepRunOptions& opt) {
    writeSweepSnapshot(sweep, opt.outputDir);
    // SIGINT/SIGTERM (a Slurm cancel, Ctrl-C) only set the flag: the runs in flight are stopped first.
    installInterruptHandlers();
    const size_t n = opt.indices.size();
    const int width = int(std::to_string(n).size());
    size_t reported = 0, failed = 0, next = 0;
    struct Running {
        size_t index;
        Clock::time_point start;
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
            if (p.complete()) {
                report(run, "skip", "  (complete already)");
                continue;
            }
            writeFileAtomic(p.config, run.config.dump(2) + "\n");
            running[startRun(opt.binary, p)] = {run.index, Clock::now()};
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
        running.erase(it);
        RunPaths p(opt.outputDir, run.id);
        char took[64];
        std::snprintf(took, sizeof took, "  (%.1f s)", seconds);
        if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && p.complete()) {
            fs::remove(p.error);
            report(run, "done", took);
            continue;
        }
        ++failed;
        Json error = {{"id", run.id},
                      {"index", run.index},
                      {"axes", runLabel(sweep, run)},
                      {"status", describeStatus(status)},
                      {"seconds", seconds},
                      {"log", p.log},
                      {"log_tail", lastLines(readFile(p.log), 8)}};
        writeFileAtomic(p.error, error.dump(2) + "\n");
        report(run, "FAILED", std::string(took) + ": " + describeStatus(status) + "; see " + p.log);
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
    std::fprintf(stderr, "sweep: %zu runs: %zu complete, %zu failed (%s)\n", n, n - failed, failed, opt.outputDir.c_str());
    return failed ? 1 : 0;
}

} // namespace shadowlab
