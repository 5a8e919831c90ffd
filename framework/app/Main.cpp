// shadowlab: the headless command line. One binary per GL back end (OSMesa, EGL) links this file.
#include "framework/algorithm/ShadowAlgorithm.h"
#include "framework/core/Error.h"
#include "framework/core/Interrupt.h"
#include "framework/experiment/Config.h"
#include "framework/experiment/Runner.h"
#include "framework/gl/GlContext.h"
#include "framework/sweep/SweepCli.h"

#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

using namespace shadowlab;

namespace {

const char* kUsage = R"(shadowlab: real-time shadow algorithms side by side, checked against a ray-traced reference.

Usage:
  shadowlab run CONFIG.json [--out DIR] [--force] [--no-progress] [--set PATH=VALUE]...
      Runs the experiment and writes DIR (default: the config's output.dir): config.resolved.json,
      frames.csv, summary.json, report.md, images/ and plots. An existing DIR is kept unless --force;
      it is replaced only once the new run has completed.
      --set overrides one config value before validation, by dotted path (array elements by
      index), VALUE as JSON or a plain string: --set resolution=[128,128] --set frames=3
      --set algorithms.0.params.pcf=0 --set light.type=directional
  shadowlab validate CONFIG.json [--set PATH=VALUE]...
      Checks the config (and loads its scene) without rendering; prints the resolved config.
  shadowlab list [--json | --markdown [NAME]]
      Lists the registered algorithms and their parameters; --markdown prints each parameter table
      as docs/algorithms/NAME.md holds it (scripts/update_param_docs.py rewrites the docs from it).
%s  shadowlab --help | --version

Exit codes: 0 success, 2 bad input (config, scene file, parameter), 1 runtime failure.
)";

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
        if (!a) throw InputError("list", "", "unknown algorithm \"" + name + "\"");
        std::cout << a->schema().markdownTable();
        return 0;
    }
    for (const auto& a : algorithmRegistry()) std::cout << "## " << a.name << "\n\n" << a.schema().markdownTable() << "\n";
    return 0;
}

[[noreturn]] void usageError(const std::string& msg) {
    std::fprintf(stderr, "shadowlab: %s (see shadowlab --help)\n", msg.c_str());
    std::exit(2);
}

int run(const std::vector<std::string>& args) {
    std::string config;
    std::vector<std::string> overrides;
    RunOptions opt;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--out") {
            if (++i >= args.size()) usageError("--out needs a directory");
            opt.outputDir = args[i];
        } else if (a == "--force") {
            opt.force = true;
        } else if (a == "--no-progress") {
            opt.progress = false;
        } else if (a == "--set") {
            if (++i >= args.size()) usageError("--set needs PATH=VALUE");
            overrides.push_back(args[i]);
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
    std::vector<std::string> notes;
    OutputPlace place = OutputPlace::open(opt.outputDir.empty() ? cfg.outputDir : opt.outputDir, opt.force, &notes);
    for (const auto& n : notes) std::fprintf(stderr, "shadowlab: %s\n", n.c_str());
    opt.place = &place;
    cfg = loadConfig(config, true, overrides);
    throwIfInterrupted();
    auto context = createHeadlessContext(false);
    installGlDebugCallback(true);
    std::fprintf(stderr, "shadowlab: %s, %zu triangles, %d×%d, %d frames on %s (%s)\n", cfg.name.c_str(),
                 cfg.scene->triangleCount(), cfg.resolution.x, cfg.resolution.y, cfg.frames, glRendererString().c_str(),
                 context->backend().c_str());
    ExperimentResults r = runExperiment(cfg, opt, context->backend());
    const std::string& dir = place.finalDir();
    std::fprintf(stderr, "shadowlab: wrote %s (report.md, summary.json) in %.1f s\n", dir.c_str(),
                 r.meta["wall_time_s"].get<double>());
    if (glErrorCount() > 0) {
        std::fprintf(stderr, "shadowlab: %d OpenGL errors were reported during the run\n", glErrorCount());
        return 1;
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    try {
        if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
            std::string usage = kUsage;
            usage.replace(usage.find("%s"), 2, kSweepUsage);
            std::fputs(usage.c_str(), args.empty() ? stderr : stdout);
            return args.empty() ? 2 : 0;
        }
        if (args[0] == "--version") {
            std::puts("shadowlab 0.1");
            return 0;
        }
        if (args[0] == "list") {
            if (args.size() > 1 && args[1] == "--markdown") {
                if (args.size() > 3) usageError("list --markdown takes at most one algorithm name");
                return printMarkdown(args.size() == 3 ? args[2] : "");
            }
            bool json = args.size() > 1 && args[1] == "--json";
            if (args.size() > (json ? 2u : 1u)) usageError("list takes only --json or --markdown [NAME]");
            printList(json);
            return 0;
        }
        if (args[0] == "validate") {
            std::vector<std::string> overrides;
            for (size_t i = 2; i < args.size(); ++i) {
                if (args[i] != "--set" || ++i >= args.size()) usageError("validate takes one config file and --set PATH=VALUE");
                overrides.push_back(args[i]);
            }
            if (args.size() < 2) usageError("validate needs a config file");
            ExperimentConfig cfg = loadConfig(args[1], true, overrides);
            std::cout << cfg.resolved.dump(2) << "\n";
            std::fprintf(stderr, "%s: valid (%zu triangles, %zu algorithms%s)\n", args[1].c_str(), cfg.scene->triangleCount(),
                         cfg.algorithms.size(), cfg.reference ? " + reference" : "");
            return 0;
        }
        if (args[0] == "run") return run(args);
        if (args[0] == "sweep") return sweepCommand(args);
        usageError("unknown command " + args[0]);
    } catch (const InputError& e) {
        std::fprintf(stderr, "shadowlab: error: %s\n", e.what());
        return 2;
    } catch (const Interrupted& e) {
        std::fprintf(stderr, "shadowlab: %s; no results written, any previous ones kept\n", e.what());
        return 128 + e.signal();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "shadowlab: failed: %s\n", e.what());
        return 1;
    }
}
