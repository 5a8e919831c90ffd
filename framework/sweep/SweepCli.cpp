#include "framework/sweep/SweepCli.h"

#include "framework/core/Error.h"
#include "framework/sweep/SlurmScript.h"
#include "framework/sweep/SweepCheck.h"
#include "framework/sweep/SweepFile.h"
#include "framework/sweep/SweepMerge.h"
#include "framework/sweep/SweepRunner.h"
#include "framework/sweep/SweepText.h"

#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <iostream>
#include <map>

namespace shadowlab {

namespace {

namespace fs = std::filesystem;

// Limits of the counts on the command line: beyond them a number is a typo (or an attempt to
// wrap), never a real request.
constexpr size_t kMaxJobs = 256;
constexpr size_t kMaxGpusPerTask = 64;
constexpr size_t kMaxCpusPerTask = 1024;
constexpr size_t kMaxTasks = 100000; // runs of the largest sweep (SweepFile.cpp)

struct Usage {
    const char* command;
    const char* text;
};

const Usage kUsages[] = {
    {"plan", R"(  shadowlab sweep plan SWEEP.json [--json] [--check]
      Validates every run's config (docs/sweep.md) and lists the runs: index, id, axis values.
      --check also puts each run through `shadowlab validate` (its memory plan, scene and each
      algorithm's fit on it, decided on this device), one at a time: slower, as each scene is made.
)"},
    {"config", R"(  shadowlab sweep config SWEEP.json INDEX
      Prints the experiment config of one run (what `sweep run` gives `shadowlab run`).
)"},
    {"run", R"(  shadowlab sweep run SWEEP.json [--out DIR] [--jobs N] [--shard I/N | --index K]
      Runs the runs into DIR/runs/ID/ (DIR default: the sweep's output.dir), N at once (1 to 256);
      skips complete runs, so it resumes; --shard I/N does runs I, I+N, ...; --index K does run K.
      Exit code 0 when every selected run is complete, 1 when one failed (DIR/runs/ID.error.json),
      2 for bad input or when another `sweep run` holds DIR (DIR/sweep.lock), 3 when all are
      complete but some run's expectations (its config's `expect`) were not met.
)"},
    {"slurm", R"(  shadowlab sweep slurm SWEEP.json [--out DIR] [--partition P] [--gpus-per-task G]
                        [--cpus-per-task C] [--time T] [--max-parallel K] [--shards N] [--submit]
      Writes DIR/sweep.sbatch, a Slurm array job (one task per run, or N tasks); --submit submits
      it and prints the job id. DIR must be on a file system the nodes share (docs/cluster.md).
      G: 0 to 64, C: 0 to 1024, T: M, M:S, H:M:S, D-H, D-H:M or D-H:M:S; P: Slurm partition names.
)"},
    {"merge", R"(  shadowlab sweep merge DIR [--no-plots]
      Writes DIR/sweep.csv (one row per run, algorithm and measure), DIR/sweep.md and plots.
)"},
};

std::string allUsages() {
    std::string s;
    for (const auto& u : kUsages) s += u.text;
    return s;
}

int printUsage(const std::string& command) {
    for (const auto& u : kUsages)
        if (command == u.command) {
            std::fputs(("Usage:\n" + std::string(u.text)).c_str(), stdout);
            return 0;
        }
    std::fputs(("Usage:\n" + allUsages()).c_str(), stdout);
    return 0;
}

struct Args {
    std::vector<std::string> positional;
    std::map<std::string, std::string> options; ///< --name → value ("" for flags)
    bool help = false;                          ///< --help or -h among the options
};

/// Splits `args` (after "sweep COMMAND") into positionals and the options of `valued` / `flags`.
Args parseArgs(const std::vector<std::string>& args, const std::vector<std::string>& valued, const std::vector<std::string>& flags) {
    Args out;
    for (size_t i = 2; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--help" || a == "-h") {
            out.help = true;
        } else if (std::find(valued.begin(), valued.end(), a) != valued.end()) {
            if (++i >= args.size()) throw InputError(a, "", "needs a value (see shadowlab sweep " + args[1] + " --help)");
            // Twice is a mistake either way (which one was meant?), never the last one silently.
            if (out.options.count(a)) throw InputError(a, "", "is given twice");
            // An empty value would read as the option left out (--partition "" as no partition).
            if (args[i].empty()) throw InputError(a, "", "must not be empty (leave the option out for its default)");
            // `--out --jobs 2` (the value forgotten) would take the next option for the value.
            if (args[i].starts_with("--")) throw InputError(a, "", "needs a value, not the option " + shortText(args[i], 40) + " (a folder named so: ./" + shortText(args[i], 40) + ")");
            out.options[a] = args[i];
        } else if (std::find(flags.begin(), flags.end(), a) != flags.end()) {
            if (out.options.count(a)) throw InputError(a, "", "is given twice");
            out.options[a] = "";
        } else if (!a.empty() && a[0] == '-') {
            throw InputError(shortText(a, 60), "", "unknown option of `sweep " + args[1] + "` (see shadowlab sweep " + args[1] + " --help)");
        } else {
            out.positional.push_back(a);
        }
    }
    return out;
}

std::string one(const Args& a, const std::string& what, const std::string& command) {
    if (a.positional.size() != 1)
        throw InputError("sweep " + command, "", "expects one " + what + " (see shadowlab sweep " + command + " --help)");
    return a.positional[0];
}

std::string get(const Args& a, const std::string& key, const std::string& def = "") {
    auto it = a.options.find(key);
    return it == a.options.end() ? def : it->second;
}

/// Where a sweep runs without --out: its output.dir, except for a sweep's own DIR/sweep.json (a
/// sweep.json beside a runs/ folder) in a folder that has moved since the snapshot was written,
/// which names the old place: the runs are where the snapshot is, so the sweep resumes there.
std::string snapshotFolder(const Sweep& s) {
    const fs::path file(s.file);
    if (file.filename() != "sweep.json") return s.outputDir;
    const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(fs::symlink_status(folder / "runs", ec))) return s.outputDir;
    if (fs::equivalent(folder, s.outputDir, ec)) return s.outputDir;
    std::fprintf(stderr, "sweep: %s was written for %s; this folder's runs are used (the folder has moved)\n",
                 shortText(s.file, 300).c_str(), shortText(s.outputDir, 300).c_str());
    return folder.string();
}

/// --out, or the sweep's output.dir: never empty (DIR + "/runs" would be /runs), and a path that
/// the snapshot (JSON, so UTF-8) and the progress lines (one line) can hold.
std::string outputDir(const Args& a, const Sweep& s) {
    const std::string dir = get(a, "--out", snapshotFolder(s));
    if (dir.empty()) throw InputError("--out", "", "must not be empty (the sweep's folder: DIR/sweep.json, DIR/runs/)");
    if (const std::string why = pathTextProblem(dir); !why.empty()) throw InputError("--out", "", "the folder's name " + why);
    return dir;
}

int plan(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {}, {"--json", "--check"});
    if (a.help) return printUsage("plan");
    const Sweep s = loadSweep(one(a, "sweep file", "plan"));
    // The output folder as `sweep run` checks it before writing (twenty-first probe: plan called
    // "/", a run's output or a folder of the user's valid, and run refused them).
    const std::string folder = snapshotFolder(s);
    try {
        checkSweepFolder(folder);
        checkSweepSnapshot(s, folder);
    } catch (const InputError& e) {
        throw InputError(shortText(s.file, 300), "/output/dir", "\"" + shortText(folder, 200) + "\": " + e.cause());
    }
    const bool checked = a.options.count("--check") > 0;
    if (checked)
        if (const std::string why = checkSweepRuns(s, selfBinary()); !why.empty()) throw InputError(s.file, "", why);
    if (a.options.count("--json")) {
        std::cout << planJson(s).dump(2) << "\n";
        return 0;
    }
    // Labels hold no tab or newline (SweepFile.cpp), so each run is one row of the TSV.
    std::cout << "index\tid";
    for (const auto& axis : s.axes) std::cout << "\t" << axis.name;
    std::cout << "\n";
    for (const auto& run : s.runs) {
        std::cout << run.index << "\t" << run.id;
        for (size_t k = 0; k < s.axes.size(); ++k) std::cout << "\t" << s.axes[k].labels[run.point[k]];
        std::cout << "\n";
    }
    std::cout.flush();
    // Without --check only the configs are checked: said so, as a run can still be refused on its scene.
    std::fprintf(stderr, "%s: %zu runs, %s; output %s\n", shortText(s.file, 300).c_str(), s.runs.size(),
                 checked ? "each validated on this device" : "every config valid (--check also validates each run's memory plan and scene)",
                 shortText(folder, 300).c_str());
    return 0;
}

int config(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {}, {});
    if (a.help) return printUsage("config");
    if (a.positional.size() != 2) throw InputError("sweep config", "", "expects a sweep file and a run index (see shadowlab sweep config --help)");
    const Sweep s = loadSweep(a.positional[0]);
    const size_t k = parseCount(a.positional[1], "INDEX", 0, s.runs.size() - 1);
    std::cout << s.runConfig(k).dump(2) << "\n";
    return 0;
}

int run(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {"--out", "--jobs", "--shard", "--index"}, {});
    if (a.help) return printUsage("run");
    const Sweep s = loadSweep(one(a, "sweep file", "run"));
    SweepRunOptions o;
    o.outputDir = outputDir(a, s);
    o.jobs = parseCount(get(a, "--jobs", "1"), "--jobs", 1, kMaxJobs);
    o.binary = selfBinary();
    if (a.options.count("--shard") && a.options.count("--index")) throw InputError("--shard", "", "give --shard or --index, not both");
    if (a.options.count("--index")) {
        o.indices = {parseCount(a.options["--index"], "--index", 0, s.runs.size() - 1)};
        o.part = true;
    } else if (a.options.count("--shard")) {
        const std::string& t = a.options["--shard"];
        const size_t slash = t.find('/');
        if (slash == std::string::npos) throw InputError("--shard", "", "expected I/N, e.g. 0/4, got \"" + shortText(t, 40) + "\"");
        const size_t n = parseCount(t.substr(slash + 1), "--shard", 1, kMaxTasks);
        const size_t i = parseCount(t.substr(0, slash), "--shard", 0, n - 1);
        // Round robin: a size axis's small and large runs spread over the shards.
        for (size_t k = i; k < s.runs.size(); k += n) o.indices.push_back(k);
        o.part = true;
    } else {
        for (size_t k = 0; k < s.runs.size(); ++k) o.indices.push_back(k);
    }
    return runSweep(s, o);
}

int slurm(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {"--out", "--partition", "--gpus-per-task", "--cpus-per-task", "--time", "--max-parallel", "--shards"}, {"--submit"});
    if (a.help) return printUsage("slurm");
    const Sweep s = loadSweep(one(a, "sweep file", "slurm"));
    SlurmOptions o;
    o.outputDir = outputDir(a, s);
    if (!a.options.count("--out")) { // the sweep file's output.dir (probe 25: an error blamed an --out never given)
        o.outputFrom = s.file;
        o.outputJsonPath = "/output/dir";
    }
    o.partition = get(a, "--partition");
    o.gpusPerTask = int(parseCount(get(a, "--gpus-per-task", "0"), "--gpus-per-task", 0, kMaxGpusPerTask));
    o.cpusPerTask = int(parseCount(get(a, "--cpus-per-task", "0"), "--cpus-per-task", 0, kMaxCpusPerTask));
    o.time = get(a, "--time");
    o.maxParallel = parseCount(get(a, "--max-parallel", "0"), "--max-parallel", 0, kMaxTasks);
    o.shards = parseCount(get(a, "--shards", "0"), "--shards", 0, kMaxTasks);
    const std::string script = writeSlurmScript(s, o, selfBinary());
    std::fprintf(stderr, "sweep: wrote %s (%zu runs)\n", shortText(script, 300).c_str(), s.runs.size());
    if (!a.options.count("--submit")) return 0;
    const std::string job = submitSlurmScript(script);
    std::fprintf(stderr, "sweep: submitted job %s; when it is done: shadowlab sweep merge %s\n", job.c_str(), shortText(o.outputDir, 300).c_str());
    std::cout << job << "\n";
    return 0;
}

int merge(const std::vector<std::string>& args) {
    Args a = parseArgs(args, {}, {"--no-plots"});
    if (a.help) return printUsage("merge");
    const std::string dir = one(a, "output folder", "merge");
    MergeResult r = mergeSweep(dir, !a.options.count("--no-plots"));
    // Names only what was written: without the report, sweep.csv alone.
    std::fprintf(stderr, "sweep merge: %zu of %zu runs merged (%zu failed) into %s/sweep.csv%s\n", r.merged, r.runs, r.failed,
                 shortText(dir, 300).c_str(), r.reportWritten ? ", sweep.md" : " (no report: see above)");
    return r.merged == r.runs && r.reportWritten ? 0 : 1;
}

} // namespace

const std::string kSweepUsage = allUsages();

int sweepCommand(const std::vector<std::string>& args) {
    const std::string cmd = args.size() > 1 ? args[1] : "";
    if (cmd == "--help" || cmd == "-h" || cmd == "help") return printUsage("");
    if (cmd == "plan") return plan(args);
    if (cmd == "config") return config(args);
    if (cmd == "run") return run(args);
    if (cmd == "slurm") return slurm(args);
    if (cmd == "merge") return merge(args);
    // `sweep SOMETHING --help`: the help asked for wins over the unknown command.
    if (std::any_of(args.begin() + 1, args.end(), [](const std::string& a) { return a == "--help" || a == "-h"; })) return printUsage("");
    throw InputError("sweep", "", (cmd.empty() ? std::string("needs a command") : "unknown command \"" + shortText(cmd, 40) + "\"") +
                                      ": plan, config, run, slurm or merge (see shadowlab sweep --help)");
}

} // namespace shadowlab
