// Sweeps against hostile and broken input: values that could reach a shell or an #SBATCH line,
// counts that could wrap, text that breaks tables or JSON, broken run results, two sweeps on one
// folder, a killed sweep, and the memory of many runs over a large base. Most of these run no
// renderer: the run folders are written as a finished run leaves them (SweepTestData.h).
#include "framework/core/JsonNode.h"
#include "tests/SweepTestData.h"
#include "tests/TestSupport.h"

#include <chrono>
#include <cmath>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sys/file.h>
#include <thread>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
using test::Ran;
using test::runArgs;

const std::string kBin = SHADOWLAB_BINARY;

std::vector<std::string> sweep(std::initializer_list<std::string> rest) {
    std::vector<std::string> v = {kBin, "sweep"};
    v.insert(v.end(), rest);
    return v;
}

/// One line on stderr (the trailing newline aside), at most `maxChars` long.
void expectOneShortLine(const Ran& r, size_t maxChars = 1200) {
    const std::string trimmed = r.err.substr(0, r.err.find_last_not_of('\n') + 1);
    EXPECT_EQ(trimmed.find('\n'), std::string::npos) << r.err.substr(0, 2000);
    EXPECT_LE(r.err.size(), maxChars) << r.err.substr(0, 2000);
}

std::string smallFile(const std::string& dir, const Json& patch = Json::object()) {
    Json s = test::smallSweep();
    s.merge_patch(patch);
    return test::writeJson(dir + "/small.sweep.json", s);
}

// ---- Counts on the command line -----------------------------------------------------------------

TEST(SweepInputTest, CountsAreDecimalsInTheirRange) {
    const std::string dir = test::makeTempDir("sweep-counts"), file = smallFile(dir), out = dir + "/out";
    // Each is refused before anything is written: std::stoul would take "-1" (2^64 - 1) and "+1".
    const std::vector<std::vector<std::string>> bad = {
        {"run", file, "--out", out, "--jobs", "0"},
        {"run", file, "--out", out, "--jobs", "257"},
        {"run", file, "--out", out, "--jobs", "-1"},
        {"run", file, "--out", out, "--jobs", "+1"},
        {"run", file, "--out", out, "--jobs", " 1"},
        {"run", file, "--out", out, "--jobs", "0x2"},
        {"run", file, "--out", out, "--jobs", ""},
        {"run", file, "--out", out, "--jobs", "99999999999999999999999"},
        {"run", file, "--out", out, "--index", "-1"},
        {"run", file, "--out", out, "--index", "4"},
        {"run", file, "--out", out, "--index", "18446744073709551616"},
        {"run", file, "--out", out, "--shard", "-1/2"},
        {"run", file, "--out", out, "--shard", "0/+2"},
        {"run", file, "--out", out, "--shard", "0/0"},
        {"run", file, "--out", out, "--shard", "2/2"},
        {"slurm", file, "--out", out, "--gpus-per-task", "4294967297"},
        {"slurm", file, "--out", out, "--gpus-per-task", "-1"},
        {"slurm", file, "--out", out, "--gpus-per-task", "65"},
        {"slurm", file, "--out", out, "--cpus-per-task", "1025"},
        {"slurm", file, "--out", out, "--cpus-per-task", "-0"},
        {"slurm", file, "--out", out, "--max-parallel", "-1"},
        {"slurm", file, "--out", out, "--shards", "18446744073709551617"},
        {"config", file, "-1"},
        {"config", file, "4"},
        {"config", file, "+0"},
    };
    for (const auto& args : bad) {
        std::vector<std::string> argv = {kBin, "sweep"};
        argv.insert(argv.end(), args.begin(), args.end());
        const Ran r = runArgs(argv);
        std::string shown;
        for (const auto& a : args) shown += a + " ";
        EXPECT_EQ(r.rc, 2) << shown << r.err;
        expectOneShortLine(r);
        EXPECT_FALSE(fs::exists(out)) << shown << ": nothing is written for a bad count";
    }
    // The ends of each range are accepted.
    EXPECT_EQ(runArgs(sweep({"config", file, "3"})).rc, 0);
    EXPECT_EQ(runArgs(sweep({"slurm", file, "--out", out, "--gpus-per-task", "0", "--cpus-per-task", "1024", "--max-parallel", "4",
                             "--shards", "2"})).rc, 0);
}

TEST(SweepInputTest, SetPathIndexPastAnyArrayIsBadInput) {
    const std::string smoke = std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json";
    const std::string out = test::makeTempDir("set-index") + "/o";
    for (const char* set : {"algorithms.99999999999999999999.params.pcf=1", "algorithms.18446744073709551616=1"}) {
        for (const Ran& r : {runArgs({kBin, "validate", smoke, "--set", set}), runArgs({kBin, "run", smoke, "--set", set, "--out", out})}) {
            EXPECT_EQ(r.rc, 2) << set << ": " << r.err;
            expectOneShortLine(r);
        }
    }
    EXPECT_FALSE(fs::exists(out));
}

// ---- Text that reaches files, tables and lines --------------------------------------------------

TEST(SweepInputTest, NamesPathsAndLabelsMustBeOneLineOfUtf8) {
    const std::string dir = test::makeTempDir("sweep-text");
    // A file name that is not UTF-8 becomes the sweep's default name: refused at load, not after the
    // runs (nlohmann's type_error.316 when writing sweep.json).
    const std::string latin1 = dir + "/caf\xe9.sweep.json";
    {
        Json s = test::smallSweep();
        s.erase("name");
        test::writeJson(latin1, s);
    }
    for (const auto& args : std::vector<std::vector<std::string>>{{"plan", latin1}, {"run", latin1, "--out", dir + "/o1"}}) {
        std::vector<std::string> argv = {kBin, "sweep"};
        argv.insert(argv.end(), args.begin(), args.end());
        const Ran r = runArgs(argv);
        EXPECT_EQ(r.rc, 2) << r.err;
        EXPECT_NE(r.err.find("not valid UTF-8"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find('\xe9'), std::string::npos) << "the byte itself is not echoed";
        expectOneShortLine(r);
    }
    EXPECT_FALSE(fs::exists(dir + "/o1"));

    const std::string file = smallFile(dir);
    for (const std::string& out : {dir + "/o\xff", dir + "/o\nx", dir + "/o\tx"}) {
        for (const char* command : {"run", "slurm"}) {
            const Ran r = runArgs(sweep({command, file, "--out", out}));
            EXPECT_EQ(r.rc, 2) << command << ": " << r.err;
            expectOneShortLine(r);
            EXPECT_FALSE(fs::exists(out));
        }
    }

    // A name with a newline is no name (it titles the report): an axis that sets one is refused,
    // naming the axis and the run config's path.
    Json s = test::smallSweep();
    s["axes"] = Json::parse(R"([{"name": "title", "values": {"name": ["line one\nline two", "tab\there"]}}])");
    const std::string escaped = test::writeJson(dir + "/escaped.sweep.json", s);
    const Ran plan = runArgs(sweep({"plan", escaped}));
    EXPECT_EQ(plan.rc, 2) << plan.err;
    EXPECT_NE(plan.err.find("/axes/0"), std::string::npos) << plan.err;
    EXPECT_NE(plan.err.find("/name"), std::string::npos) << plan.err;
    expectOneShortLine(plan);
}

TEST(SweepInputTest, HugeNamesAndLabelsAreRefusedWithoutEchoingThem) {
    const std::string dir = test::makeTempDir("sweep-huge");
    const std::string huge(5 << 20, 'x');
    Json labels = test::smallSweep();
    labels["axes"][1]["labels"] = {huge, "b"};
    Json named = test::smallSweep();
    named["name"] = huge;
    Json derived = test::smallSweep(); // a label made of a huge value
    derived["axes"] = Json::array({{{"name", "n"}, {"values", {{"name", {huge, "short"}}}}}});
    for (const Json& s : {labels, named, derived}) {
        const std::string file = test::writeJson(dir + "/huge.sweep.json", s);
        for (const char* command : {"plan", "run", "slurm"}) {
            const Ran r = runArgs(std::string(command) == "plan" ? sweep({command, file}) : sweep({command, file, "--out", dir + "/o"}));
            EXPECT_EQ(r.rc, 2) << command;
            expectOneShortLine(r, 1200);
            EXPECT_NE(r.err.find("200"), std::string::npos) << r.err;
            EXPECT_FALSE(fs::exists(dir + "/o"));
        }
    }
    // At the cap it is fine.
    Json ok = test::smallSweep();
    ok["axes"][1]["labels"] = {std::string(200, 'y'), "b"};
    EXPECT_EQ(runArgs(sweep({"plan", test::writeJson(dir + "/ok.sweep.json", ok)})).rc, 0);
}

// Seventh probe: labels such as "=HYPERLINK(...)" reached sweep.csv and the plan's TSV as typed,
// formulas to a spreadsheet. A given label is refused; one made of a value becomes its JSON text.
TEST(SweepInputTest, LabelsASpreadsheetWouldRunAreRefusedOrQuoted) {
    const std::string dir = test::makeTempDir("sweep-formula");
    // The last five read as numbers to strtod, as text or names to a spreadsheet (tenth probe).
    for (const char* label : {"=HYPERLINK(\"http://x\")", "@SUM(1)", "+1+2", "-x", "-nan(HYPERLINK)", "+INF", "-infinity",
                              "+0x1p3", "-1e"}) {
        Json given = test::smallSweep();
        given["axes"][1]["labels"] = {label, "b"};
        const Ran r = runArgs(sweep({"plan", test::writeJson(dir + "/given.sweep.json", given)}));
        EXPECT_EQ(r.rc, 2) << label;
        EXPECT_NE(r.err.find("/axes/1/labels/0"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("formula"), std::string::npos) << r.err;
        expectOneShortLine(r);
    }
    Json numbers = test::smallSweep();
    numbers["axes"][1]["labels"] = {"-0.5", "+2e-3"};
    EXPECT_EQ(runArgs(sweep({"plan", test::writeJson(dir + "/numbers.sweep.json", numbers)})).rc, 0);
    Json derived = test::smallSweep();
    derived["axes"] = Json::array({{{"name", "n"}, {"values", {{"name", {"=1+1", "plain"}}}}}});
    const Ran plan = runArgs(sweep({"plan", test::writeJson(dir + "/derived.sweep.json", derived)}));
    EXPECT_EQ(plan.rc, 0) << plan.err;
    EXPECT_NE(plan.out.find("\"=1+1\""), std::string::npos) << plan.out;
    EXPECT_EQ(plan.out.find("\t=1+1"), std::string::npos) << plan.out;
}

TEST(SweepInputTest, EmptyOutIsRefusedAndNothingIsCreated) {
    ASSERT_FALSE(fs::exists("/runs")) << "a /runs folder exists already: this test cannot tell";
    const std::string dir = test::makeTempDir("sweep-empty-out"), file = smallFile(dir);
    for (const char* command : {"run", "slurm"}) {
        const Ran r = runArgs(sweep({command, file, "--out", ""}));
        EXPECT_EQ(r.rc, 2) << command << ": " << r.err;
        EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
        expectOneShortLine(r);
    }
    EXPECT_FALSE(fs::exists("/runs"));
    EXPECT_FALSE(fs::exists("/sweep.json"));
    EXPECT_EQ(runArgs(sweep({"merge", ""})).rc, 2);
}

// Twenty-first probe: `sweep plan` called every config valid for output folders `sweep run` then
// refused (a run's output, a file, a folder of the user's): plan checks the folder as run does.
TEST(SweepInputTest, PlanRefusesTheOutputFoldersRunRefuses) {
    const std::string dir = test::makeTempDir("sweep-plan-out");
    fs::create_directories(dir + "/a_run");
    std::ofstream(dir + "/a_run/summary.json") << "{}";
    std::ofstream(dir + "/a_file") << "x";
    fs::create_directories(dir + "/mine");
    std::ofstream(dir + "/mine/notes.txt") << "mine";
    for (const char* out : {"a_run", "a_file", "mine"}) {
        const std::string file = smallFile(dir, {{"output", {{"dir", dir + "/" + out}}}});
        const Ran plan = runArgs(sweep({"plan", file}));
        EXPECT_EQ(plan.rc, 2) << out << ": " << plan.err;
        EXPECT_NE(plan.err.find("/output/dir"), std::string::npos) << plan.err;
        expectOneShortLine(plan);
        EXPECT_EQ(runArgs(sweep({"run", file})).rc, 2) << out << ": what plan refuses, run refuses";
    }
    // Another sweep's folder: run would refuse to mix its runs with that sweep's.
    ASSERT_FALSE(test::fakeSweepRuns(kBin, smallFile(dir), dir + "/theirs").is_null());
    const Ran other = runArgs(sweep({"plan", smallFile(dir, {{"name", "another"}, {"output", {{"dir", dir + "/theirs"}}}})}));
    EXPECT_EQ(other.rc, 2) << other.err;
    EXPECT_NE(other.err.find("holds another sweep"), std::string::npos) << other.err;
    EXPECT_EQ(runArgs(sweep({"plan", smallFile(dir, {{"output", {{"dir", dir + "/new"}}}})})).rc, 0);
}

TEST(SweepInputTest, RelativeGltfInAnAxisValueIsTheSweepFilesNeighbour) {
    const std::string dir = test::makeTempDir("sweep-gltf"), models = dir + "/models";
    fs::create_directories(models);
    fs::copy_file(test::kAssimpGltf + "/BoxTextured-glTF-Binary/BoxTextured.glb", models + "/box.glb");
    Json s = test::smallSweep();
    s["axes"] = Json::parse(R"([{"name": "object", "labels": ["box", "sphere"],
        "values": {"scene.objects.1": [{"gltf": "box.glb"}, {"procedural": "sphere", "radius": 0.5}]}}])");
    s["base"]["scene"]["objects"].push_back({{"gltf", "box.glb"}}); // a base path, resolved the same way
    const std::string file = test::writeJson(models + "/s.sweep.json", s);
    const std::string absolute = fs::absolute(models).lexically_normal().string() + "/box.glb";
    // From any working folder, by a relative path to the sweep file: the same absolute path, so the same runs.
    for (const std::string& cwd : {dir, models, std::string("/")}) {
        const std::string rel = fs::relative(file, cwd).string();
        const Ran config = runArgs(sweep({"config", rel, "0"}), {}, cwd);
        ASSERT_EQ(config.rc, 0) << cwd << ": " << config.err;
        const Json c = Json::parse(config.out);
        EXPECT_EQ(c["scene"]["objects"][1]["gltf"], absolute) << cwd;
        EXPECT_EQ(c["scene"]["objects"][2]["gltf"], absolute) << cwd;
    }
    EXPECT_EQ(test::planOf(kBin, file)["runs"], test::planOf(kBin, models + "/../models/s.sweep.json")["runs"]);
    // The snapshot holds the absolute path, so the runs read from DIR find the file; and the run renders.
    const std::string out = dir + "/out";
    const Ran run = runArgs(sweep({"run", file, "--out", out, "--index", "0"}));
    ASSERT_EQ(run.rc, 0) << run.err;
    EXPECT_NE(test::readText(out + "/sweep.json").find(absolute), std::string::npos);
    EXPECT_EQ(test::planOf(kBin, out + "/sweep.json")["runs"], test::planOf(kBin, file)["runs"]);
}

// ---- Slurm: nothing reaches a shell or an #SBATCH line unchecked --------------------------------

TEST(SweepSlurmScriptTest, ValuesThatCouldAddOptionsOrCommandsAreRefused) {
    const std::string dir = test::makeTempDir("sbatch-bad"), file = smallFile(dir), out = dir + "/out";
    const std::vector<std::vector<std::string>> bad = {
        {"--partition", "debug\ntouch " + dir + "/X"},
        {"--partition", "debug --wrap=id"},
        {"--partition", "gpu'x"},
        {"--partition", "a,,b"},
        {"--time", "10 --wrap=id"},
        {"--time", "1\n#SBATCH --wrap=id"},
        {"--time", "1:2:3:4"},
        {"--time", "01:00:00'"},
        {"--time", "-1"},
    };
    for (const auto& options : bad) {
        std::vector<std::string> argv = sweep({"slurm", file, "--out", out});
        argv.insert(argv.end(), options.begin(), options.end());
        const Ran r = runArgs(argv);
        EXPECT_EQ(r.rc, 2) << options[0] << " " << options[1] << ": " << r.err;
        EXPECT_NE(r.err.find(options[0]), std::string::npos) << r.err;
        expectOneShortLine(r);
        EXPECT_FALSE(fs::exists(out + "/sweep.sbatch")) << options[1];
    }
    // --output would read % and \ as a file name pattern.
    for (const std::string& o : {dir + "/100%", dir + "/a\\b"}) {
        const Ran r = runArgs(sweep({"slurm", file, "--out", o}));
        EXPECT_EQ(r.rc, 2) << o << ": " << r.err;
        EXPECT_FALSE(fs::exists(o + "/sweep.sbatch"));
    }
    // The same folder given by the sweep file's output.dir is blamed there, not on an --out never
    // given (probe 25).
    {
        const std::string inFile = smallFile(dir, {{"output", {{"dir", dir + "/out_%j"}}}});
        const Ran r = runArgs(sweep({"slurm", inFile}));
        EXPECT_EQ(r.rc, 2) << r.err;
        EXPECT_NE(r.err.find("small.sweep.json: at /output/dir"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("error: --out"), std::string::npos) << r.err;
        expectOneShortLine(r);
    }
    // Each Slurm time format is accepted.
    for (const char* time : {"30", "30:00", "02:00:00", "1-0", "1-12:30", "2-00:00:00", "UNLIMITED"})
        EXPECT_EQ(runArgs(sweep({"slurm", file, "--out", out, "--time", time})).rc, 0) << time;
    EXPECT_EQ(runArgs(sweep({"slurm", file, "--out", out, "--partition", "gpu,debug_2.a-b"})).rc, 0);
    EXPECT_FALSE(fs::exists(dir + "/X"));
}

/// A stand-in for sbatch on PATH: records its arguments one per line and prints a job id.
std::string fakeSbatch(const std::string& dir) {
    const std::string bin = dir + "/bin";
    fs::create_directories(bin);
    std::ofstream(bin + "/sbatch") << "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\n' \"$a\"; done > \"" << dir
                                   << "/sbatch.args\"\necho 'sbatch: warning: a site note'\necho '4242;cluster'\n";
    fs::permissions(bin + "/sbatch", fs::perms::owner_all);
    return bin;
}

TEST(SweepSlurmScriptTest, PathsAreQuotedAndSbatchIsRunWithoutAShell) {
    const std::string dir = test::makeTempDir("sbatch-quote");
    // A sweep name that is not a Slurm name, and a folder with a space, a quote and a command in it.
    const std::string file = smallFile(dir, {{"name", "psv scaling; $(touch X)"}});
    const std::string out = dir + "/it's a $(touch " + dir + "/X) folder";
    const std::string bin = fakeSbatch(dir);
    const Ran r = runArgs(sweep({"slurm", file, "--out", out, "--partition", "gpu", "--time", "02:00:00", "--submit"}),
                          {"PATH=" + bin + ":/usr/bin:/bin"});
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.out, "4242\n") << "the job id, after sbatch's warnings";
    const std::string script = fs::absolute(out).string() + "/sweep.sbatch";
    EXPECT_EQ(test::readText(dir + "/sbatch.args"), "--parsable\n" + script + "\n") << "sbatch --parsable SCRIPT, as two arguments";
    EXPECT_FALSE(fs::exists(dir + "/X"));
    EXPECT_FALSE(fs::exists("X"));

    const std::string text = test::readText(script);
    const std::string quoted = "'" + dir + "/it'\\''s a $(touch " + dir + "/X) folder";
    for (const std::string& line : std::vector<std::string>{"#SBATCH --job-name='shadowlab-psv_scaling____touch_X_'\n", "#SBATCH --partition='gpu'\n",
                                    "#SBATCH --time='02:00:00'\n", "#SBATCH --output=" + quoted + "/slurm/%A_%a.out'\n",
                                    " sweep run " + quoted + "/sweep.json' --out " + quoted + "' --index \"$SLURM_ARRAY_TASK_ID\"\n"})
        EXPECT_NE(text.find(line), std::string::npos) << line << " in\n" << text;
    // Every #SBATCH option is one line; bash reads the script (without running it).
    size_t sbatch = 0;
    for (size_t pos = text.find("#SBATCH"); pos != std::string::npos; pos = text.find("#SBATCH", pos + 1)) ++sbatch;
    EXPECT_EQ(sbatch, 6u) << text;
    EXPECT_EQ(runArgs({"/bin/bash", "-n", script}).rc, 0) << text;

    // No sbatch on PATH: a runtime failure that says so, not a shell's message.
    const Ran missing = runArgs(sweep({"slurm", file, "--out", out, "--submit"}), {"PATH=" + dir + "/nothing"});
    EXPECT_EQ(missing.rc, 1) << missing.err;
    EXPECT_NE(missing.err.find("is Slurm installed?"), std::string::npos) << missing.err;
}

// ---- Merge ----------------------------------------------------------------------------------------

TEST(SweepMergeEdgeTest, TheReportScriptGetsTheFolderAsAnArgument) {
    const std::string dir = test::makeTempDir("merge-quote");
    const std::string out = dir + "/res'; touch " + dir + "/X; echo '";
    ASSERT_FALSE(test::fakeSweepRuns(kBin, smallFile(dir), out).is_null());
    const Ran r = runArgs(sweep({"merge", out}));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/X"));
    EXPECT_TRUE(fs::exists(out + "/sweep.md"));
    EXPECT_TRUE(fs::exists(out + "/sweep_tris.png"));
}

// Twenty-first probe: a link planted at sweep.csv was refused with exit 2 and one line, the same
// link at sweep.md with exit 1 and two lines (the script's refusal reported as its failure). Both
// are the same bad input; neither file behind the link is touched.
TEST(SweepMergeEdgeTest, ALinkAtAReportFileIsRefusedLikeOneAtTheTable) {
    const std::string dir = test::makeTempDir("merge-link");
    const std::string out = dir + "/sw";
    ASSERT_FALSE(test::fakeSweepRuns(kBin, smallFile(dir), out).is_null());
    std::ofstream(dir + "/victim.txt") << "keep";
    for (const char* name : {"sweep.csv", "sweep.md", "sweep.html"}) {
        fs::remove(out + "/" + name);
        fs::create_symlink(dir + "/victim.txt", out + "/" + name);
        const Ran r = runArgs(sweep({"merge", out, "--no-plots"}));
        EXPECT_EQ(r.rc, 2) << name << ": " << r.err;
        expectOneShortLine(r);
        EXPECT_NE(r.err.find(std::string(name) + ": "), std::string::npos) << r.err;
        fs::remove(out + "/" + name);
        std::ifstream victim(dir + "/victim.txt");
        EXPECT_EQ(std::string(std::istreambuf_iterator<char>(victim), {}), "keep") << name;
    }
}

// Twenty-third probe: a sweep folder whose runs/ was a link wrote its runs through it, replacing a
// user's files in the folder it named (exit 0). The runs go into the sweep's own folder only.
TEST(SweepMergeEdgeTest, ALinkedRunsFolderIsRefusedAndWhatItNamesIsLeftAlone) {
    const std::string dir = test::makeTempDir("sweep-linked-runs");
    const std::string out = dir + "/sw", victim = dir + "/elsewhere", file = smallFile(dir);
    ASSERT_FALSE(test::fakeSweepRuns(kBin, file, out).is_null());  // a sweep's folder, its runs kept elsewhere
    fs::remove_all(out + "/runs");
    fs::create_directories(victim);
    std::ofstream(victim + "/notes.log") << "keep";
    fs::create_directory_symlink(victim, out + "/runs");
    const Ran r = runArgs(sweep({"run", file, "--out", out}));
    EXPECT_EQ(r.rc, 2) << r.err;
    expectOneShortLine(r);
    EXPECT_NE(r.err.find("symbolic link"), std::string::npos) << r.err;
    size_t entries = 0;
    for (const auto& e : fs::directory_iterator(victim)) entries += e.path().filename() != "notes.log";
    EXPECT_EQ(entries, 0u) << "the sweep wrote into the folder the link names";
    std::ifstream kept(victim + "/notes.log");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), {}), "keep");
}

/// Sweeps that plan accepts at the edges of what it accepts; the report must take each of them.
struct EdgeSweep {
    const char* name;
    const char* axes;
};

const EdgeSweep kEdgeSweeps[] = {
    {"NoAxes", "[]"},
    {"OneValue", R"([{"name": "f", "values": {"frames": [2]}}])"},
    {"ValueScaleNumericLabels", R"([{"name": "f", "values": {"frames": [2, 3]}, "labels": ["1e3", "2.5"], "scale": "value"}])"},
    {"LabelsThatBreakCsvAndMarkdown", R"([{"name": "l", "values": {"frames": [2, 3, 4]},
        "labels": ["a,b", "say \"hi\" | there", "$\\frac{x}{$ ×é"]}])"},
    {"MarkupStringLabels", R"json([{"name": "n", "values": {"name": ["a*b](x)", "![c](etc-hostname) | d"]}}])json"},
    {"PixelsAndCategory", R"([{"name": "res", "values": {"resolution": [[64, 64], [96, 96]]}, "scale": "pixels"},
        {"name": "pcf", "values": {"algorithms.0.params.pcf": [0, 1]}}])"},
};

void PrintTo(const EdgeSweep& e, std::ostream* os) { *os << e.name << ": " << e.axes; }

class SweepMergeEdgeSweepTest : public ::testing::TestWithParam<EdgeSweep> {};

TEST_P(SweepMergeEdgeSweepTest, WhatPlanAcceptsTheReportAccepts) {
    const std::string dir = test::makeTempDir("merge-edge");
    Json s = test::smallSweep();
    s["axes"] = Json::parse(GetParam().axes);
    s["merge"] = {{"ratios", {"psv/shadow_map", "reference/psv"}}, {"stages", {"build", "total"}}};
    const std::string file = test::writeJson(dir + "/edge.sweep.json", s), out = dir + "/out";
    const Ran plan = runArgs(sweep({"plan", file}));
    ASSERT_EQ(plan.rc, 0) << plan.err;
    const Json p = test::fakeSweepRuns(kBin, file, out);
    ASSERT_FALSE(p.is_null());
    const Ran r = runArgs(sweep({"merge", out}));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(fs::exists(out + "/sweep.md")) << r.err;
    EXPECT_EQ(test::runIds(out + "/sweep.csv").size(), p["runs"].size());
}

INSTANTIATE_TEST_SUITE_P(Edges, SweepMergeEdgeSweepTest, ::testing::ValuesIn(kEdgeSweeps),
                         [](const auto& info) { return std::string(info.param.name); });

// ---- State: what counts as complete, and who may write a folder ----------------------------------

TEST(SweepStateTest, BrokenSummariesAreFailedRunsAndTheGoodOnesAreMerged) {
    const std::string dir = test::makeTempDir("merge-broken"), out = dir + "/out";
    const Json plan = test::fakeSweepRuns(kBin, smallFile(dir), out);
    ASSERT_EQ(plan["runs"].size(), 4u);
    auto summary = [&](size_t k) { return out + "/runs/" + plan["runs"][k]["id"].get<std::string>() + "/summary.json"; };
    const std::string good = test::readText(summary(0));
    std::ofstream(summary(1), std::ios::trunc) << good.substr(0, good.size() / 2); // truncated
    fs::remove(summary(2));
    fs::create_directory(summary(2)); // a directory in its place
    Json missing = test::fakeSummary(10);
    missing["algorithms"]["psv"]["time_ms"]["total"].erase("mean"); // a key the table needs
    missing["algorithms"]["reference"] = missing["algorithms"]["shadow_map"];  // the config's ids all there
    missing["algorithms"]["reference"]["algorithm"] = "reference";
    std::ofstream(summary(3), std::ios::trunc) << missing.dump();

    Ran r = runArgs(sweep({"merge", out, "--no-plots"}));
    EXPECT_EQ(r.rc, 1) << r.err;
    EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("at /algorithms/psv/time_ms/total/mean: missing"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("1 of 4 runs merged (3 failed)"), std::string::npos) << r.err;
    EXPECT_EQ(test::runIds(out + "/sweep.csv"), std::set<std::string>{plan["runs"][0]["id"].get<std::string>()});
    const Json merged = JsonNode::parseFile(out + "/plan.json");
    for (size_t k = 1; k < 4; ++k) EXPECT_EQ(merged["runs"][k]["status"], "failed") << k;
    EXPECT_TRUE(fs::exists(out + "/sweep.md"));

    // Empty, garbled, or not saying it is complete: not complete either.
    for (const std::string& text : {std::string(), std::string("{\"complete\": tru"), std::string("{\"complete\": false}")}) {
        std::ofstream(summary(1), std::ios::trunc) << text;
        r = runArgs(sweep({"merge", out, "--no-plots"}));
        EXPECT_EQ(r.rc, 1);
        EXPECT_NE(r.err.find("run 1 " + plan["runs"][1]["id"].get<std::string>()), std::string::npos) << r.err;
    }
}

// Eleventh probe: a summary.json whose psv results were renamed =HYPERLINK("http://evil","x") was
// taken as complete and its id written into sweep.csv, where a spreadsheet runs it. Results under
// an id the run's config does not give are no run's: a failed run, its rows not merged.
TEST(SweepStateTest, ResultsUnderAnIdTheConfigDoesNotGiveAreAFailedRun) {
    const std::string dir = test::makeTempDir("merge-forged-id"), out = dir + "/out";
    const Json plan = test::fakeSweepRuns(kBin, smallFile(dir), out);
    ASSERT_EQ(plan["runs"].size(), 4u);
    const std::string summary = out + "/runs/" + plan["runs"][1]["id"].get<std::string>() + "/summary.json";
    Json forged = JsonNode::parseFile(summary);
    forged["algorithms"]["=HYPERLINK(\"http://evil\",\"x\")"] = forged["algorithms"]["psv"];
    forged["algorithms"].erase("psv");
    std::ofstream(summary, std::ios::trunc) << forged.dump();
    // Twelfth probe: a 100,000-character stage name reached sweep.csv and crashed the plots.
    const std::string other = out + "/runs/" + plan["runs"][2]["id"].get<std::string>() + "/summary.json";
    Json longStage = JsonNode::parseFile(other);
    longStage["algorithms"]["psv"]["time_ms"][std::string(100000, 'S')] = {{"mean", 1.0}};
    std::ofstream(other, std::ios::trunc) << longStage.dump();
    // Fourteenth probe: an overflow of 1e300 (and a mismatch of 500 %, negative memory) was merged.
    const std::string third = out + "/runs/" + plan["runs"][3]["id"].get<std::string>() + "/summary.json";
    Json huge = JsonNode::parseFile(third);
    huge["algorithms"]["psv"]["overflow"] = 1e300;
    std::ofstream(third, std::ios::trunc) << huge.dump();
    const Ran r = runArgs(sweep({"merge", out, "--no-plots"}));
    EXPECT_EQ(r.rc, 1) << r.err;
    EXPECT_NE(r.err.find("which its config.resolved.json does not give"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("at /algorithms/psv/time_ms: holds the name \"SSSS"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("at /algorithms/psv/overflow"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("1 of 4 runs merged (3 failed)"), std::string::npos) << r.err;
    const std::string csv = test::readText(out + "/sweep.csv");
    EXPECT_EQ(csv.find("HYPERLINK"), std::string::npos);
    EXPECT_EQ(csv.find("SSSSSSSS"), std::string::npos);
}

// Seventeenth probe: a summary.json whose algorithm was rewritten (to a formula, which
// readRunSummary refuses, or to another algorithm's name) was merged as the run's.
TEST(SweepStateTest, ResultsOfAnotherAlgorithmThanTheConfigsAreAFailedRun) {
    const std::string dir = test::makeTempDir("merge-forged-algorithm"), out = dir + "/out";
    const Json plan = test::fakeSweepRuns(kBin, smallFile(dir), out);
    ASSERT_EQ(plan["runs"].size(), 4u);
    const std::string summary = out + "/runs/" + plan["runs"][1]["id"].get<std::string>() + "/summary.json";
    Json forged = JsonNode::parseFile(summary);
    forged["algorithms"]["psv"]["algorithm"] = "izb";
    std::ofstream(summary, std::ios::trunc) << forged.dump();
    const Ran r = runArgs(sweep({"merge", out, "--no-plots"}));
    EXPECT_EQ(r.rc, 1) << r.err;
    EXPECT_NE(r.err.find("names another algorithm for \"psv\" than its config.resolved.json (psv)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("3 of 4 runs merged (1 failed)"), std::string::npos) << r.err;
    EXPECT_EQ(test::readText(out + "/sweep.csv").find("izb"), std::string::npos);
}

TEST(SweepStateTest, AStaleErrorRecordBesideACompleteRunIsIgnoredAndRemoved) {
    const std::string dir = test::makeTempDir("stale-error"), file = smallFile(dir), out = dir + "/out";
    const Json plan = test::fakeSweepRuns(kBin, file, out);
    const std::string error = out + "/runs/" + plan["runs"][2]["id"].get<std::string>() + ".error.json";
    std::ofstream(error) << R"({"status": "exit code 1"})";
    Ran r = runArgs(sweep({"merge", out, "--no-plots"}));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("4 of 4 runs merged (0 failed)"), std::string::npos) << r.err;
    EXPECT_EQ(JsonNode::parseFile(out + "/plan.json")["runs"][2]["status"], "complete");
    // The next `sweep run` skips the run and removes the record.
    r = runArgs(sweep({"run", file, "--out", out}));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("removed its stale error record"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(error));
}

TEST(SweepStateTest, AnotherSweepIntoTheSameFolderIsRefused) {
    const std::string dir = test::makeTempDir("other-sweep"), out = dir + "/out";
    const std::string a = smallFile(dir);
    Json other = test::smallSweep();
    other["name"] = "other";
    other["axes"][1]["values"] = {{"algorithms.0.params.pcf", {0, 2}}};
    const std::string b = test::writeJson(dir + "/other.sweep.json", other);
    ASSERT_EQ(runArgs(sweep({"slurm", a, "--out", out})).rc, 0);
    const std::string before = test::readText(out + "/sweep.json");
    for (const char* command : {"run", "slurm"}) {
        const Ran r = runArgs(sweep({command, b, "--out", out}));
        EXPECT_EQ(r.rc, 2) << command << ": " << r.err;
        for (const std::string& part : {out + "/sweep.json", b, std::string("\"small\""), std::string("\"other\"")})
            EXPECT_NE(r.err.find(part), std::string::npos) << part << " in " << r.err;
        expectOneShortLine(r);
    }
    EXPECT_EQ(test::readText(out + "/sweep.json"), before);
    EXPECT_FALSE(fs::exists(out + "/runs/" + test::planOf(kBin, b)["runs"][0]["id"].get<std::string>()));
    // The same sweep again resumes, also from its snapshot, also when the folder was moved.
    EXPECT_EQ(runArgs(sweep({"slurm", a, "--out", out})).rc, 0);
    EXPECT_EQ(runArgs(sweep({"slurm", out + "/sweep.json", "--out", out})).rc, 0);
    fs::rename(out, dir + "/moved");
    EXPECT_EQ(runArgs(sweep({"slurm", a, "--out", dir + "/moved"})).rc, 0);
}

/// Holds an flock on `path` for the life of the object, as another sweep process would.
struct HeldLock {
    int fd;
    HeldLock(const std::string& path, int mode) : fd(open(path.c_str(), O_RDWR | O_CREAT, 0644)) { EXPECT_EQ(flock(fd, mode | LOCK_NB), 0); }
    ~HeldLock() { close(fd); }
};

TEST(SweepStateTest, ALockedFolderOrRunIsRefused) {
    const std::string dir = test::makeTempDir("sweep-lock"), file = smallFile(dir), out = dir + "/out";
    const Json plan = test::fakeSweepRuns(kBin, file, out);
    {
        HeldLock whole(out + "/sweep.lock", LOCK_EX); // a whole sweep running here
        for (const auto& extra : std::vector<std::vector<std::string>>{{}, {"--index", "1"}, {"--shard", "0/2"}}) {
            std::vector<std::string> argv = sweep({"run", file, "--out", out});
            argv.insert(argv.end(), extra.begin(), extra.end());
            const Ran r = runArgs(argv);
            EXPECT_EQ(r.rc, 2) << r.err;
            EXPECT_NE(r.err.find("sweep.lock"), std::string::npos) << r.err;
            expectOneShortLine(r);
        }
    }
    {
        HeldLock part(out + "/sweep.lock", LOCK_SH); // an array task running here
        EXPECT_EQ(runArgs(sweep({"run", file, "--out", out})).rc, 2) << "a whole sweep waits for the parts";
        EXPECT_EQ(runArgs(sweep({"run", file, "--out", out, "--index", "1"})).rc, 0) << "parts run side by side";
        // The task that holds run 1 makes another task for run 1 step aside.
        HeldLock run(out + "/runs/" + plan["runs"][1]["id"].get<std::string>() + ".sweep.lock", LOCK_EX);
        const Ran r = runArgs(sweep({"run", file, "--out", out, "--index", "1"}));
        EXPECT_EQ(r.rc, 2) << r.err;
        EXPECT_NE(r.err.find("BUSY"), std::string::npos) << r.err;
    }
    EXPECT_EQ(runArgs(sweep({"run", file, "--out", out})).rc, 0) << "the locks die with their holders";
}

/// The pids whose parent is `parent` (from /proc).
std::vector<pid_t> childrenOf(pid_t parent) {
    std::vector<pid_t> out;
    for (const auto& e : fs::directory_iterator("/proc")) {
        const std::string name = e.path().filename();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        std::ifstream in(e.path() / "stat");
        std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const size_t close = stat.rfind(')');
        if (close == std::string::npos) continue;
        std::istringstream rest(stat.substr(close + 2));
        char state;
        pid_t ppid;
        rest >> state >> ppid;
        if (ppid == parent) out.push_back(pid_t(std::stol(name)));
    }
    return out;
}

/// Whether `pid` is gone (or a zombie no one has reaped yet: it runs nothing).
bool gone(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
    std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t close = stat.rfind(')');
    return close == std::string::npos || stat.substr(close + 2, 1) == "Z";
}

TEST(SweepStateTest, KillingTheSweepAloneStopsItsRuns) {
    // Runs of many frames (a minute each), so that they still render when their sweep is killed.
    const std::string dir = test::makeTempDir("sweep-kill9"), file = smallFile(dir, {{"base", {{"frames", 20000}}}}), out = dir + "/out";
    const pid_t sweepPid = fork();
    if (sweepPid == 0) {
        const int log = open((dir + "/sweep.log").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(log, 1);
        dup2(log, 2);
        execl(kBin.c_str(), kBin.c_str(), "sweep", "run", file.c_str(), "--out", out.c_str(), "--jobs", "2", static_cast<char*>(nullptr));
        _exit(127);
    }
    // Wait until both runs are in flight, then SIGKILL the sweep process only (no process group):
    // it gets no chance to stop them itself.
    std::vector<pid_t> runs;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (runs.size() < 2 && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        runs = childrenOf(sweepPid);
    }
    ASSERT_EQ(runs.size(), 2u) << test::readText(dir + "/sweep.log");
    std::this_thread::sleep_for(std::chrono::milliseconds(500)); // the runs are rendering
    kill(sweepPid, SIGKILL);
    waitpid(sweepPid, nullptr, 0);
    const auto stop = std::chrono::steady_clock::now() + std::chrono::seconds(8);
    for (pid_t run : runs) {
        while (!gone(run) && std::chrono::steady_clock::now() < stop) std::this_thread::sleep_for(std::chrono::milliseconds(20));
        EXPECT_TRUE(gone(run)) << "run process " << run << " outlived its sweep";
        if (!gone(run)) kill(run, SIGKILL); // not left rendering after the test
    }
    // Stopped, not finished: no run folder, no partial one left.
    for (const auto& e : fs::directory_iterator(out + "/runs"))
        EXPECT_FALSE(e.is_directory()) << e.path() << " is left";
    // The folder's lock died with the sweep (the runs never held it).
    const int fd = open((out + "/sweep.lock").c_str(), O_RDWR);
    EXPECT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
    close(fd);
}

TEST(SweepStateTest, BrokenResultsAreRunAgain) {
    const std::string dir = test::makeTempDir("sweep-rerun"), file = smallFile(dir), out = dir + "/out";
    Ran r = runArgs(sweep({"run", file, "--out", out, "--jobs", "2"}));
    ASSERT_EQ(r.rc, 0) << r.err;
    const Json plan = test::planOf(kBin, file);
    const std::string one = out + "/runs/" + plan["runs"][0]["id"].get<std::string>() + "/summary.json";
    const std::string two = out + "/runs/" + plan["runs"][3]["id"].get<std::string>() + "/summary.json";
    std::ofstream(one, std::ios::trunc) << "{\"algorithms\": {";
    std::ofstream(two, std::ios::trunc);
    r = runArgs(sweep({"run", file, "--out", out, "--jobs", "2"}));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 7) << "2 notes, 4 run lines, the total:\n" << r.err;
    size_t again = 0;
    for (size_t pos = r.err.find("running it again"); pos != std::string::npos; pos = r.err.find("running it again", pos + 1)) ++again;
    EXPECT_EQ(again, 2u) << r.err;
    EXPECT_TRUE(JsonNode::parseFile(one)["complete"].get<bool>());
    EXPECT_EQ(runArgs(sweep({"merge", out, "--no-plots"})).rc, 0);
}

// ---- Memory --------------------------------------------------------------------------------------

TEST(SweepMemoryTest, ManyRunsOverALargeBaseShareIt) {
    const std::string dir = test::makeTempDir("sweep-memory");
    // A base of about 1 MB: a camera path of many keyframes (a recorded fly-through). As JSON in
    // memory that is some 10 MB, so a copy of the base per run would show at once.
    Json base = test::smallSweep()["base"];
    Json keys = Json::array();
    for (int k = 0; k < 10000; ++k)
        keys.push_back({{"time", k * 0.01}, {"position", {std::sin(k * 0.01) * 5, 3.0, std::cos(k * 0.01) * 5}}, {"target", {0, 0, 0}}});
    base["camera"] = {{"path", {{"keyframes", keys}}}};
    auto sweepOf = [&](int runs, const std::string& name) {
        Json frames = Json::array();
        for (int f = 1; f <= runs; ++f) frames.push_back(f);
        Json s = {{"name", name}, {"base", base}, {"axes", {{{"name", "frames"}, {"values", {{"frames", frames}}}}}}};
        return test::writeJson(dir + "/" + name + ".sweep.json", s);
    };
    const std::string one = sweepOf(1, "one"), many = sweepOf(16, "many");
    const Ran single = runArgs(sweep({"plan", one}));
    ASSERT_EQ(single.rc, 0) << single.err;
    // The whole sweep in one process (plan), and what an array task does (`sweep run --index K`, here
    // of a run that is complete already, so that nothing renders).
    const Ran plan = runArgs(sweep({"plan", many}));
    ASSERT_EQ(plan.rc, 0) << plan.err;
    std::istringstream rows(plan.out);
    std::string id;
    for (std::string row; std::getline(rows, row);)
        if (row.rfind("12\t", 0) == 0) id = row.substr(3, 12); // index, tab, id
    ASSERT_EQ(id.size(), 12u) << plan.out;
    const std::string out = dir + "/out";
    fs::create_directories(out + "/runs");
    ASSERT_TRUE(test::fakeRunFolder(kBin, many, 12, out + "/runs/" + id, test::fakeSummary(10)));
    const Ran task = runArgs(sweep({"run", many, "--out", out, "--index", "12"}));
    ASSERT_EQ(task.rc, 0) << task.err;
    EXPECT_NE(task.err.find("skip"), std::string::npos) << task.err;
    // Sixteen copies of the base would take some 90 MB (5.5 MB of JSON nodes each) more than one run
    // does; shared, about one.
    for (const Ran* r : {&plan, &task})
        EXPECT_LT(r->maxRssKiB, single.maxRssKiB + 40 * 1024) << "one run: " << single.maxRssKiB << " KiB; sixteen: " << r->maxRssKiB << " KiB";
}

} // namespace
} // namespace shadowlab
