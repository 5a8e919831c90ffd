// shadowlab: the headless command line. One binary per GL back end (OSMesa, EGL) links this file.
#include "framework/algorithm/ShadowAlgorithm.h"
#include "framework/core/Error.h"
#include "framework/core/Interrupt.h"
#include "framework/core/StandardStreams.h"
#include "framework/experiment/Config.h"
#include "framework/experiment/MemoryPlan.h"
#include "framework/experiment/OutputPlace.h"
#include "framework/experiment/DeviceReport.h"
#include "framework/experiment/Runner.h"
#include "framework/gl/DeviceInfo.h"
#include "framework/experiment/CompareCli.h"
#include "framework/gl/GlContext.h"
#include "framework/scene/SceneConfig.h"
#include "framework/sweep/SweepCli.h"
#include "framework/sweep/SweepText.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

using namespace shadowlab;

namespace {

const char* kRunUsage = R"(  shadowlab run CONFIG.json [--out DIR] [--force] [--no-progress] [--set PATH=VALUE]...
      Runs the experiment and writes DIR (default: the config's output.dir): config.resolved.json,
      frames.csv, summary.json, report.md, images/ and plots. An existing DIR is kept unless --force;
      it is replaced only once the new run has completed.
      --set overrides one config value before validation, by dotted path (array elements by
      index), VALUE as JSON or a plain string: --set resolution=[128,128] --set frames=3
      --set algorithms.0.params.pcf=0 --set light.type=directional
      The config's `expect` bounds are checked once every result is written: exit code 3 when
      one is not met (report.md's first table, expectations.junit.xml).
)";
const char* kValidateUsage = R"(  shadowlab validate CONFIG.json [--set PATH=VALUE]...
      Checks the config (and loads its scene) without rendering; prints the resolved config.
)";
const char* kPlanUsage = R"(  shadowlab plan CONFIG.json [--set PATH=VALUE]... [--triangles N]
      The memory a run would need, without making the scene: the scene's predicted triangles (or
      N, 1 to 200000000), each algorithm's estimate or why it refuses the scene on this device, and
      the total against the memory available. Exit 2 when the run would be refused (as run would
      refuse it).
)";
const char* kListUsage = R"(  shadowlab list [--json | --markdown [NAME]]
      Lists the registered algorithms and their parameters; --markdown prints each parameter table
      as docs/algorithms/NAME.md holds it (scripts/update_param_docs.py rewrites the docs from it).
)";
const char* kInfoUsage = R"(  shadowlab info [--json]
      Prints what this binary runs on: the GL implementation (vendor, renderer, version, GLSL, back
      end), the limits the algorithms depend on, the subgroup width (0: no ARB_shader_ballot), the
      extensions the shaders use and whether each is present, and for every algorithm what its
      device-dependent parameters (auto, or 0 for a rule) resolve to with the defaults. --json: one
      JSON object, summary.json's device record plus each algorithm's resolved_params.
)";

std::string fullUsage() {
    return std::string("shadowlab: real-time shadow algorithms side by side, checked against a ray-traced reference.\n\nUsage:\n") +
           kRunUsage + kValidateUsage + kPlanUsage + kListUsage + kInfoUsage + kSweepUsage + kCompareUsage + kHistoryUsage + "  shadowlab --help | --version\n\n" +
           "Exit codes: 0 success, 2 bad input (config, scene file, parameter), 1 runtime failure,\n"
           "3 a run's expectations not met (every result written), 128 + N stopped by signal N.\n";
}

/// `COMMAND --help`: that command's usage on stdout, exit code 0.
int commandUsage(const char* text) {
    std::fputs((std::string("Usage:\n") + text).c_str(), stdout);
    return 0;
}

bool isHelp(const std::string& a) { return a == "--help" || a == "-h"; }

void printList(bool json) {
    if (json) {
        Json out = Json::array();
        for (const auto& a : algorithmRegistry()) {
            Json lights = Json::array();
            for (LightType t : a.lights) lights.push_back(toString(t));
            out.push_back({{"name", a.name}, {"summary", a.summary}, {"lights", lights}, {"exact", a.exact},
                           {"motion", toString(a.motion)}, {"params", a.schema().toJson()}});
        }
        std::cout << out.dump(2) << "\n";
        return;
    }
    for (const auto& a : algorithmRegistry()) {
        std::cout << a.name << " — " << a.summary << "\n  lights:";
        for (LightType t : a.lights) std::cout << " " << toString(t);
        std::cout << "\n  moving geometry: " << toString(a.motion)
                  << (a.rebuildParam.empty() ? "" : " (allowed with " + a.rebuildParam + " = true)") << "\n";
        for (const auto& s : a.schema().specs()) {
            std::cout << "  " << s.key << " (" << toString(s.type) << ", default " << toString(s.def);
            if (s.type == ParamType::Int || s.type == ParamType::Float) std::cout << ", range [" << s.min << ", " << s.max << "]";
            if (s.type == ParamType::Enum) {
                std::cout << ", one of";
                for (const auto& c : s.choices) std::cout << " " << c;
            }
            if (!s.unit.empty()) std::cout << ", " << s.unit;
            std::cout << ", " << toString(s.change) << ")\n      " << s.doc << "\n";
        }
    }
}

/// The parameter tables of the docs: one algorithm's, or each one's under a heading.
int printMarkdown(const std::string& name) {
    if (!name.empty()) {
        const AlgorithmInfo* a = findAlgorithm(name);
        if (!a) throw InputError("list", "", "unknown algorithm \"" + shortText(name, 60) + "\"");
        std::cout << a->schema().markdownTable();
        return 0;
    }
    for (const auto& a : algorithmRegistry()) std::cout << "## " << a.name << "\n\n" << a.schema().markdownTable() << "\n";
    return 0;
}

/// `msg` echoes what was typed: it is cut to one short line.
[[noreturn]] void usageError(const std::string& msg) {
    std::fprintf(stderr, "shadowlab: %s (see shadowlab --help)\n", shortText(msg, 300).c_str());
    std::exit(2);
}

/// A --set PATH=VALUE whose PATH the override walker could misread (an index past what it can
/// count) is refused here, as bad input, before it gets there.
void checkOverride(const std::string& assignment) {
    const std::string path = assignment.substr(0, assignment.find('='));
    if (const std::string why = dottedPathProblem(path); !why.empty() && !path.empty() && assignment.find('=') != std::string::npos)
        usageError("--set " + shortText(path, 80) + ": the path " + why);
}

/// Adds a checked --set; the same path twice is a usage error, as a key twice in a config file is
/// (which value was meant?), never the last one silently.
void addOverride(std::vector<std::string>& overrides, const std::string& assignment) {
    checkOverride(assignment);
    const std::string path = assignment.substr(0, assignment.find('='));
    for (const std::string& o : overrides)
        if (o.substr(0, o.find('=')) == path) usageError("--set " + shortText(path, 80) + " is given twice");
    overrides.push_back(assignment);
}

/// What run and validate check before the first frame, in this order (GL context current): the
/// memory plan of the predicted scene, before it is made; the scene, made into `cfg` (loaded without
/// it); each algorithm's fit on it. What validate accepts, run runs.
MemoryPlan planAndLoadScene(ExperimentConfig& cfg, const std::string& config, const std::vector<std::string>& overrides) {
    const ScenePrediction predicted = predictConfigScene(config, overrides);
    MemoryPlan plan = checkMemoryPlan(cfg, predicted, currentDeviceLimits(predicted.triangles));
    cfg = loadConfig(config, true, overrides);
    checkAlgorithmsTakeScene(cfg);
    return plan;
}

/// The config's expectations on stderr, one line each failed (all of them count as one line per
/// record), and the run's exit code: kExpectationsFailedExit when one failed, else 0.
int reportExpectations(const Json& meta) {
    if (!meta.contains("expectations")) return 0;
    const Json& records = meta["expectations"];
    size_t failed = 0;
    for (const Json& r : records)
        if (!r.value("passed", false)) {
            ++failed;
            std::fprintf(stderr, "shadowlab: expectation FAILED: %s\n", shortText(expectationLine(r), 600).c_str());
        }
    if (failed == 0) {
        std::fprintf(stderr, "shadowlab: expectations: all %zu met\n", records.size());
        return 0;
    }
    std::fprintf(stderr, "shadowlab: expectations: %zu of %zu failed (exit %d; every result was written)\n", failed, records.size(),
                 kExpectationsFailedExit);
    return kExpectationsFailedExit;
}

/// --force replaces DIR with everything in it: a run whose own config or scene files lie inside
/// it would delete them (sixth probe: config.resolved.json then named a glTF file that was gone).
void refuseInputsInsideReplacedOutput(const std::string& config, const std::vector<std::string>& overrides, const std::string& dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_directory(fs::symlink_status(dir, ec))) return;
    Json j = JsonNode::parseFile(config);
    for (const auto& o : overrides) applyOverride(j, o);
    // Each glTF file with the buffer files it names (eleventh probe: a buffer inside DIR was deleted).
    OutputPlace::refuseInputsInside(dir, configInputFiles(j, config), "this run");
}

int run(const std::vector<std::string>& args) {
    std::string config;
    std::vector<std::string> overrides;
    RunOptions opt;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (isHelp(a)) return commandUsage(kRunUsage);
        if (a == "--out") {
            if (++i >= args.size()) usageError("--out needs a directory");
            if (!opt.outputDir.empty()) usageError("--out is given twice (one output folder a run)");
            if (args[i].empty()) usageError("--out must not be empty (leave it out for the config's output.dir)");
            // `--out --force` (the folder forgotten) would make a folder named "--force".
            if (args[i].starts_with("--")) usageError("--out needs a directory, not the option " + args[i] + " (a folder named so: ./" + args[i] + ")");
            // The folder's name reaches summary.json and the report, which hold UTF-8 text only.
            if (const std::string why = pathTextProblem(args[i]); !why.empty()) usageError("--out: the folder's name " + why);
            opt.outputDir = args[i];
        } else if (a == "--force") {
            if (opt.force) usageError("--force is given twice");
            opt.force = true;
        } else if (a == "--no-progress") {
            if (!opt.progress) usageError("--no-progress is given twice");
            opt.progress = false;
        } else if (a == "--set") {
            if (++i >= args.size()) usageError("--set needs PATH=VALUE");
            addOverride(overrides, args[i]);
        } else if (!a.empty() && a[0] == '-') {
            usageError("unknown option " + a);
        } else if (config.empty()) {
            config = a;
        } else {
            usageError("unexpected argument " + a);
        }
    }
    if (config.empty()) usageError("run needs a config file");
    installInterruptHandlers();
    // The output place is checked and locked before the scene is loaded and anything rendered, so a
    // run that could not save its results fails at once instead of after the work.
    ExperimentConfig cfg = loadConfig(config, false, overrides);
    if (opt.outputDir.empty() && !cfg.defaultOutputProblem.empty()) throw InputError(config, "/name", cfg.defaultOutputProblem);
    std::vector<std::string> notes;
    // A place from the config is named as validate names it: the config and /output/dir.
    OutputPlace place = [&] {
        try {
            const std::string dir = opt.outputDir.empty() ? cfg.outputDir : opt.outputDir;
            if (opt.force) refuseInputsInsideReplacedOutput(config, overrides, dir);
            // A compare or history output is not a run's to replace (thirteenth probe).
            if (opt.force) OutputPlace::refuseOtherKind(dir, "summary.json", "run");
            return OutputPlace::open(dir, opt.force, &notes,
                                     overrides.empty() ? config : std::string());
        } catch (const InputError& e) {
            if (!opt.outputDir.empty()) throw;
            throw InputError(config, "/output/dir", e.cause());
        }
    }();
    for (const auto& n : notes) std::fprintf(stderr, "shadowlab: %s\n", shortText(n, 600).c_str());
    opt.place = &place;
    // The context first: the memory plan needs the device's limits, and is checked before the
    // scene is made, so a run that cannot fit stops here (exit 2) instead of in the OOM killer.
    auto context = createHeadlessContext(false);
    installGlDebugCallback(true);
    // Refused before anything is said about the run, so a refused run prints its one error line only.
    const MemoryPlan plan = planAndLoadScene(cfg, config, overrides);
    opt.memoryPlan = plan.toJson();
    throwIfInterrupted();
    std::fprintf(stderr, "shadowlab: memory: %s\n", plan.summary().c_str());
    // The name is the config's text: cut, so a huge or multi-line one stays one short line.
    std::fprintf(stderr, "shadowlab: %s, %zu triangles, %d×%d, %d frames on %s (%s)\n", shortText(cfg.name, 100).c_str(),
                 cfg.scene->triangleCount(), cfg.resolution.x, cfg.resolution.y, cfg.frames, glRendererString().c_str(),
                 context->backend().c_str());
    ExperimentResults r = runExperiment(cfg, opt, context->backend());
    const std::string& dir = place.finalDir();
    std::fprintf(stderr, "shadowlab: wrote %s (report.md, summary.json) in %.1f s\n", shortText(dir, 300).c_str(),
                 r.meta["wall_time_s"].get<double>());
    std::fputs(summaryTable(r.summary()).c_str(), stdout);
    if (glErrorCount() > 0) {
        std::fprintf(stderr, "shadowlab: %d OpenGL errors were reported during the run\n", glErrorCount());
        return 1;
    }
    return reportExpectations(r.meta);
}

/// `shadowlab plan CONFIG [--set PATH=VALUE] [--triangles N]`: the memory plan of a run and each
/// algorithm's estimate or refusal on this device, for the config's scene or for N triangles,
/// without making the scene. Exit 0 when the run would start, 2 (with the run's error) when not.
int plan(const std::vector<std::string>& args) {
    std::string config;
    std::vector<std::string> overrides;
    size_t triangles = 0;
    for (size_t i = 1; i < args.size(); ++i) {
        if (isHelp(args[i])) return commandUsage(kPlanUsage);
        if (args[i] == "--set") {
            if (++i >= args.size()) usageError("--set needs PATH=VALUE");
            addOverride(overrides, args[i]);
        } else if (args[i] == "--triangles") {
            if (++i >= args.size()) usageError("--triangles needs a count");
            if (triangles > 0) usageError("--triangles is given twice");
            // No scene may hold more (max_triangles' ceiling), so no plan is asked past it.
            triangles = parseCount(args[i], "--triangles", 1, kMaxSceneTriangles);
        } else if (config.empty() && !args[i].empty() && args[i][0] != '-') {
            config = args[i];
        } else {
            usageError("plan takes one config file, --set PATH=VALUE and --triangles N");
        }
    }
    if (config.empty()) usageError("plan needs a config file");
    ExperimentConfig cfg = loadConfig(config, false, overrides);
    auto context = createHeadlessContext(false);
    installGlDebugCallback(true);
    ScenePrediction predicted = predictConfigScene(config, overrides);
    if (triangles > 0) {
        // The config's scene scaled to N triangles: its moving share is unknown, so all of it moves.
        predicted.triangles = triangles;
        if (predicted.moving) predicted.movingTriangles = triangles;
    }
    const DeviceLimits limits = currentDeviceLimits(predicted.triangles);
    std::printf("scene: up to %zu triangles%s; storage block %zu MiB (reported %zu), buffer-texture view %zu texels\n",
                predicted.triangles, predicted.moving ? ", moving" : "", limits.storageBlockBytes >> 20,
                limits.reportedStorageBlockBytes >> 20, limits.textureBufferTexels);
    for (const std::string& line : describeFootprints(cfg, predicted.triangles, predicted.moving, limits))
        std::printf("%s\n", line.c_str());
    const MemoryPlan p = checkMemoryPlan(cfg, predicted, limits);
    std::printf("plan: %s\n", p.summary().c_str());
    return 0;
}

/// `shadowlab validate CONFIG [--set PATH=VALUE]`: every check `run` makes before its first frame,
/// in the same order (the output place, the memory plan before the scene is made, the scene, each
/// algorithm's fit on it), then the resolved config on standard output. What validate accepts, run runs.
int validate(const std::string& config, const std::vector<std::string>& overrides) {
    ExperimentConfig cfg = loadConfig(config, false, overrides);
    // The output place too (run --out may name another).
    // An existing one must be one `run --force` can replace (seventh probe: a user's folder, a sweep
    // and the config's own folder were "valid", and every run refused them).
    if (!cfg.defaultOutputProblem.empty()) throw InputError(config, "/name", cfg.defaultOutputProblem);
    try {
        OutputPlace::check(cfg.outputDir, overrides.empty() ? config : std::string());
        OutputPlace::checkReplaceable(cfg.outputDir);
        OutputPlace::refuseOtherKind(cfg.outputDir, "summary.json", "run");
        refuseInputsInsideReplacedOutput(config, overrides, cfg.outputDir);
    } catch (const InputError& e) {
        throw InputError(config, "/output/dir", e.cause());
    }
    auto context = createHeadlessContext(false);
    installGlDebugCallback(true);
    planAndLoadScene(cfg, config, overrides);
    std::cout << cfg.resolved.dump(2) << "\n";
    std::fprintf(stderr, "%s: valid (%zu triangles, %zu algorithms%s)\n", shortText(config, 300).c_str(), cfg.scene->triangleCount(),
                 cfg.algorithms.size(), cfg.reference ? " + reference" : "");
    return 0;
}

/// `shadowlab info`: the device and what each algorithm's auto parameters resolve to on it. Exit 1
/// when an algorithm cannot be created here or GL reported an error.
int info(const std::vector<std::string>& args) {
    bool json = false;
    if (std::any_of(args.begin() + 1, args.end(), isHelp)) return commandUsage(kInfoUsage);
    for (size_t i = 1; i < args.size(); ++i) {
        if (args[i] == "--json" && json) usageError("--json is given twice");
        else if (args[i] == "--json") json = true;
        else if (!args[i].empty() && args[i][0] == '-') usageError("unknown option " + args[i] + " (info takes only --json)");
        else usageError("unexpected argument " + args[i] + " (info takes only --json)");
    }
    auto context = createHeadlessContext(false);
    installGlDebugCallback(true);
    const Json device = deviceRecord(context->backend());
    const std::vector<ResolvedDefaults> algorithms = resolveDefaults();
    if (json) std::cout << deviceInfoJson(device, algorithms).dump(2) << "\n";
    else std::cout << deviceInfoText(device, algorithms);
    bool failed = glErrorCount() > 0;
    for (const auto& a : algorithms)
        if (!a.error.empty()) {
            std::fprintf(stderr, "shadowlab: %s cannot be created here: %s\n", a.algorithm.c_str(), shortText(a.error, 600).c_str());
            failed = true;
        }
    if (glErrorCount() > 0) std::fprintf(stderr, "shadowlab: %d OpenGL errors were reported\n", glErrorCount());
    return failed ? 1 : 0;
}

} // namespace

static int dispatch(std::vector<std::string> args);

int main(int argc, char** argv) {
    reopenClosedStandardStreams();
    // A write to a pipe whose reader is gone then fails with EPIPE, which checkStandardOutput()
    // reports in one line (exit 2), instead of SIGPIPE ending the process without a word (seventh
    // probe). Children get the default back (SweepProcess, runChildProcess).
    std::signal(SIGPIPE, SIG_IGN);
    return checkStandardOutput("shadowlab", dispatch(std::vector<std::string>(argv + 1, argv + argc)));
}

static int dispatch(std::vector<std::string> args) {
    try {
        if (args.empty() || isHelp(args[0]) || args[0] == "help") {
            std::fputs(fullUsage().c_str(), args.empty() ? stderr : stdout);
            return args.empty() ? 2 : 0;
        }
        if (args[0] == "--version") {
            // Eighteenth probe: `--version --bogus` printed the version; every command refuses what it does not take.
            if (args.size() > 1) usageError("--version takes no arguments, got \"" + shortText(args[1], 60) + "\"");
            std::puts("shadowlab 0.1");
            return 0;
        }
        if (args[0] == "list") {
            if (std::any_of(args.begin() + 1, args.end(), isHelp)) return commandUsage(kListUsage);
            if (args.size() > 1 && args[1] == "--markdown") {
                if (args.size() > 3) usageError("list --markdown takes at most one algorithm name");
                // An empty name is no algorithm's (fourteenth probe: it printed every table).
                if (args.size() == 3 && args[2].empty()) throw InputError("list", "", "--markdown NAME: the name is empty");
                return printMarkdown(args.size() == 3 ? args[2] : "");
            }
            bool json = args.size() > 1 && args[1] == "--json";
            if (args.size() > (json ? 2u : 1u)) usageError("list takes only --json or --markdown [NAME]");
            printList(json);
            return 0;
        }
        if (args[0] == "validate") {
            std::string config;
            std::vector<std::string> overrides;
            for (size_t i = 1; i < args.size(); ++i) {
                if (isHelp(args[i])) return commandUsage(kValidateUsage);
                if (args[i] == "--set") {
                    if (++i >= args.size()) usageError("--set needs PATH=VALUE");
                    addOverride(overrides, args[i]);
                } else if (config.empty() && !args[i].empty() && args[i][0] != '-') {
                    config = args[i];
                } else {
                    usageError("validate takes one config file and --set PATH=VALUE");
                }
            }
            if (config.empty()) usageError("validate needs a config file");
            return validate(config, overrides);
        }
        if (args[0] == "plan") return plan(args);
        if (args[0] == "run") return run(args);
        if (args[0] == "info") return info(args);
        if (args[0] == "sweep") return sweepCommand(args);
        if (args[0] == "compare") return compareCommand(args);
        if (args[0] == "history") return historyCommand(args);
        usageError("unknown command " + args[0]);
    } catch (const InputError& e) {
        std::fprintf(stderr, "shadowlab: error: %s\n", shortText(e.what(), 1000).c_str());
        return 2;
    } catch (const Interrupted& e) {
        std::fprintf(stderr, "shadowlab: %s; no results written, any previous ones kept\n", e.what());
        return 128 + e.signal();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "shadowlab: failed: %s\n", shortText(e.what(), 1000).c_str());
        return 1;
    }
}
