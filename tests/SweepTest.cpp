// Sweeps through the command line: validation errors (exit code 2, one line naming the axis and
// the JSON path), stable run ids, running, failing, resuming after a kill, and merging.
#include "framework/core/JsonNode.h"
#include "tests/HostileInputs.h"
#include "tests/SweepTestData.h"
#include "tests/TestSupport.h"

#include <algorithm>
#include <cerrno>
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

std::string bin() { return SHADOWLAB_BINARY; }

size_t countOf(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
    return n;
}

// ---- Validation -----------------------------------------------------------------------------------

struct BadSweep {
    const char* name;
    const char* patch;     ///< JSON merged into the small sweep (merge_patch: null removes a key)
    const char* expected;  ///< substrings of the one-line error, separated by '|'
};

const BadSweep kBadSweeps[] = {
    {"AxisNameNotAnIdentifier", R"({"axes": [{"name": "tri count", "values": {"frames": [1, 2]}}]})", "/axes/0/name|tri count"},
    {"AxisNameTwice", R"({"axes": [{"name": "a", "values": {"frames": [1, 2]}}, {"name": "a", "values": {"resolution": [[8, 8]]}}]})",
     "/axes/1/name|two axes are named \"a\""},
    {"AxisNameIsAColumn", R"({"axes": [{"name": "measure", "values": {"frames": [1, 2]}}]})", "/axes/0/name|column"},
    // Eleventh probe: its plot sweep_stages.png replaced the stages figure.
    {"AxisNameIsTheStagesFigure", R"({"axes": [{"name": "stages", "values": {"frames": [1, 2]}}]})", "/axes/0/name|sweep_stages.png"},
    {"IndexPastTheArray", R"({"axes": [{"name": "pcf", "values": {"algorithms.5.params.pcf": [0, 1]}}]})",
     "axis \"pcf\"|path algorithms.5.params.pcf|no element 5 in an array of 2"},
    {"DescendIntoANumber", R"({"axes": [{"name": "f", "values": {"frames.x": [1, 2]}}]})", "axis \"f\"|path frames.x|cannot descend"},
    {"UnknownParameter", R"({"axes": [{"name": "pcf", "values": {"algorithms.0.params.pfc": [0, 1]}}]})",
     "axis \"pcf\"|path algorithms.0.params.pfc|/algorithms/0/params/pfc"},
    {"ValueOutOfRange", R"({"axes": [{"name": "frames", "values": {"frames": [2, 0]}}]})",
     "axis \"frames\"|path frames = 0|out of range"},
    {"SceneValueOutOfRange", R"({"axes": [{"name": "tris", "values": {"scene.objects.1.triangles": [300, 0]}}]})",
     "axis \"tris\"|path scene.objects.1.triangles = 0|/scene/objects/1/triangles"},
    {"ZipLengthsDiffer", R"({"axes": [{"name": "z", "labels": ["a", "b"], "values": {"frames": [1, 2], "warmup_frames": [0, 1, 2]}}]})",
     "axis \"z\"|path warmup_frames|has 3 values but frames has 2"},
    {"ZipWithoutLabels", R"({"axes": [{"name": "z", "values": {"frames": [1, 2], "warmup_frames": [0, 1]}}]})",
     "/axes/0/labels|required when an axis sets several paths"},
    {"SamePathTwice", R"({"axes": [{"name": "a", "values": {"frames": [1, 2]}}, {"name": "b", "values": {"frames": [3]}}]})",
     "axis \"b\"|path frames|another axis sets this path"},
    {"SameRunTwice", R"({"axes": [{"name": "pcf", "values": {"algorithms.0.params.pcf": [1, 1.0]}, "labels": ["one", "also one"]}]})",
     "/axes|resolve to the same config"},
    {"UnknownTopLevelKey", R"({"axis": []})", "/axis|unknown"},
    // The accepted keys are every key the object takes, not the ones the file happens to give.
    {"UnknownMergeKey", R"({"merge": {"ratio": []}})", "/merge/ratio|accepted keys: counters, paper, ratios, stages"},
    {"UnknownAxisKey", R"({"axes": [{"name": "f", "values": {"frames": [1, 2]}, "label": ["a", "b"]}]})",
     "/axes/0/label|accepted keys: labels, name, scale, values"},
    {"BadBaseOutsideAnyAxis", R"({"base": {"frames": -1}})", "/base/frames|out of range"},
    {"NoBase", R"({"base": null})", "/base|required"},
    {"BadRatio", R"({"merge": {"ratios": ["psv"]}})", "/merge/ratios|not ID/ID"},
    // Fifth probe: an id over itself, or a ratio or stage twice, gave rows of 1 or the same numbers twice.
    {"RatioOfAnIdOverItself", R"({"merge": {"ratios": ["psv/psv"]}})", "/merge/ratios/0|an id over itself"},
    // Seventh probe: no index in the path, and "/" was called an id over itself.
    {"RatioOfEmptyIds", R"({"merge": {"ratios": ["psv/shadow_map", "/"]}})", "/merge/ratios/1|an empty id"},
    // Seventh probe: a base file that cannot be read named neither the sweep file nor /base.
    {"BaseFileMissing", R"({"base": "missing-base.json"})", "/base|the base config|missing-base.json"},
    {"BaseFileIsAFolder", R"({"base": "."})", "/base|the base config"},
    // Probe 26: the base's name was checked after "x\u202e/../base.json" folded to "base.json".
    {"BaseNameWithABidiMarkBeforeDotDot", R"({"base": "x\u202e/../base.json"})", "/base|U+202E"},
    {"BaseNameWithANulBeforeDotDot", R"({"base": "x\u0000/../base.json"})", "/base|control character"},
    // ... and a glTF path an axis gives, folded before the config's check saw it.
    {"AxisGltfPathWithABidiMarkBeforeDotDot",
     R"({"axes": [{"name": "m", "values": {"scene.objects.0": [{"procedural": "plane"}, {"gltf": "d\u202e/../m.gltf"}]}}]})",
     "/axes/0|/scene/objects/0/gltf|U+202E"},
    {"RatioTwice", R"({"merge": {"ratios": ["psv/shadow_map", "psv/shadow_map"]}})", "/merge/ratios/1|given twice"},
    // Probe 26: an axis whose values break a valid base's expectations blamed the base.
    {"AxisValuesBreakAValidBase",
     R"({"base": {"expect": [{"id": "psv", "measure": "overflow", "max": 0}]},
         "axes": [{"name": "al", "values": {"algorithms": [[{"algorithm": "psv"}], [{"algorithm": "shadow_map"}]]}}], "merge": null})",
     "bad.sweep.json: at /axes: run 1 (al=|/expect/0/id"},
    // Probe 26: a ratio of two ids that never meet in one run gave a table of no rows.
    {"RatioOfIdsThatNeverMeet",
     R"({"axes": [{"name": "a", "values": {"algorithms": [[{"algorithm": "psv", "id": "x"}], [{"algorithm": "psv", "id": "y"}]]}}],
         "merge": {"ratios": ["x/y"]}})",
     "/merge/ratios/0|no run holds both"},
    {"StageTwice", R"({"merge": {"stages": ["total", "total"]}})", "/merge/stages/1|given twice"},
    {"PaperTimeNotPositive", R"({"merge": {"paper": {"source": "s", "times_ms": {"psv": 0}}}})", "/merge/paper/times_ms/psv|out of range"},
    {"PaperWithoutSource", R"({"merge": {"paper": {"times_ms": {"psv": 1}}}})", "/merge/paper/source|required"},
    {"PaperWithAnEmptySource", R"({"merge": {"paper": {"source": "", "times_ms": {"psv": 1}}}})", "/merge/paper/source|must name the paper"},
    {"PaperWithoutTimes", R"({"merge": {"paper": {"source": "s"}}})", "/merge/paper/times_ms|expected an object"},
    // Every fixed column of sweep.csv, `kind` included: the report reads rows by column name.
    {"AxisNamedKind", R"({"axes": [{"name": "kind", "values": {"frames": [1, 2]}}]})", "/axes/0/name|column"},
    {"AxisNamedValue", R"({"axes": [{"name": "value", "values": {"frames": [1, 2]}}]})", "/axes/0/name|column"},
    // A "value" axis is plotted at its labels: words there would pass plan and crash the report.
    {"ValueScaleWithWordLabels", R"({"axes": [{"name": "f", "values": {"frames": [1, 2]}, "labels": ["one", "two"], "scale": "value"}]})",
     "/axes/0/scale|positive number|\"one\""},
    {"ValueScaleWithNonNumbers", R"({"axes": [{"name": "l", "values": {"light.type": ["point", "directional"]}, "scale": "value"}]})",
     "/axes/0/scale|positive numbers"},
    // A label is one cell of the plan's TSV and of the tables.
    {"LabelWithNewline", R"({"axes": [{"name": "f", "values": {"frames": [1, 2]}, "labels": ["a\nb", "c"]}]})",
     "/axes/0/labels/0|control character (a newline)"},
    {"LabelWithTab", R"({"axes": [{"name": "f", "values": {"frames": [1, 2]}, "labels": ["a", "b\tc"]}]})",
     "/axes/0/labels/1|control character (a tab)"},
    {"NameWithNewline", R"({"name": "small\n#SBATCH --wrap=id"})", "/name|control character (a newline)"},
    // Twenty-second probe: axis names become plot files, one file for "res" and "RES" (or for
    // "STAGES" and the stages figure) on a case-insensitive file system.
    {"AxisNamesDifferingInCase", R"({"axes": [{"name": "res", "values": {"frames": [1, 2]}}, {"name": "RES", "values": {"warmup_frames": [0, 1]}}]})",
     "/axes/1/name|only in case"},
    {"AxisNamedStagesInCapitals", R"({"axes": [{"name": "STAGES", "values": {"frames": [1, 2]}}]})", "/axes/0/name|sweep_stages.png"},
    {"EmptyOutputDir", R"({"output": {"dir": ""}})", "/output/dir|must not be empty"},
    // Parsed by a walker that would wrap such an index (std::stoul) or throw something else than bad input.
    {"ArrayIndexPastAnyArray", R"({"axes": [{"name": "pcf", "values": {"algorithms.99999999999999999999.params.pcf": [0, 1]}}]})",
     "axis \"pcf\"|past any array"},
};

void PrintTo(const BadSweep& c, std::ostream* os) { *os << c.name << ": " << c.patch; }

class SweepValidationTest : public ::testing::TestWithParam<BadSweep> {};

TEST_P(SweepValidationTest, ExitsWithCode2AndOneLineNamingThePath) {
    const BadSweep& c = GetParam();
    const std::string dir = test::makeTempDir("sweep-bad");
    Json sweep = test::smallSweep();
    sweep.merge_patch(Json::parse(c.patch));
    const std::string file = test::writeJson(dir + "/bad.sweep.json", sweep);
    for (const std::string& command : {"plan " + file, "run " + file + " --out " + dir + "/out"}) {
        std::string out;
        EXPECT_EQ(test::runCommand(bin() + " sweep " + command, out), 2) << out;
        const std::string trimmed = out.substr(0, out.find_last_not_of('\n') + 1);
        EXPECT_EQ(trimmed.find('\n'), std::string::npos) << out;
        EXPECT_NE(out.find(file), std::string::npos) << out;
        std::stringstream expected(c.expected);
        for (std::string part; std::getline(expected, part, '|');) EXPECT_NE(out.find(part), std::string::npos) << part << " in " << out;
    }
    // Nothing ran: validation comes before any output.
    EXPECT_FALSE(fs::exists(dir + "/out/runs"));
}

INSTANTIATE_TEST_SUITE_P(BadSweeps, SweepValidationTest, ::testing::ValuesIn(kBadSweeps),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(SweepTest, BadCommandLinesAreBadInput) {
    const std::string dir = test::makeTempDir("sweep-args");
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep());
    std::string out;
    for (const std::string& args : std::vector<std::string>{"sweep", "sweep frobnicate", "sweep run " + file + " --jobs 0", "sweep run " + file + " --shard 4/4",
                                   "sweep run " + file + " --index 4", "sweep run " + file + " --index 1 --shard 0/2",
                                   "sweep config " + file + " 9", "sweep merge " + dir + "/nothing", "sweep plan " + dir + "/missing.json",
                                   "sweep slurm " + file + " --gpus-per-task x"})
        EXPECT_EQ(test::runCommand(bin() + " " + args, out), 2) << args << ": " << out;
}

// ---- Ids --------------------------------------------------------------------------------------------

/// index → id, and labels → id, of `sweep plan --json`.
Json plan(const std::string& file) {
    std::string out;
    EXPECT_EQ(test::runCommand("(" + bin() + " sweep plan " + file + " --json 2>/dev/null)", out), 0) << out;
    return Json::parse(out);
}

TEST(SweepTest, RunsKeepTheirIdsWhenAnAxisIsAdded) {
    const std::string dir = test::makeTempDir("sweep-ids");
    Json small = test::smallSweep();
    const Json before = plan(test::writeJson(dir + "/a.sweep.json", small));
    ASSERT_EQ(before["runs"].size(), 4u);
    std::set<std::string> ids;
    for (const Json& r : before["runs"]) ids.insert(r["id"].get<std::string>());
    EXPECT_EQ(ids.size(), 4u) << "every run has its own id";

    // A third axis whose first value is the base's own (a point light): those runs are the old ones.
    small["axes"].push_back({{"name", "light"}, {"values", {{"light.type", {"point", "directional"}}}}});
    // Moving the output and writing a default explicitly change no run either.
    small["output"] = {{"dir", "elsewhere"}};
    small["base"]["camera"]["fov_y_deg"] = 60;
    const Json after = plan(test::writeJson(dir + "/b.sweep.json", small));
    ASSERT_EQ(after["runs"].size(), 8u);
    for (const Json& r : before["runs"]) {
        size_t matches = 0;
        for (const Json& s : after["runs"])
            if (s["axes"]["tris"] == r["axes"]["tris"] && s["axes"]["pcf"] == r["axes"]["pcf"] && s["axes"]["light"] == "point") {
                EXPECT_EQ(s["id"], r["id"]) << r.dump();
                ++matches;
            }
        EXPECT_EQ(matches, 1u);
    }
    // The directional runs are new runs.
    for (const Json& s : after["runs"])
        if (s["axes"]["light"] == "directional") EXPECT_FALSE(ids.count(s["id"].get<std::string>())) << s.dump();
}

TEST(SweepTest, SlurmScriptRunsOneTaskPerRunOrPerShard) {
    const std::string dir = test::makeTempDir("sweep-sbatch");
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep());
    std::string out;
    auto script = [&](const std::string& options) {
        EXPECT_EQ(test::runCommand(bin() + " sweep slurm " + file + " --out " + dir + "/out " + options, out), 0) << out;
        std::ifstream in(dir + "/out/sweep.sbatch");
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    };
    const std::string perRun = script("--partition debug --time 00:05:00 --max-parallel 2");
    for (const char* line : {"#SBATCH --array=0-3%2\n", "#SBATCH --partition='debug'\n", "#SBATCH --time='00:05:00'\n",
                             "/shadowlab' sweep run '", "/out/sweep.json' --out '", " --index \"$SLURM_ARRAY_TASK_ID\"\n"})
        EXPECT_NE(perRun.find(line), std::string::npos) << line << " in\n" << perRun;
    EXPECT_EQ(perRun.find("--gpus-per-task"), std::string::npos) << perRun;
    EXPECT_TRUE(fs::exists(dir + "/out/sweep.json"));
    EXPECT_TRUE(fs::is_directory(dir + "/out/slurm")) << "Slurm does not create the folder of --output itself";
#ifdef SHADOWLAB_EGL_BINARY
    // GPU nodes have no display: the EGL runner.
    const std::string gpu = script("--gpus-per-task 1 --cpus-per-task 4 --shards 3");
    for (const char* line : {"#SBATCH --array=0-2\n", "#SBATCH --gpus-per-task=1\n", "#SBATCH --cpus-per-task=4\n", "/shadowlab-egl' sweep run",
                             " --shard \"$SLURM_ARRAY_TASK_ID/3\"\n"})
        EXPECT_NE(gpu.find(line), std::string::npos) << line << " in\n" << gpu;
#endif
}

// ---- Running ----------------------------------------------------------------------------------------

/// Starts `command` in its own process group (so it can be killed with everything it started).
pid_t startGroup(const std::string& command) {
    pid_t pid = fork();
    if (pid == 0) {
        setpgid(0, 0);
        execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    setpgid(pid, pid);
    return pid;
}

/// Run slots (runs/ID) holding a summary. A run's ID.partial-PID also holds one for a moment before
/// its commit renames it into place, and is not a complete run.
size_t completeRuns(const std::string& dir) {
    size_t n = 0;
    if (!fs::exists(dir + "/runs")) return 0;
    for (const auto& e : fs::directory_iterator(dir + "/runs"))
        n += e.path().filename().string().find('.') == std::string::npos && fs::exists(e.path() / "summary.json");
    return n;
}

TEST(SweepTest, KilledMidwayThenRestartedRunsOnlyTheMissingRuns) {
    const std::string dir = test::makeTempDir("sweep-kill");
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep()), out = dir + "/out";
    const std::string command = bin() + " sweep run " + file + " --out " + out + " --jobs 1 > " + dir + "/first.log 2>&1";

    // The whole process group dies at once (a node lost, kill -9): no run gets to clean up.
    const pid_t pid = startGroup(command);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (completeRuns(out) < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    kill(-pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    const size_t done = completeRuns(out);
    ASSERT_GE(done, 2u);
    ASSERT_LT(done, 4u) << "the sweep finished before it could be killed";
    std::map<std::string, fs::file_time_type> before;
    for (const auto& e : fs::directory_iterator(out + "/runs"))
        if (e.path().filename().string().find('.') == std::string::npos && fs::exists(e.path() / "summary.json")) before[e.path().filename()] = fs::last_write_time(e.path() / "summary.json");

    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out + " --jobs 2", log), 0) << log;
    EXPECT_EQ(countOf(log, "] skip"), done) << log;
    EXPECT_EQ(countOf(log, "] done"), 4 - done) << log;
    EXPECT_EQ(completeRuns(out), 4u);
    // Killed between writing its summary and renaming its folder into place, a run left an unmarked
    // ID.partial-PID that no later run removed (CI, stop 48).
    for (const auto& e : fs::directory_iterator(out + "/runs"))
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path() << " left behind";
    for (const auto& [id, time] : before) EXPECT_EQ(fs::last_write_time(out + "/runs/" + id + "/summary.json"), time) << id << " ran again";

    // A third start has nothing left to do.
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    EXPECT_EQ(countOf(log, "] skip"), 4u) << log;
    ASSERT_EQ(test::runCommand(bin() + " sweep merge " + out + " --no-plots", log), 0) << log;
    EXPECT_EQ(test::runIds(out + "/sweep.csv").size(), 4u);
}

// Fifth probe: a run slot replaced by a copy of (or a link to) another run's folder counted as
// complete and was merged as this run. A run's results count only where its config.resolved.json
// is this run's config.
TEST(SweepTest, AnotherRunsResultsInASlotAreNotThisRun) {
    const std::string dir = test::makeTempDir("sweep-foreign-slot");
    Json sweep = test::twoRunSweep();
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep), out = dir + "/out";
    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    const Json p = plan(file);
    const std::string first = p["runs"][0]["id"], second = p["runs"][1]["id"];
    fs::remove_all(out + "/runs/" + second);
    fs::copy(out + "/runs/" + first, out + "/runs/" + second, fs::copy_options::recursive);
    EXPECT_EQ(test::runCommand(bin() + " sweep merge " + out + " --no-plots", log), 1) << log;
    EXPECT_NE(log.find("holds the results of another config (run " + first + ")"), std::string::npos) << log;
    EXPECT_EQ(test::runIds(out + "/sweep.csv").size(), 1u);
    // The copy is not taken for the run: the sweep runs it again, into its own folder.
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    EXPECT_EQ(countOf(log, "] done"), 1u) << log;
    // A link to the other run's folder is not this run's folder either.
    fs::remove_all(out + "/runs/" + second);
    fs::create_directory_symlink(first, out + "/runs/" + second);
    EXPECT_EQ(test::runCommand(bin() + " sweep merge " + out + " --no-plots", log), 1) << log;
    EXPECT_NE(log.find("is not a folder of its own"), std::string::npos) << log;
}

// Fifth probe: the refusal of another sweep's folder advises removing its sweep.json to hand the
// folder over, but once merged the folder was then refused as not a sweep's. A merged sweep's
// folder without sweep.json is taken (its runs with equal ids kept); with a file of the user's in it, not.
TEST(SweepTest, AMergedSweepsFolderWithoutItsSnapshotGoesToANewSweep) {
    const std::string dir = test::makeTempDir("sweep-handover");
    Json sweep = test::twoRunSweep();
    sweep["axes"][0]["values"]["algorithms.0.params.pcf"] = Json::array({0});  // one run, then two
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep), out = dir + "/out";
    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    ASSERT_EQ(test::runCommand(bin() + " sweep merge " + out + " --no-plots", log), 0) << log;
    sweep["name"] = "bigger";
    sweep["axes"][0]["values"]["algorithms.0.params.pcf"] = Json::array({0, 1});
    test::writeJson(file, sweep);
    EXPECT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 2) << log;
    EXPECT_NE(log.find("holds another sweep"), std::string::npos) << log;
    fs::remove(out + "/sweep.json");
    std::ofstream(out + "/notes.txt") << "mine\n";
    EXPECT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 2) << log;
    EXPECT_NE(log.find("is not a sweep's folder"), std::string::npos) << log;
    fs::remove(out + "/notes.txt");
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    EXPECT_EQ(countOf(log, "] skip"), 1u) << log;
    EXPECT_EQ(countOf(log, "] done"), 1u) << log;
    ASSERT_EQ(test::runCommand(bin() + " sweep merge " + out + " --no-plots", log), 0) << log;
    EXPECT_EQ(test::runIds(out + "/sweep.csv").size(), 2u);
}

// Fifth probe: `sweep run MOVED/sweep.json` without --out ran every run again at the folder's old
// place (the snapshot's output.dir). The snapshot's own folder is the sweep's: it resumes there.
TEST(SweepTest, AMovedSweepResumesFromItsSnapshotInPlace) {
    const std::string dir = test::makeTempDir("sweep-moved");
    Json sweep = test::twoRunSweep();
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep), out = dir + "/out", moved = dir + "/moved";
    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    fs::rename(out, moved);
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + moved + "/sweep.json", log), 0) << log;
    EXPECT_EQ(countOf(log, "] skip"), 2u) << log;
    EXPECT_NE(log.find("this folder's runs are used (the folder has moved)"), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(out)) << "nothing at the old place";
    ASSERT_EQ(test::runCommand(bin() + " sweep merge " + moved + " --no-plots", log), 0) << log;
}

// A run that exits 3 (expectations not met) has written its results: the sweep counts it complete,
// says so on its line, and exits 3 itself, also when it resumes.
TEST(SweepTest, RunsWithUnmetExpectationsAreCompleteAndTheSweepExitsThree) {
    const std::string dir = test::makeTempDir("sweep-expect");
    Json sweep = test::twoRunSweep();
    sweep["base"]["expect"] = Json::parse(R"([{"id": "shadow_map", "measure": "memory_bytes", "max": 1}])");
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep), out = dir + "/out";
    std::string log;
    EXPECT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 3) << log;
    EXPECT_EQ(countOf(log, "] done"), 2u) << log;
    EXPECT_EQ(countOf(log, "its expectations failed"), 2u) << log;
    EXPECT_NE(log.find("2 complete, 0 failed, 2 complete with expectations not met"), std::string::npos) << log;
    EXPECT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 3) << log;
    EXPECT_EQ(countOf(log, "] skip"), 2u) << log;
    EXPECT_EQ(test::runCommand(bin() + " sweep merge " + out + " --no-plots", log), 0) << log;
}

// Sixth probe: a model edited between two `sweep run`s kept its runs' ids, and the results of the
// old geometry were skipped as complete and merged. Its content is part of the id: they run again.
TEST(SweepTest, EditingAGltfFileGivesItsRunsNewIds) {
    const std::string dir = test::makeTempDir("sweep-gltf-edit");
    std::ofstream(dir + "/m.gltf") << test::triangleGltf({});
    Json sweep = test::twoRunSweep();
    sweep["base"]["scene"]["objects"][1] = Json::parse(R"({"gltf": "m.gltf"})");
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep), out = dir + "/out";
    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    const Json before = plan(file);
    std::ofstream(dir + "/m.gltf") << test::triangleGltf({{"nodes", R"([{"mesh": 0, "translation": [0, 0.5, 0]}])"}});
    const Json after = plan(file);
    for (size_t k = 0; k < 2; ++k) EXPECT_NE(before["runs"][k]["id"], after["runs"][k]["id"]) << k;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out, log), 0) << log;
    EXPECT_EQ(countOf(log, "] done"), 2u) << log;
    EXPECT_EQ(countOf(log, "] skip"), 0u) << log;
}

// Thirteenth probe: a buffer file named percent-encoded ("my%20buf.bin") was left out of the run's
// id, so a model edited between two sweep runs kept its stale results.
TEST(SweepTest, EditingAPercentEncodedBufferFileGivesItsRunsNewIds) {
    const std::string dir = test::makeTempDir("sweep-buffer-edit");
    auto writeBuffer = [&](float y) {
        const float pos[9] = {-1, y, -1, -1, y, 1, 1, y, -1};
        std::ofstream(dir + "/my buf.bin", std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(pos), sizeof pos);
    };
    writeBuffer(0.5f);
    std::ofstream(dir + "/m.gltf") << test::triangleGltf(
        {{"buffers", R"([{"byteLength": 36, "uri": "my%20buf.bin"}])"},
         {"accessors", R"([{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3, "min": [-1, 0, -1], "max": [1, 1, 1]}])"}});
    Json sweep = test::twoRunSweep();
    sweep["base"]["scene"]["objects"][1] = Json::parse(R"({"gltf": "m.gltf"})");
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep);
    const Json before = plan(file);
    writeBuffer(0.75f);
    const Json after = plan(file);
    for (size_t k = 0; k < 2; ++k) EXPECT_NE(before["runs"][k]["id"], after["runs"][k]["id"]) << k;
}

TEST(SweepTest, SigtermStopsTheRunsInFlightAndTheSweepResumes) {
    const std::string dir = test::makeTempDir("sweep-term");
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep()), out = dir + "/out";
    // What scancel and Ctrl-C send: only the sweep process gets it, and it stops its runs itself.
    const pid_t pid = startGroup("exec " + bin() + " sweep run " + file + " --out " + out + " --jobs 1 > " + dir + "/first.log 2>&1");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (completeRuns(out) < 1 && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    const size_t done = completeRuns(out);
    if (done < 4) {
        ASSERT_TRUE(WIFEXITED(status));
        EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
    }
    // Nothing left running (the sweep waited for its runs), and no half-written run folder left.
    const bool groupGone = kill(-pid, 0) != 0 && errno == ESRCH;
    EXPECT_TRUE(groupGone) << "a run outlived the sweep";
    if (!groupGone) kill(-pid, SIGKILL);
    for (const auto& e : fs::directory_iterator(out + "/runs"))
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out + " --jobs 2", log), 0) << log;
    EXPECT_EQ(countOf(log, "] skip"), done) << log;
    EXPECT_EQ(countOf(log, "] done"), 4 - done) << log;
}

TEST(SweepTest, AFailedRunLeavesAnErrorRecordAndTheOthersGoOn) {
    const std::string dir = test::makeTempDir("sweep-fail");
    Json sweep = test::smallSweep();
    // A malformed glTF file passes the sweep's checks (files are not loaded then) and fails its run.
    const std::string bad = test::kAssimpGltf + "/IndexOutOfRange/IndexOutOfRange.gltf";
    sweep["axes"] = Json::parse(R"([
      {"name": "object", "labels": ["sphere", "broken"],
       "values": {"scene.objects.1": [{"procedural": "sphere", "radius": 0.5}, {"gltf": ")" + bad + R"("}]}},
      {"name": "pcf", "values": {"algorithms.0.params.pcf": [0, 1]}}])");
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep), out = dir + "/out";
    std::string log;
    EXPECT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out + " --jobs 2", log), 1) << log;
    EXPECT_EQ(countOf(log, "] done"), 2u) << log;
    EXPECT_EQ(countOf(log, "] FAILED"), 2u) << log;
    const Json p = plan(file);
    for (const Json& r : p["runs"]) {
        const std::string base = out + "/runs/" + r["id"].get<std::string>();
        if (r["axes"]["object"] == "broken") {
            ASSERT_TRUE(fs::exists(base + ".error.json")) << base;
            const Json e = JsonNode::parseFile(base + ".error.json");
            EXPECT_EQ(e["status"], "exit code 2");
            EXPECT_NE(e["log_tail"].get<std::string>().find("IndexOutOfRange.gltf"), std::string::npos) << e.dump(2);
            EXPECT_FALSE(fs::exists(base + "/summary.json"));
        } else {
            EXPECT_TRUE(fs::exists(base + "/summary.json")) << base;
            EXPECT_FALSE(fs::exists(base + ".error.json")) << base;
        }
    }
    // The merge keeps what exists, names what failed, and says so in its exit code.
    EXPECT_EQ(test::runCommand(bin() + " sweep merge " + out + " --no-plots", log), 1) << log;
    EXPECT_EQ(test::runIds(out + "/sweep.csv").size(), 2u);
    std::ifstream md(out + "/sweep.md");
    std::stringstream text;
    text << md.rdbuf();
    EXPECT_EQ(countOf(text.str(), ": failed**"), 2u) << text.str();
}

// Fifth probe: `sweep plan` passed a line_space (n, d) that validate refuses on the scene, and the
// sweep's run then failed. Plain plan checks configs only and says so; --check validates each run
// (scene made, each algorithm's fit decided) and stops at the first refusal, naming the run.
TEST(SweepTest, PlanCheckValidatesEachRunOnItsScene) {
    const std::string dir = test::makeTempDir("sweep-plan-check");
    Json sweep = test::smallSweep();
    sweep["base"]["algorithms"] = Json::parse(R"([{"algorithm": "shadow_map"}, {"algorithm": "line_space", "params": {"n": 4, "d": 2}}])");
    sweep.erase("merge");
    sweep["axes"] = Json::parse(R"([{"name": "n", "values": {"algorithms.1.params.n": [4, 8], "algorithms.1.params.d": [2, 4]},
                                     "labels": ["small", "deep"]}])");
    const std::string file = test::writeJson(dir + "/s.sweep.json", sweep);
    std::string log;
    EXPECT_EQ(test::runCommand("(" + bin() + " sweep plan " + file + " >/dev/null)", log), 0) << log;
    EXPECT_NE(log.find("every config valid (--check also validates"), std::string::npos) << log;
    EXPECT_EQ(test::runCommand("(" + bin() + " sweep plan " + file + " --check >/dev/null)", log), 2) << log;
    const std::string refused = log.substr(log.rfind("shadowlab: "));
    EXPECT_NE(refused.find("s.sweep.json: run 1 ("), std::string::npos) << log;
    EXPECT_NE(refused.find("n=deep) is refused: run 1's config: at /algorithms/1: line_space cannot hold this scene"),
              std::string::npos) << log;
    EXPECT_EQ(std::count(refused.begin(), refused.end(), '\n'), 1) << log;
    // The run that fits passes alone; nothing is left in the temporary folder.
    sweep["axes"][0]["values"] = Json::parse(R"({"algorithms.1.params.n": [4], "algorithms.1.params.d": [2]})");
    sweep["axes"][0]["labels"] = Json::parse(R"(["small"])");
    test::writeJson(file, sweep);
    EXPECT_EQ(test::runCommand("(TMPDIR=" + dir + " " + bin() + " sweep plan " + file + " --check >/dev/null)", log), 0) << log;
    EXPECT_NE(log.find("1 runs, each validated on this device"), std::string::npos) << log;
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "only s.sweep.json";
}

TEST(SweepTest, MergeWritesTheTidyTableReportAndPlots) {
    const std::string dir = test::makeTempDir("sweep-merge");
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep()), out = dir + "/out";
    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out + " --shard 1/2", log), 0) << log;
    EXPECT_EQ(countOf(log, "] done"), 2u) << log;
    EXPECT_EQ(test::runCommand(bin() + " sweep merge " + out, log), 1) << "two runs are missing: " << log;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + out + " --shard 0/2", log), 0) << log;
    ASSERT_EQ(test::runCommand(bin() + " sweep merge " + out, log), 0) << log;

    std::ifstream csv(out + "/sweep.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header, "run,index,tris,pcf,triangles,pixels,id,algorithm,measure,kind,value");
    const auto rows = test::rowsOfKind(out + "/sweep.csv", "accuracy");
    // 4 runs × 3 algorithms (reference, shadow_map, psv), each with its accuracy.
    size_t accuracy = 0;
    for (const auto& [key, value] : rows) accuracy += key.find(",accuracy.mismatch_ratio_max") != std::string::npos;
    EXPECT_EQ(accuracy, 12u);
    std::ifstream mdFile(out + "/sweep.md");
    std::stringstream md;
    md << mdFile.rdbuf();
    for (const char* part : {"## By `tris`", "## By `pcf`", "## psv / shadow_map", "## Power-law fits along `tris`"})
        EXPECT_NE(md.str().find(part), std::string::npos) << part << "\n" << md.str();
    EXPECT_EQ(md.str().find("No fit:"), std::string::npos) << md.str();
    EXPECT_TRUE(fs::exists(out + "/sweep_tris.png"));
    EXPECT_TRUE(fs::exists(out + "/sweep_pcf.png"));
}

} // namespace
} // namespace shadowlab
