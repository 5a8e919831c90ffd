#pragma once
// The small sweep that the sweep tests run (2 × 2 runs, 64², 2 frames, a few hundred triangles,
// no warm-up, no images or plots: about a second a run on llvmpipe) and the reading of sweep.csv.
#include "framework/core/JsonNode.h"

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <poll.h>
#include <set>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace shadowlab::test {

inline Json smallSweep() {
    return Json::parse(R"({
  "name": "small",
  "base": {
    "resolution": [64, 64], "frames": 2, "warmup_frames": 0,
    "scene": {"objects": [
      {"procedural": "plane", "size": [6, 6]},
      {"procedural": "sphere", "radius": 0.5, "triangles": 300, "transform": {"translate": [0, 0.7, 0]}}
    ]},
    "camera": {"position": [0, 3, 5], "target": [0, 0, 0]},
    "light": {"position": [1, 4, 1]},
    "algorithms": [{"algorithm": "shadow_map", "params": {"resolution": 256}}, {"algorithm": "psv"}],
    "output": {"images_at_frames": [], "plots": false}
  },
  "axes": [
    {"name": "tris", "values": {"scene.objects.1.triangles": [300, 1200]}, "scale": "triangles"},
    {"name": "pcf", "values": {"algorithms.0.params.pcf": [0, 1]}}
  ],
  "merge": {"ratios": ["psv/shadow_map"]}
})");
}

/// smallSweep() cut to two runs of one frame (an axis of pcf 0 and 1), no merge section: for the
/// tests about a sweep's folder and slots rather than its tables.
inline Json twoRunSweep() {
    Json sweep = smallSweep();
    sweep["base"]["frames"] = 1;
    sweep["axes"] = Json::parse(R"([{"name": "pcf", "values": {"algorithms.0.params.pcf": [0, 1]}}])");
    sweep.erase("merge");
    return sweep;
}

inline std::string writeJson(const std::string& path, const Json& j) {
    std::ofstream(path) << j.dump(2);
    return path;
}

/// sweep.csv rows of one kind (SweepMerge.cpp: "accuracy", which depends on the config alone;
/// "counter"; "cache"; "time"), keyed "run,index,axes...,triangles,pixels,id,algorithm,measure" → value;
/// an empty kind keeps every row (with its value blanked: the keys alone).
inline std::map<std::string, std::string> rowsOfKind(const std::string& csvPath, const std::string& kind) {
    std::ifstream in(csvPath);
    std::string line;
    std::getline(in, line); // header
    std::map<std::string, std::string> rows;
    while (std::getline(in, line)) {
        const size_t valueComma = line.rfind(','), kindComma = line.rfind(',', valueComma - 1);
        if (kind.empty()) rows[line.substr(0, kindComma)] = "";
        else if (line.substr(kindComma + 1, valueComma - kindComma - 1) == kind) rows[line.substr(0, kindComma)] = line.substr(valueComma + 1);
    }
    return rows;
}

/// The run ids of sweep.csv.
inline std::set<std::string> runIds(const std::string& csvPath) {
    std::ifstream in(csvPath);
    std::string line;
    std::getline(in, line);
    std::set<std::string> ids;
    while (std::getline(in, line)) ids.insert(line.substr(0, line.find(',')));
    return ids;
}

/// The whole of a file ("" when it cannot be read).
inline std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// What a command run by runArgs did.
struct Ran {
    int rc = -1;           ///< exit code; 128 + signal when it died of one
    std::string out, err;  ///< stdout, stderr
    long maxRssKiB = 0;    ///< its peak resident memory (wait4's ru_maxrss)
};

/// Runs `argv` (argv[0] a path) without a shell, so an argument may hold any byte (newlines,
/// quotes, $(...)) exactly as a user's shell would pass it; `env` entries NAME=VALUE are added
/// to its environment, `cwd` is its working directory when not empty.
inline Ran runArgs(const std::vector<std::string>& argv, const std::vector<std::string>& env = {}, const std::string& cwd = "") {
    int out[2], err[2];
    Ran r;
    if (pipe(out) != 0 || pipe(err) != 0) return r;
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const pid_t pid = fork();
    if (pid == 0) {
        dup2(out[1], 1);
        dup2(err[1], 2);
        close(out[0]), close(out[1]), close(err[0]), close(err[1]);
        for (const auto& e : env) putenv(const_cast<char*>(e.c_str()));
        if (!cwd.empty() && chdir(cwd.c_str()) != 0) _exit(126);
        execv(args[0], args.data());
        _exit(127);
    }
    close(out[1]);
    close(err[1]);
    pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
    std::string* into[2] = {&r.out, &r.err};
    int open = 2;
    while (open > 0) {
        if (poll(fds, 2, -1) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        for (int k = 0; k < 2; ++k) {
            if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
            char buf[4096];
            const ssize_t n = read(fds[k].fd, buf, sizeof buf);
            if (n > 0) {
                into[k]->append(buf, size_t(n));
            } else {
                close(fds[k].fd);
                fds[k].fd = -1;
                --open;
            }
        }
    }
    int status = 0;
    rusage usage {};
    while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {}
    r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
    r.maxRssKiB = usage.ru_maxrss;
    return r;
}

/// A summary.json as a finished run writes it, with what `sweep merge` reads: two algorithm
/// entries (one without accuracy), times that grow with the triangle count.
inline Json fakeSummary(uint64_t triangles) {
    const double t = 1.0 + double(triangles) / 1000.0;
    auto entry = [&](const char* algorithm, double scale, bool accuracy) {
        Json e = {{"algorithm", algorithm},
                  {"params", Json::object()},
                  {"time_ms", {{"build", {{"mean", 0.4 * t * scale}}}, {"total", {{"mean", t * scale}}}}},
                  {"preprocess_ms", 0.5},
                  {"counters", {{"nodes", {{"mean", 10.0 * scale}}}}},
                  {"memory_bytes", 1 << 20},
                  {"overflow", 0}};
        e["accuracy"] = accuracy ? Json{{"mismatch_ratio", 0.001}, {"mismatch_ratio_max", 0.002}, {"false_lit", 0.0005},
                                        {"false_shadowed", 0.0005}, {"rmse", 0.01}}
                                 : Json();
        return e;
    };
    return {{"complete", true},
            {"renderer", "test"},
            {"stage_time_source", "wall"},
            {"triangles", triangles},
            {"resolution", {64, 64}},
            {"algorithms", {{"psv", entry("psv", 1.0, true)}, {"shadow_map", entry("shadow_map", 0.5, false)}}}};
}

/// `sweep plan --json` of `file` (a sweep file or DIR/sweep.json).
inline Json planOf(const std::string& binary, const std::string& file) {
    const Ran r = runArgs({binary, "sweep", "plan", file, "--json"});
    return r.rc == 0 ? Json::parse(r.out) : Json();
}

/// DIR/runs/ID of run `index` of the sweep whose snapshot is `snapshot`, as its run leaves it but
/// without rendering: its config (`sweep config`), its config.resolved.json (what `validate` prints
/// of it, as the run writes it: the sweep takes the folder for the run's by it) and `summary`.
/// false when a command failed.
inline bool fakeRunFolder(const std::string& binary, const std::string& snapshot, size_t index, const std::string& runDir,
                          const Json& summary) {
    const Ran config = runArgs({binary, "sweep", "config", snapshot, std::to_string(index)});
    if (config.rc != 0) return false;
    // Its own slot as output.dir: validate checks the place as `run --out` would.
    Json c = Json::parse(config.out);
    c["output"]["dir"] = runDir;
    std::ofstream(runDir + ".config.json") << c.dump(2);
    const Ran resolved = runArgs({binary, "validate", runDir + ".config.json"});
    if (resolved.rc != 0) return false;
    std::filesystem::create_directories(runDir);
    std::ofstream(runDir + "/config.resolved.json") << resolved.out;
    // The run's own resolution, as a run writes it (compare and merge hold the summary to its config).
    Json own = summary;
    const Json r = Json::parse(resolved.out, nullptr, false);
    if (own.is_object() && own.contains("resolution") && r.is_object() && r.contains("resolution")) own["resolution"] = r["resolution"];
    // And the reference's results, where its config compares with it (a run writes them; compare and
    // merge hold a summary to the ids its config gives).
    if (own.is_object() && own.contains("algorithms") && own["algorithms"].contains("shadow_map") && r.is_object() &&
        r.value("reference", Json(true)) != Json(false) && !own["algorithms"].contains("reference")) {
        Json reference = own["algorithms"]["shadow_map"];
        reference["algorithm"] = "reference";
        own["algorithms"]["reference"] = reference;
    }
    std::ofstream(runDir + "/summary.json") << own.dump(2);
    return true;
}

/// DIR as `sweep run` leaves it when every run has finished, without rendering anything: the
/// snapshot (written by `sweep slurm`) and a fakeRunFolder() with a fakeSummary() per run.
/// Returns the plan (null when a command failed).
inline Json fakeSweepRuns(const std::string& binary, const std::string& sweepFile, const std::string& out) {
    const Ran r = runArgs({binary, "sweep", "slurm", sweepFile, "--out", out});
    if (r.rc != 0) return Json();
    const Json plan = planOf(binary, out + "/sweep.json");
    for (const Json& run : plan["runs"]) {
        const uint64_t index = run["index"].get<uint64_t>();
        if (!fakeRunFolder(binary, out + "/sweep.json", index, out + "/runs/" + run["id"].get<std::string>(), fakeSummary(1000 * (index + 1))))
            return Json();
    }
    return plan;
}

} // namespace shadowlab::test
