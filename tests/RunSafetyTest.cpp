// `shadowlab run` under interruption and contention, as a user meets them: Ctrl-C or SIGTERM while
// rendering or while plotting, two runs aimed at one output, and an experiment in which no pixel
// is lit. Results are never lost or left half-written, and a vacuous 0 % mismatch is never reported.
#include "framework/core/JsonNode.h"
#include "tests/HostileInputs.h"
#include "tests/SweepTestData.h"
#include "tests/TestSupport.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::string slurp(const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Starts `shadowlab run CONFIG --out OUT [extra]` in the background with stderr to LOG.
pid_t startRun(const std::string& config, const std::string& out, const std::string& log,
               std::vector<std::string> extra = {}, const std::string& python = "") {
    pid_t pid = fork();
    if (pid == 0) {
        if (!python.empty()) setenv("SHADOWLAB_PYTHON", python.c_str(), 1);
        freopen(log.c_str(), "w", stderr);
        freopen("/dev/null", "w", stdout);
        std::vector<std::string> args = {SHADOWLAB_BINARY, "run", config, "--out", out, "--no-progress"};
        args.insert(args.end(), extra.begin(), extra.end());
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        execv(argv[0], argv.data());
        _exit(127);
    }
    return pid;
}

/// The exit code, or 1000 + signal; fails the test if it does not end within `limit`.
int waitExit(pid_t pid, std::chrono::seconds limit) {
    auto until = std::chrono::steady_clock::now() + limit;
    int status = 0;
    while (waitpid(pid, &status, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() > until) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            ADD_FAILURE() << "the run did not stop within " << limit.count() << " s";
            return -1;
        }
        std::this_thread::sleep_for(20ms);
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

bool waitFor(const std::function<bool()>& cond, std::chrono::seconds limit = 120s) {
    auto until = std::chrono::steady_clock::now() + limit;
    while (!cond()) {
        if (std::chrono::steady_clock::now() > until) return false;
        std::this_thread::sleep_for(20ms);
    }
    return true;
}

bool hasPartial(const std::string& base) {
    for (const auto& e : fs::directory_iterator(base))
        if (e.path().filename().string().find(".partial-") != std::string::npos) return true;
    return false;
}

/// A config of `frames` frames at 32² (shadow_map + reference), and a finished output of it in OUT.
struct Fixture {
    std::string base, config, out, previous;
    Fixture(const std::string& tag, int frames, bool plots = false) {
        base = test::makeTempDir(tag);
        config = base + "/c.json";
        out = base + "/out";
        std::ofstream(config) << test::configWith({{"resolution", "[32, 32]"}, {"frames", std::to_string(frames)},
                                                   {"output", std::string(R"({"plots": )") + (plots ? "true" : "false") + "}"}});
        std::string log;
        EXPECT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + config + " --out " + out +
                                       " --no-progress --set frames=1 --set output.plots=false", log), 0) << log;
        previous = slurp(out + "/summary.json");
        EXPECT_FALSE(previous.empty());
    }
    void expectPreviousKept() const {
        EXPECT_EQ(slurp(out + "/summary.json"), previous);
        EXPECT_FALSE(hasPartial(base));
        EXPECT_FALSE(fs::exists(out + ".lock"));
    }
};

TEST(RunSafetyTest, CtrlCWhileRenderingStopsAndKeepsThePreviousResults) {
    Fixture f("interrupt-render", 100000);
    pid_t pid = startRun(f.config, f.out, f.base + "/log", {"--force"});
    ASSERT_TRUE(waitFor([&] { return hasPartial(f.base); })) << slurp(f.base + "/log");
    std::this_thread::sleep_for(300ms);  // inside the frame loop
    kill(pid, SIGINT);
    EXPECT_EQ(waitExit(pid, 60s), 128 + SIGINT) << slurp(f.base + "/log");
    EXPECT_NE(slurp(f.base + "/log").find("interrupted by SIGINT"), std::string::npos);
    f.expectPreviousKept();
}

// Fifth probe: SIGHUP (a closed terminal, a dropped ssh session) killed the run outright. It stops
// as Ctrl-C does; where it was ignored when the run started (nohup), it stays ignored.
TEST(RunSafetyTest, SighupStopsTheRunUnlessItWasIgnoredAtTheStart) {
    Fixture f("interrupt-hup", 100000);
    pid_t pid = startRun(f.config, f.out, f.base + "/log", {"--force"});
    ASSERT_TRUE(waitFor([&] { return hasPartial(f.base); })) << slurp(f.base + "/log");
    kill(pid, SIGHUP);
    EXPECT_EQ(waitExit(pid, 60s), 128 + SIGHUP) << slurp(f.base + "/log");
    EXPECT_NE(slurp(f.base + "/log").find("interrupted by SIGHUP"), std::string::npos);
    f.expectPreviousKept();
    // As nohup starts it: SIGHUP ignored, inherited through exec.
    std::signal(SIGHUP, SIG_IGN);
    pid = startRun(f.config, f.out, f.base + "/log", {"--force"});
    std::signal(SIGHUP, SIG_DFL);
    ASSERT_TRUE(waitFor([&] { return hasPartial(f.base); })) << slurp(f.base + "/log");
    kill(pid, SIGHUP);
    std::this_thread::sleep_for(500ms);
    EXPECT_EQ(waitpid(pid, nullptr, WNOHANG), 0) << "the run stopped on an ignored SIGHUP";
    kill(pid, SIGINT);
    EXPECT_EQ(waitExit(pid, 60s), 128 + SIGINT) << slurp(f.base + "/log");
    f.expectPreviousKept();
}

// Sixth probe: the output removed mid-run and a folder of the user's made in its place got the
// same inode number, and the commit replaced it (mine.txt lost, exit 0). Emptied and refilled in
// place, the same. Both are kept now, the run's results beside them in DIR.kept-PID, exit 1.
TEST(RunSafetyTest, AFolderPutInPlaceOfTheOutputMidRunIsKept) {
    for (bool sameDirectory : {false, true}) {
        SCOPED_TRACE(sameDirectory ? "emptied and refilled" : "removed and made again");
        Fixture f(sameDirectory ? "swap-refill" : "swap-remake", 40);
        pid_t pid = startRun(f.config, f.out, f.base + "/log", {"--force"});
        ASSERT_TRUE(waitFor([&] { return hasPartial(f.base); })) << slurp(f.base + "/log");
        if (sameDirectory) {
            for (const auto& e : fs::directory_iterator(f.out)) fs::remove_all(e.path());
        } else {
            fs::remove_all(f.out);
            fs::create_directory(f.out);
        }
        std::ofstream(f.out + "/mine.txt") << "user data\n";
        EXPECT_EQ(waitExit(pid, 120s), 1) << slurp(f.base + "/log");
        EXPECT_EQ(slurp(f.out + "/mine.txt"), "user data\n");
        bool kept = false;
        for (const auto& e : fs::directory_iterator(f.base)) kept = kept || e.path().filename().string().starts_with("out.kept-");
        EXPECT_TRUE(kept) << slurp(f.base + "/log");
    }
}

// Sixth probe: a config kept inside the output it names, run with --force, was deleted with the
// old results (its glTF too). Refused now, exit 2, everything kept.
TEST(RunSafetyTest, ForceNeverReplacesAFolderTheRunReadsItsInputsFrom) {
    Fixture f("inputs-inside", 1);
    const std::string config = f.out + "/my.json";
    std::ofstream(config) << test::configWith({{"output", R"({"dir": ".", "plots": false})"}});
    std::string log;
    EXPECT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + config + " --force --no-progress", log), 2) << log;
    EXPECT_NE(log.find("this run reads"), std::string::npos) << log;
    EXPECT_TRUE(fs::exists(config));
    f.expectPreviousKept();
}

// Eleventh probe: a glTF file beside the config whose buffer file lay inside the output was fine
// for the check (it looked at the .gltf only), and --force deleted the buffer with the old results.
TEST(RunSafetyTest, ForceNeverReplacesAFolderHoldingAGltfsBufferFile) {
    Fixture f("buffer-inside", 1);
    const float pos[9] = {-1, 0.5f, -1, -1, 0.5f, 1, 1, 0.5f, -1};
    std::ofstream(f.out + "/tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(pos), sizeof pos);
    std::ofstream(f.base + "/tri.gltf") << test::triangleGltf(
        {{"buffers", R"([{"byteLength": 36, "uri": "out/tri.bin"}])"},
         {"accessors", R"([{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3, "min": [-1, 0.5, -1], "max": [1, 0.5, 1]}])"}});
    std::ofstream(f.config) << test::configWith({{"resolution", "[32, 32]"}, {"frames", "1"},
                                                 {"scene", R"({"objects": [{"procedural": "plane", "size": [4, 4]}, {"gltf": "tri.gltf"}]})"},
                                                 {"output", R"({"plots": false})"}});
    std::string log;
    EXPECT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + f.config + " --out " + f.out + " --force --no-progress", log), 2)
        << log;
    EXPECT_NE(log.find("this run reads"), std::string::npos) << log;
    EXPECT_NE(log.find("tri.bin"), std::string::npos) << log;
    EXPECT_TRUE(fs::exists(f.out + "/tri.bin"));
    f.expectPreviousKept();
    // Thirteenth probe: the same buffer named percent-encoded (out%2Ftri.bin), as the reader decodes it.
    std::ofstream(f.base + "/tri.gltf", std::ios::trunc) << test::triangleGltf(
        {{"buffers", R"([{"byteLength": 36, "uri": "out%2Ftri.bin"}])"},
         {"accessors", R"([{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3, "min": [-1, 0.5, -1], "max": [1, 0.5, 1]}])"}});
    EXPECT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + f.config + " --out " + f.out + " --force --no-progress", log), 2)
        << log;
    EXPECT_NE(log.find("tri.bin"), std::string::npos) << log;
    EXPECT_TRUE(fs::exists(f.out + "/tri.bin"));
    f.expectPreviousKept();
}

// Thirteenth probe: run --force replaced a compare or history output with a run, and deleted the
// user's files in a run's output whose mark was gone (copied without its dot files). Each refused.
TEST(RunSafetyTest, ForceReplacesOnlyAMarkedRunOutput) {
    Fixture f("force-kind", 1);
    const std::string bin = SHADOWLAB_BINARY, cmp = f.base + "/cmp";
    std::string log;
    ASSERT_EQ(test::runCommand(bin + " compare " + f.out + " " + f.out + " --out " + cmp, log), 0) << log;
    EXPECT_EQ(test::runCommand(bin + " run " + f.config + " --out " + cmp + " --force --no-progress", log), 2) << log;
    EXPECT_NE(log.find("another command's output (compare's"), std::string::npos) << log;
    EXPECT_TRUE(fs::exists(cmp + "/compare.md"));
    EXPECT_EQ(test::runCommand(bin + " validate " + f.config + " --set output.dir=" + cmp + " >/dev/null", log), 2) << log;
    fs::remove(f.out + "/.shadowlab-output");
    std::ofstream(f.out + "/notes.txt") << "mine\n";
    EXPECT_EQ(test::runCommand(bin + " run " + f.config + " --out " + f.out + " --force --no-progress", log), 2) << log;
    EXPECT_NE(log.find("not a shadowlab output"), std::string::npos) << log;
    EXPECT_EQ(slurp(f.out + "/notes.txt"), "mine\n");
}

// Sixth probe: validate accepted an output.dir run could not make (/proc/x); a plotter that exits
// 0 without writing anything (SHADOWLAB_PYTHON=/bin/true) left a run without report.html, unsaid.
TEST(RunSafetyTest, ValidateTriesTheOutputPlaceAndASilentPlotterIsNamed) {
    const std::string base = test::makeTempDir("place-and-plotter");
    std::ofstream(base + "/c.json") << test::configWith({{"output", R"({"dir": "/proc/shadowlab-x", "plots": true})"}});
    std::string log;
    EXPECT_EQ(test::runCommand("(" + std::string(SHADOWLAB_BINARY) + " validate " + base + "/c.json >/dev/null)", log), 2) << log;
    EXPECT_NE(log.find("at /output/dir: cannot create folders in /proc"), std::string::npos) << log;
    EXPECT_EQ(test::runCommand("(SHADOWLAB_PYTHON=/bin/true " + std::string(SHADOWLAB_BINARY) + " run " + base + "/c.json --no-progress --out " +
                                   base + "/out --set output.dir=out >/dev/null)",
                               log),
              0)
        << log;
    EXPECT_NE(log.find("wrote no report.html"), std::string::npos) << log;
}

// Seventh probe: a disk that filled while plotting left a run without report.html or plots, and
// the run exited 0 with a warning naming a plots.log that was never written. A full disk is a
// failed write: exit 1, and the results already there stay. The disk: a 150 KiB tmpfs in a mount
// namespace of its own (unshare), which the tables fit and the plots do not.
TEST(RunSafetyTest, ADiskThatFillsWhilePlottingFailsTheRunAndKeepsThePreviousResults) {
    const std::string base = test::makeTempDir("full-disk");
    std::ofstream(base + "/c.json") << test::configWith({{"resolution", "[32, 32]"}, {"frames", "1"}, {"warmup_frames", "0"}});
    const std::string tiny = base + "/tiny", out = tiny + "/r";
    fs::create_directories(tiny);
    const std::string run = std::string(SHADOWLAB_BINARY) + " run " + base + "/c.json --no-progress --out " + out;
    // First a run on the tmpfs with plots off (it fits), then one with plots over it.
    const std::string script = "mount -t tmpfs -o size=150k tmpfs " + tiny + " || exit 99; " + run +
                               " --set output.plots=false >/dev/null 2>&1 || exit 98; " + run + " --set output.plots=true --force; echo rc=$?; ls " + out;
    std::string log;
    const int rc = test::runCommand("unshare -rm sh -c '" + script + "' 2>&1", log);
    // Where the machine lends no mount namespace (unshare refused, or mount in it), there is no small
    // disk to fill: nothing to test here (runCommand returns the exit status, 99 for the mount).
    if (rc == 99 || log.find("unshare:") == 0) GTEST_SKIP() << "no mount namespace here: " << log;
    ASSERT_NE(rc, 98) << "the first run, without plots, failed: " << log;
    EXPECT_NE(log.find("rc=1"), std::string::npos) << log;
    EXPECT_NE(log.find("is full: the plots and report.html could not be written"), std::string::npos) << log;
    EXPECT_NE(log.find("summary.json"), std::string::npos) << "the first run's results are gone: " << log;
    EXPECT_EQ(log.find("plots.log"), std::string::npos) << log;
}

// Seventh probe: validate accepted an output.dir that run refuses with and without --force: a
// user's folder, a sweep, the folder holding the config. Each is now refused by validate too.
TEST(RunSafetyTest, ValidateRefusesAnOutputNoRunCouldReplace) {
    const std::string base = test::makeTempDir("validate-places");
    fs::create_directories(base + "/notes");
    std::ofstream(base + "/notes/todo.txt") << "mine\n";
    fs::create_directories(base + "/sweep");
    std::ofstream(base + "/sweep/sweep.json") << "{}\n";
    fs::create_directories(base + "/inside");
    std::ofstream(base + "/inside/c.json") << test::configWith({{"output", "{\"dir\": \"" + base + "/inside\"}"}});
    std::ofstream(base + "/c.json") << test::configWith({});
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{base + "/c.json", "--set", "output.dir=" + base + "/notes"}, "not a shadowlab output"},
        {{base + "/c.json", "--set", "output.dir=" + base + "/sweep"}, "is a sweep"},
        {{base + "/inside/c.json"}, "not a shadowlab output"}};
    for (const auto& [args, cause] : cases) {
        std::vector<std::string> argv{SHADOWLAB_BINARY, "validate"};
        argv.insert(argv.end(), args.begin(), args.end());
        const test::Ran ran = test::runArgs(argv);
        EXPECT_EQ(ran.rc, 2) << ran.err;
        EXPECT_NE(ran.err.find("at /output/dir: "), std::string::npos) << ran.err;
        EXPECT_NE(ran.err.find(cause), std::string::npos) << ran.err;
    }
    EXPECT_TRUE(fs::exists(base + "/notes/todo.txt"));
}

TEST(RunSafetyTest, SigtermWhilePlottingStopsThePlotterAndKeepsThePreviousResults) {
    Fixture f("interrupt-plot", 2, true);
    // A plotter that announces itself and then takes far longer than any real plot.
    std::string plotter = f.base + "/slow_plotter.sh", marker = f.base + "/plotting";
    std::ofstream(plotter) << "#!/bin/sh\necho $$ > " << marker << ".tmp; mv " << marker << ".tmp " << marker << "\nexec sleep 300\n";
    fs::permissions(plotter, fs::perms::owner_all);
    pid_t pid = startRun(f.config, f.out, f.base + "/log", {"--force"}, plotter);
    ASSERT_TRUE(waitFor([&] { return fs::exists(marker); })) << slurp(f.base + "/log");
    pid_t plotterPid = std::stoi(slurp(marker));
    kill(pid, SIGTERM);
    EXPECT_EQ(waitExit(pid, 30s), 128 + SIGTERM) << slurp(f.base + "/log");
    f.expectPreviousKept();
    EXPECT_NE(kill(plotterPid, 0), 0) << "the plotter still runs";
}

TEST(RunSafetyTest, ASecondRunIntoTheSameOutputIsRefusedWhileTheFirstRuns) {
    Fixture f("concurrent", 100000);
    pid_t first = startRun(f.config, f.out, f.base + "/log", {"--force"});
    ASSERT_TRUE(waitFor([&] { return hasPartial(f.base); })) << slurp(f.base + "/log");
    std::string log;
    EXPECT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + f.config + " --out " + f.out + " --force", log), 2);
    EXPECT_NE(log.find("in use by another shadowlab run"), std::string::npos) << log;
    kill(first, SIGINT);
    EXPECT_EQ(waitExit(first, 60s), 128 + SIGINT);
    f.expectPreviousKept();
    // Without --force, a run into a finished output is refused before it starts, also run after run.
    EXPECT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + f.config + " --out " + f.out, log), 2);
    EXPECT_NE(log.find("already exists"), std::string::npos) << log;
    f.expectPreviousKept();
}

TEST(RunSafetyTest, FramesWithoutLitPixelsAreFlaggedNotScoredZero) {
    std::string base = test::makeTempDir("no-lit");
    // A spot light aimed away from everything the camera sees.
    std::ofstream(base + "/c.json") << test::configWith(
        {{"light", R"({"type": "spot", "position": [0, 4, 0], "target": [0, 10, 0], "cone_deg": 10})"}});
    std::string log;
    ASSERT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + base + "/c.json --out " + base + "/out --no-progress", log), 0)
        << log;
    EXPECT_NE(log.find("warning: 2 of 2 frames have no lit pixel"), std::string::npos) << log;
    Json summary = Json::parse(slurp(base + "/out/summary.json"));
    EXPECT_EQ(summary["frames_without_lit_pixels"], Json::array({0, 1}));
    EXPECT_EQ(summary["warnings"].size(), 1u);
    EXPECT_TRUE(summary["algorithms"]["shadow_map"]["accuracy"].is_null());
    EXPECT_NE(slurp(base + "/out/report.md").find("**warning**"), std::string::npos);
}

// An algorithm that refuses the scene only once it exists (line_space's tree past a storage block)
// is bad input at its entry, exit 2, as validate says; the output folder is not made.
TEST(RunSafetyTest, AnAlgorithmRefusingTheBuiltSceneIsExitTwoAtItsEntryAndWritesNothing) {
    const std::string base = test::makeTempDir("scene-refusal");
    std::ofstream(base + "/c.json") << test::configWith(
        {{"algorithms", R"([{"algorithm": "shadow_map"}, {"algorithm": "line_space", "params": {"n": 8, "d": 4}}])"}});
    for (const std::string& command : {" validate " + base + "/c.json", " run " + base + "/c.json --no-progress --out " + base + "/out"}) {
        std::string log;
        EXPECT_EQ(test::runCommand(std::string("(") + SHADOWLAB_BINARY + command + " >/dev/null)", log), 2) << command << log;
        EXPECT_NE(log.find("c.json: at /algorithms/1: line_space cannot hold this scene"), std::string::npos) << log;
        // One line, as any bad input: the run says nothing about itself before the refusal.
        EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
    }
    EXPECT_FALSE(fs::exists(base + "/out"));
}

// Fourth probe: run named an unusable output.dir from the config by its folder only; validate named
// the config and /output/dir. Both do now.
TEST(RunSafetyTest, AnOutputDirFromTheConfigIsNamedAtItsJsonPath) {
    const std::string base = test::makeTempDir("output-dir-path");
    std::ofstream(base + "/file") << "mine";
    std::ofstream(base + "/c.json") << test::configWith({{"output", R"({"dir": "file", "plots": false})"}});
    for (const char* command : {" validate ", " run "}) {
        std::string log;
        EXPECT_EQ(test::runCommand(std::string("(") + SHADOWLAB_BINARY + command + base + "/c.json >/dev/null)", log), 2) << log;
        EXPECT_NE(log.find("c.json: at /output/dir: the output path exists and is not a directory"), std::string::npos) << log;
    }
    EXPECT_EQ(slurp(base + "/file"), "mine");
}

} // namespace
} // namespace shadowlab
