#include "framework/sweep/SweepCli.h"

#include "framework/core/Error.h"
#include "framework/sweep/SlurmScript.h"
#include "framework/sweep/SweepFile.h"
#include "framework/sweep/SweepMerge.h"
#include "framework/sweep/SweepRunner.h"

#include <cstdio>
#include <iostream>
#include <map>

namespace shadowlab {

const char* kSweepUsage = R"(  shadowlab sweep plan SWEEP.json [--json]
      Validates every run of a sweep (docs/sweep.md) and lists them: index, id, axis values.
  shadowlab sweep config SWEEP.json INDEX
      Prints the experiment config of one run (what `sweep run` gives `shadowlab run`).
  shadowlab sweep run SWEEP.json [--out DIR] [--jobs N] [--shard I/N | --index K]
      Runs the runs into DIR/runs/ID/ (DIR default: the sweep's output.dir), N at once; skips
      complete runs, so it resumes; --shard I/N does runs I, I+N, ...; --index K does run K.
      Exit code 0 when every selected run is complete, 1 when one failed (DIR/runs/ID.error.json).
  shadowlab sweep slurm SWEEP.json [--out DIR] [--partition P] [--gpus-per-task G]
                        [--cpus-per-task C] [--time T] [--max-parallel K] [--shards N] [--submit]
      Writes DIR/sweep.sbatch, a Slurm array job (one task per run, or N tasks); --submit submits
      it and prints the job id. DIR must be on a file system the nodes share (docs/cluster.md).
  shadowlab sweep merge DIR [--no-plots]
      Writes DIR/sweep.csv (one row per run, algorithm and measure), DIR/sweep.md and plots.
)";

namespace {

struct Args {
    std::vector<std::string> positional;
    std::map<std::string, std::string> options; ///< --name → value ("" for flags)
};

/// Splits `args` (after "sweep COMMAND") into positionals and the options of `valued` / `flags`.
Args parseArgs(const std::vector<std::string>& args, const std::vector<std::string>& valued, const std::vector<std::string>& flags) {
    Args out;
    for (size_t i = 2; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (std::find(valued.begin(), valued.end(), a) != valued.end()) {
            if (++i >= args.size()) throw InputError(a, "", "needs a value (see shadowlab --help)");
            out.options[a] = args[i];
        } else if (std::find(flags.begin(), flags.end(), a) != flags.end()) {
            out.options[a] = "";
        } else if (!a.empty() && a[0] == '-') {
            throw InputError(a, "", "unknown option of `sweep " + args[1] + "` (see shadowlab --help)");
        } else {
            out.positional.push_back(a);
        }
    }
    return out;
}

size_t toCount(const std::string& text, const std::string& option, size_t minValue) {
    size_t used = 0;
    unsigned long v = 0;
    try {
        v = std::stoul(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || v < minValue)
        throw InputError(option, "", "expected a whole number ≥ " + std::to_string(minValue) + ", got \"" + text + "\"");
    return v;
}

std::string one(const Args& a, const std::string& what, const std::string& command) {
    if (a.positional.size() != 1) throw InputError("sweep " + command, "", "expects one " + what + " (see shadowlab --help)");
    return a.positional[0];
}

std::string get(const Args& a, const std::string& key, const std::string& def = "") {
    auto it = a.options.find(key);
    return it == a.options.end() ? def : it->second;
}

int plan(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {}, {"--json"});
    const Sweep s = loadSweep(one(a, "sweep file", "plan"));
    if (a.options.count("--json")) {
        std::cout << planJson(s).dump(2) << "\n";
        return 0;
    }
    std::cout << "index\tid";
    for (const auto& axis : s.axes) std::cout << "\t" << axis.name;
    std::cout << "\n";
    for (const auto& run : s.runs) {
        std::cout << run.index << "\t" << run.id;
        for (size_t k = 0; k < s.axes.size(); ++k) std::cout << "\t" << s.axes[k].labels[run.point[k]];
        std::cout << "\n";
    }
    std::fprintf(stderr, "%s: %zu runs, all valid; output %s\n", s.file.c_str(), s.runs.size(), s.outputDir.c_str());
    return 0;
}

int config(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {}, {});
    if (a.positional.size() != 2) throw InputError("sweep config", "", "expects a sweep file and a run index");
    const Sweep s = loadSweep(a.positional[0]);
    const size_t k = toCount(a.positional[1], "INDEX", 0);
    if (k >= s.runs.size()) throw InputError(a.positional[1], "", "no run " + std::to_string(k) + " in " + std::to_string(s.runs.size()) + " runs");
    std::cout << s.runs[k].config.dump(2) << "\n";
    return 0;
}

int run(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {"--out", "--jobs", "--shard", "--index"}, {});
    const Sweep s = loadSweep(one(a, "sweep file", "run"));
    SweepRunOptions o;
    o.outputDir = get(a, "--out", s.outputDir);
    o.jobs = toCount(get(a, "--jobs", "1"), "--jobs", 1);
    o.binary = selfBinary();
    if (a.options.count("--shard") && a.options.count("--index")) throw InputError("--shard", "", "give --shard or --index, not both");
    if (a.options.count("--index")) {
        const size_t k = toCount(a.options["--index"], "--index", 0);
        if (k >= s.runs.size()) throw InputError("--index", "", "no run " + std::to_string(k) + " in " + std::to_string(s.runs.size()) + " runs");
        o.indices = {k};
    } else if (a.options.count("--shard")) {
        const std::string& t = a.options["--shard"];
        const size_t slash = t.find('/');
        if (slash == std::string::npos) throw InputError("--shard", "", "expected I/N, e.g. 0/4, got \"" + t + "\"");
        const size_t i = toCount(t.substr(0, slash), "--shard", 0), n = toCount(t.substr(slash + 1), "--shard", 1);
        if (i >= n) throw InputError("--shard", "", "I must be below N in I/N, got \"" + t + "\"");
        // Round robin: a size axis's small and large runs spread over the shards.
        for (size_t k = i; k < s.runs.size(); k += n) o.indices.push_back(k);
    } else {
        for (size_t k = 0; k < s.runs.size(); ++k) o.indices.push_back(k);
    }
    return runSweep(s, o);
}

int slurm(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {"--out", "--partition", "--gpus-per-task", "--cpus-per-task", "--time", "--max-parallel", "--shards"}, {"--submit"});
    const Sweep s = loadSweep(one(a, "sweep file", "slurm"));
    SlurmOptions o;
    o.outputDir = get(a, "--out", s.outputDir);
    o.partition = get(a, "--partition");
    o.gpusPerTask = int(toCount(get(a, "--gpus-per-task", "0"), "--gpus-per-task", 0));
    o.cpusPerTask = int(toCount(get(a, "--cpus-per-task", "0"), "--cpus-per-task", 0));
    o.time = get(a, "--time");
    o.maxParallel = toCount(get(a, "--max-parallel", "0"), "--max-parallel", 0);
    o.shards = toCount(get(a, "--shards", "0"), "--shards", 0);
    const std::string script = writeSlurmScript(s, o, selfBinary());
    std::fprintf(stderr, "sweep: wrote %s (%zu runs)\n", script.c_str(), s.runs.size());
    if (!a.options.count("--submit")) return 0;
    const std::string job = submitSlurmScript(script);
    std::fprintf(stderr, "sweep: submitted job %s; when it is done: shadowlab sweep merge %s\n", job.c_str(), o.outputDir.c_str());
    std::cout << job << "\n";
    return 0;
}

int merge(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {}, {"--no-plots"});
    const std::string dir = one(a, "output folder", "merge");
    MergeResult r = mergeSweep(dir, !a.options.count("--no-plots"));
    std::fprintf(stderr, "sweep merge: %zu of %zu runs merged (%zu failed) into %s/sweep.csv, sweep.md\n", r.merged, r.runs, r.failed,
                 dir.c_str());
    return r.merged == r.runs && r.reportWritten ? 0 : 1;
}

} // namespace

int sweepCommand(const std::vector<std::string>& args) {
    const std::string cmd = args.size() > 1 ? args[1] : "";
    if (cmd == "plan") return plan(args);
    if (cmd == "config") return config(args);
    if (cmd == "run") return run(args);
    if (cmd == "slurm") return slurm(args);
    if (cmd == "merge") return merge(args);
    throw InputError("sweep", "", (cmd.empty() ? std::string("needs a command") : "unknown command \"" + cmd + "\"") +
                                      ": plan, config, run, slurm or merge (see shadowlab --help)");
}

} // namespace shadowlab
