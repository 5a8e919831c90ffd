// User text is data: the one rule for text that reaches a report (framework/core/Text.h), the
// Markdown it is written as, and each way a hostile or careless config reached a report, a plan or
// standard output before, kept as a test.
#include "framework/core/Text.h"
#include "HostileInputs.h"
#include "SweepTestData.h"
#include "TestSupport.h"

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;
const std::string kBin = SHADOWLAB_BINARY;
const std::string kSmoke = std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json";

struct Result {
    int rc;
    std::string out;
};

/// Runs `args` (quoted for the shell by the caller: test-made paths and fixed text only).
Result shell(const std::string& args) {
    std::string out;
    const int rc = test::runCommand(args + " 2>&1", out);
    return {rc, out};
}

void expectOneLineNaming(const Result& r, const std::string& path) {
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find(path), std::string::npos) << r.out;
    EXPECT_LE(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
}

TEST(UserTextTest, MarkdownLiteralEscapesEveryMarkupCharacter) {
    EXPECT_EQ(markdownLiteral("[click me](javascript:alert`1`)"), "\\[click me\\]\\(javascript\\:alert\\`1\\`\\)");
    EXPECT_EQ(markdownLiteral("![x](/etc/hostname)"), "\\!\\[x\\]\\(/etc/hostname\\)");
    EXPECT_EQ(markdownLiteral("a|b"), "a\\|b");
    EXPECT_EQ(markdownLiteral("psv_stack"), "psv_stack") << "intraword '_' is never emphasis";
    EXPECT_EQ(markdownLiteral("_x_"), "\\_x\\_");
    EXPECT_EQ(markdownLiteral("a\nb"), "a\xEF\xBF\xBD" "b") << "no line break survives";
    EXPECT_EQ(markdownLiteral("<!--"), "\\<\\!\\-\\-");
}

TEST(UserTextTest, TheRuleRefusesInvisibleAndLineBreakingText) {
    EXPECT_EQ(userTextProblem("engine orbit, 512² [ZFAIL]"), "");
    EXPECT_NE(userTextProblem("probe\n<!--"), "");
    EXPECT_NE(userTextProblem(std::string("a\0b", 3)), "");
    EXPECT_NE(userTextProblem("abc\xE2\x80\xAE" "def"), "") << "U+202E right-to-left override";
    EXPECT_NE(userTextProblem("a\xE2\x81\xA6" "b"), "") << "U+2066 isolate";
    EXPECT_NE(userTextProblem("a\xC2\x85" "b"), "") << "U+0085, a C1 line break";
    EXPECT_NE(userTextProblem("\xff"), "");
    EXPECT_NE(userTextProblem(std::string(201, 'n')), "");
    // Every other invisible format character (a probe's finds): tags, soft hyphen, Mongolian vowel
    // separator, interlinear annotation, Hangul filler.
    for (const char* s : {"hi\xF3\xA0\x81\x81", "a\xC2\xAD" "b", "a\xE1\xA0\x8E" "b", "a\xEF\xBF\xB9" "b", "a\xE3\x85\xA4" "b"})
        EXPECT_NE(userTextProblem(s), "") << s;
    EXPECT_EQ(pathTextProblem("results/engine orbit " + std::string(300, 'n')), "") << "a path has no length bound";
    EXPECT_NE(pathTextProblem("r\xE2\x80\xAE" "abc"), "");
    EXPECT_NE(pathTextProblem("z\xE2\x80\x8B" "w"), "");
}

// An error line echoes what it refuses masked: no U+2028 or U+0085 that ends the line for a
// Unicode-aware reader, no U+202E that reverses the terminal's text.
TEST(UserTextTest, ErrorLinesMaskTheInvisibleCharactersTheyRefuse) {
    for (const std::string& name : {std::string("a\\u2028b"), std::string("a\\u0085b"), std::string("abc\\u202edef")}) {
        const Result r = shell(kBin + " validate " + kSmoke + " --set 'name=\"" + name + "\"'");
        expectOneLineNaming(r, "/name");
        for (const char* raw : {"\xE2\x80\xA8", "\xC2\x85", "\xE2\x80\xAE"}) EXPECT_EQ(r.out.find(raw), std::string::npos) << r.out;
    }
    const Result key = shell(kBin + " validate " + kSmoke + " --set 'x\xE2\x80\xAE=1'");
    EXPECT_EQ(key.rc, 2) << key.out;
    EXPECT_EQ(key.out.find("\xE2\x80\xAE"), std::string::npos) << key.out;
}

// A config whose path is not UTF-8 cannot be named in summary.json: refused at validation, naming
// the file, never after a whole run.
TEST(UserTextTest, AConfigPathThatIsNotUtf8IsRefusedAtValidation) {
    const std::string file = test::makeTempDir("user-text-cfgpath") + "/c\xff.json";
    fs::copy_file(kSmoke, file);
    const Result r = shell(kBin + " validate '" + file + "'");
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find("not valid UTF-8"), std::string::npos) << r.out;
}

// What validate accepts, run runs: an output.dir that no run can use ("/", a file, a device) is
// refused by validate at /output/dir.
TEST(UserTextTest, ValidateRefusesAnOutputPlaceNoRunCanUse) {
    for (const char* dir : {"/", "/dev/null", "/etc/hostname"}) {
        const Result r = shell(kBin + " validate " + kSmoke + " --set 'output.dir=\"" + dir + "\"'");
        expectOneLineNaming(r, "/output/dir");
    }
    // Twentieth probe: names the file system cannot hold once a run adds its suffixes validated,
    // and run stopped with "File name too long".
    const std::string base = test::makeTempDir("user-text-long");
    std::string deep = base;
    while (deep.size() < 4000) deep += "/" + std::string(100, 'd');
    for (const std::string& dir : {base + "/" + std::string(245, 'n'), deep}) {
        const Result r = shell(kBin + " validate " + kSmoke + " --set 'output.dir=\"" + dir + "\"'");
        expectOneLineNaming(r, "/output/dir");
    }
}

// Reproduction 4 (and 12's non-UTF-8 name): a name that is not one line of plain text is bad input.
TEST(UserTextTest, ANameThatIsNotPlainTextIsRefusedAtItsPath) {
    for (const std::string& name : {std::string("probe\\n<!--"), std::string("a\\u202eb"), std::string("nul\\u0000"),
                                    std::string(300, 'n')}) {
        const Result r = shell(kBin + " validate " + kSmoke + " --set 'name=\"" + name + "\"'");
        expectOneLineNaming(r, "/name");
    }
}

// Reproduction 12's other half: a config whose folder is not UTF-8 names an output folder that no
// summary.json can hold; refused at validation, not after the run.
TEST(UserTextTest, AnOutputFolderThatIsNotUtf8IsRefusedAtValidation) {
    const std::string dir = test::makeTempDir("user-text-utf8") + "/cfg\xff";
    fs::create_directories(dir);
    Json c = Json::parse(R"({"name": "n", "resolution": [32, 32], "frames": 1, "algorithms": [{"algorithm": "shadow_map"}],
        "camera": {"position": [0, 3, 5], "target": [0, 0, 0]}, "light": {"position": [1, 4, 1]},
        "scene": {"objects": [{"procedural": "plane", "size": [6, 6]}]}})");
    const std::string file = test::writeJson(dir + "/c.json", c);
    const Result r = shell(kBin + " validate '" + file + "'");
    // The config's own path is the first thing refused (its folder names the default output).
    expectOneLineNaming(r, "not valid UTF-8");
}

// Reproductions 1-3: the name is shown as text, never read as a link or an image, in report.md and
// in the self-contained report.html.
TEST(UserTextTest, AMarkdownNameRendersAsTextInTheReport) {
    const std::string dir = test::makeTempDir("user-text-report");
    const Result r = shell(kBin + " run " + kSmoke + " --out " + dir + "/out --no-progress" +
                           " --set 'name=\"[click me](javascript:alert`1`) ![x](/etc/hostname) ![y](/dev/zero)\"'" +
                           " --set resolution=[32,32] --set frames=1 --set warmup_frames=0 --set output.images_at_frames=[0]" +
                           " --set 'algorithms=[{\"algorithm\": \"psv\"}]' --set expect=[]");
    ASSERT_EQ(r.rc, 0) << r.out;
    std::string md, html;
    ASSERT_EQ(test::runCommand("cat " + dir + "/out/report.md", md), 0);
    ASSERT_EQ(test::runCommand("cat " + dir + "/out/report.html", html), 0);
    EXPECT_NE(md.find("# \\[click me\\]\\(javascript\\:alert"), std::string::npos) << md.substr(0, 400);
    EXPECT_EQ(html.find("href=\"javascript"), std::string::npos);
    // The only links are the run's own images (the labelled heat maps).
    size_t anchors = 0, own = 0;
    for (size_t at = html.find("<a "); at != std::string::npos; at = html.find("<a ", at + 1), ++anchors)
        own += html.compare(at, 16, "<a href=\"images/") == 0 ? 1 : 0;
    EXPECT_EQ(anchors, own);
    // Every embedded image is a PNG the run made; /etc/hostname would be text/plain or octet-stream.
    EXPECT_EQ(html.find("data:text"), std::string::npos);
    EXPECT_EQ(html.find("data:application"), std::string::npos);
    EXPECT_NE(html.find("[click me](javascript:alert`1`)"), std::string::npos) << "the name, as typed, is the title";
}

// Reproduction 8: what a command prints reaches standard output, or the command fails.
TEST(UserTextTest, AFullOrClosedStandardOutputIsAnError) {
    for (const std::string& command : {std::string(" list --json"), std::string(" validate ") + kSmoke,
                                       std::string(" plan ") + kSmoke}) {
        std::string out;
        EXPECT_EQ(test::runCommand(kBin + command + " > /dev/full 2>/dev/null", out), 2) << command;
        EXPECT_EQ(test::runCommand(kBin + command + " >&- 2>/dev/null", out), 2) << command;
    }
}

// Seventh probe: a pipe whose reader has gone ended the process by SIGPIPE, without a word.
TEST(UserTextTest, APipeWhoseReaderHasGoneIsAnError) {
    for (const char* command : {"list", "info"}) {
        int fds[2];
        ASSERT_EQ(::pipe(fds), 0);
        ::close(fds[0]);
        const pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            ::dup2(fds[1], 1);
            const int null = ::open("/dev/null", O_WRONLY);
            ::dup2(null, 2);
            ::execl(kBin.c_str(), kBin.c_str(), command, "--json", static_cast<char*>(nullptr));
            ::_exit(127);
        }
        ::close(fds[1]);
        int status = 0;
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        EXPECT_TRUE(WIFEXITED(status)) << command << ": ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
        if (WIFEXITED(status)) EXPECT_EQ(WEXITSTATUS(status), 2) << command;
    }
}

// Reproduction 9: a rule between parameters is part of validation, with its JSON path.
TEST(UserTextTest, ParameterRulesAreValidated) {
    for (const char* walk : {"stackless", "hybrid"}) {
        const Result r = shell(kBin + " validate " + kSmoke + " --set algorithms.1.params.traversal=" + walk +
                               " --set algorithms.1.params.transparency=true");
        expectOneLineNaming(r, "/algorithms/1/params/traversal");
    }
    const Result ok = shell(kBin + " validate " + kSmoke + " --set algorithms.1.params.traversal=stack" +
                            " --set algorithms.1.params.transparency=true > /dev/null");
    EXPECT_EQ(ok.rc, 0) << ok.out;
    const Result lanes = shell(kBin + " validate " + kSmoke + " --set algorithms.4.params.lanes=5");
    expectOneLineNaming(lanes, "/algorithms/4/params/lanes");
}

// Reproduction 10: merge entries name ids the sweep's runs have.
TEST(UserTextTest, MergeIdsAreCheckedAgainstTheRuns) {
    const std::string dir = test::makeTempDir("user-text-merge");
    Json s = test::smallSweep();
    s["merge"] = {{"ratios", {"psv/shadow_map", "psv/absent"}}};
    const std::string file = test::writeJson(dir + "/ratio.sweep.json", s);
    expectOneLineNaming(shell(kBin + " sweep plan " + file), "/merge/ratios/1");
    s["merge"] = {{"paper", {{"source", "a paper"}, {"times_ms", {{"psv", 1.0}, {"psw", 2.0}}}}}};
    const std::string paper = test::writeJson(dir + "/paper.sweep.json", s);
    expectOneLineNaming(shell(kBin + " sweep plan " + paper), "/merge/paper/times_ms/psw");
}

// Reproduction 11: a sweep inside a complete run's output is refused before anything is written.
TEST(UserTextTest, ASweepInsideARunsOutputIsRefusedUpFront) {
    const std::string dir = test::makeTempDir("user-text-nest");
    fs::create_directories(dir + "/A");
    test::writeJson(dir + "/A/summary.json", Json{{"complete", true}});
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep());
    const Result r = shell(kBin + " sweep run " + file + " --out " + dir + "/A/sw");
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find("inside"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir + "/A/sw"));
    // Into the run's output itself: refused before anything is written there.
    const Result into = shell(kBin + " sweep run " + file + " --out " + dir + "/A");
    EXPECT_EQ(into.rc, 2) << into.out;
    EXPECT_NE(into.out.find("a run's output"), std::string::npos) << into.out;
    EXPECT_FALSE(fs::exists(dir + "/A/runs"));
    EXPECT_FALSE(fs::exists(dir + "/A/sweep.json"));
}

// Reproduction 12: a long path on an object that a grid copies is held once, not once per copy (a
// 30×30 grid of a 20,000-key path took 1.78 GB of resident memory; validate builds the scene). The
// bound is that figure's half with room for a sanitizer's quarantine: a copy per instance is past it.
TEST(UserTextTest, AGridOfALongPathHoldsThePathOnce) {
    const std::string dir = test::makeTempDir("user-text-path");
    Json keys = Json::array();
    for (int k = 0; k < 20000; ++k) keys.push_back({{"time", k * 0.01}, {"translate", {0.001 * k, 0, 0}}});
    Json c = Json::parse(std::string(R"({"resolution": [32, 32], "frames": 2, "algorithms": [{"algorithm": "shadow_map"}],
        "camera": {"position": [0, 30, 40], "target": [0, 0, 0]}, "light": {"position": [5, 40, 5]},
        "scene": {"objects": [{"procedural": "plane", "size": [80, 80]}]}})"));
    c["scene"]["objects"].push_back({{"procedural", "grid"}, {"count", {30, 1, 30}}, {"spacing", {2, 2, 2}},
                                     {"object", {{"procedural", "sphere"}, {"radius", 0.5}, {"triangles", 20},
                                                 {"path", {{"keyframes", keys}}}}}});
    const std::string file = test::writeJson(dir + "/path.json", c);
    const Result r = shell(kBin + " validate " + file + " > /dev/null");
    EXPECT_EQ(r.rc, 0) << r.out;
    rusage children{};
    ASSERT_EQ(getrusage(RUSAGE_CHILDREN, &children), 0);
    EXPECT_LT(children.ru_maxrss, 900L * 1024) << "KiB at the peak of the largest child so far";
}

// A glTF path that names a FIFO or a device is refused for what it is, not as "not found".
TEST(UserTextTest, AGltfThatIsNotARegularFileIsNamedSo) {
    for (const char* path : {"/dev/zero", "/dev/null"}) {
        const Result r = shell(kBin + " validate " + kSmoke + " --set 'scene.objects.0={\"gltf\": \"" + path + "\"}'");
        expectOneLineNaming(r, "/scene/objects/0/gltf");
        EXPECT_NE(r.out.find("not a regular file"), std::string::npos) << r.out;
    }
}

// Probe 25: a path's text was checked after "x/\0/../y" folded to "y", and a glTF path not at
// all, so a NUL cut the name short where the file was opened (a config read another file than the
// one it names) and a line break or bidi mark reached config.resolved.json.
TEST(UserTextTest, APathIsCheckedAsWrittenBeforeItIsFolded) {
    const std::string gltf = test::makeTempDir("user-text-gltf") + "/m.gltf";
    std::ofstream(gltf) << test::triangleGltf();
    for (const char* tail : {"\\u0000", "\\n", "\\u202e"}) {
        const Result out = shell(kBin + " validate " + kSmoke + " --set 'output.dir=\"o" + tail + "/../target\"'");
        expectOneLineNaming(out, "/output/dir");
        const Result scene = shell(kBin + " validate " + kSmoke + " --set 'scene.objects.0={\"gltf\": \"" + gltf + tail + ".x\"}'");
        expectOneLineNaming(scene, "/scene/objects/0/gltf");
        EXPECT_EQ(scene.out.find("valid"), std::string::npos) << scene.out;
    }
}

// Probe 25: a bad value a --set gave was blamed on the config file alone, which holds another.
TEST(UserTextTest, AnErrorInASetValueNamesTheSet) {
    const Result frames = shell(kBin + " validate " + kSmoke + " --set frames=");
    expectOneLineNaming(frames, "smoke.json: at /frames: from --set frames=: ");
    const Result params = shell(kBin + " validate " + kSmoke + " --set 'algorithms.0.params=[1]'");
    expectOneLineNaming(params, "at /algorithms/0/params: from --set algorithms.0.params=[1]: ");
    // Probe 26: an error at a key the --set made, above the value it set.
    const Json written = Json::parse(std::ifstream(kSmoke));
    ASSERT_FALSE(written["light"].contains("foo"));
    const Result made = shell(kBin + " validate " + kSmoke + " --set light.foo.bar=1");
    expectOneLineNaming(made, "at /light/foo: from --set light.foo.bar=1: ");
    // A path index spelled with a leading zero is no index (it was the same element as "0" under
    // another name, so a --set twice went unnoticed).
    expectOneLineNaming(shell(kBin + " validate " + kSmoke + " --set scene.objects.00.size=[2,2]"), "no element 00");
    // An error elsewhere stays the file's.
    const Result other = shell(kBin + " validate " + kSmoke + " --set frames=2 --set resolution=[0,4]");
    expectOneLineNaming(other, "from --set resolution=[0,4]");
    EXPECT_EQ(other.out.find("frames"), std::string::npos) << other.out;
}

// Reproduction 10, its other half: a stage or counter no run measured is named when merging,
// after sweep.csv is written.
TEST(UserTextTest, MergeStagesAreCheckedAgainstWhatTheRunsMeasured) {
    const std::string dir = test::makeTempDir("user-text-stages");
    Json s = test::smallSweep();
    s["merge"] = {{"ratios", {"psv/shadow_map"}}, {"stages", {"build", "biuld"}}};
    const std::string file = test::writeJson(dir + "/stages.sweep.json", s), out = dir + "/out";
    ASSERT_FALSE(test::fakeSweepRuns(kBin, file, out).is_null());
    // Probe 26: a previous merge's report stayed beside the new tables of a merge that failed.
    for (const char* old : {"sweep.md", "sweep.html", "sweep_size.png", "sweep_stages.png"}) std::ofstream(out + "/" + old) << "old";
    expectOneLineNaming(shell(kBin + " sweep merge " + out), "/merge/stages/1");
    EXPECT_TRUE(fs::exists(out + "/sweep.csv"));
    for (const char* old : {"sweep.md", "sweep.html", "sweep_size.png", "sweep_stages.png"}) EXPECT_FALSE(fs::exists(out + "/" + old)) << old;
}

// Probe 26: a size axis whose runs all hold one triangle count gave a fit table of no rows and
// no word; it says why now.
TEST(UserTextTest, AFitTableWithNothingToFitSaysSo) {
    const std::string dir = test::makeTempDir("user-text-no-fit");
    Json s = test::smallSweep();
    s["axes"] = Json::parse(R"([{"name": "pcf", "values": {"algorithms.0.params.pcf": [0, 1]}, "scale": "triangles"}])");
    const std::string file = test::writeJson(dir + "/nofit.sweep.json", s), out = dir + "/out";
    ASSERT_FALSE(test::fakeSweepRuns(kBin, file, out).is_null());
    // Both runs of one size, as the axis (pcf) leaves the scene alone.
    for (const auto& run : fs::directory_iterator(out + "/runs")) {
        if (!run.is_directory()) continue;
        Json summary = Json::parse(std::ifstream(run.path() / "summary.json"));
        summary["triangles"] = 1000;
        std::ofstream(run.path() / "summary.json") << summary.dump();
    }
    const Result r = shell(kBin + " sweep merge " + out + " --no-plots");
    ASSERT_EQ(r.rc, 0) << r.out;
    std::stringstream md;
    md << std::ifstream(out + "/sweep.md").rdbuf();
    EXPECT_NE(md.str().find("## Power-law fits along `pcf`"), std::string::npos) << md.str();
    EXPECT_NE(md.str().find("No fit: no group of runs holds two points of different n"), std::string::npos) << md.str();
}

// Probe 26: a TMPDIR holding a line break refused every run of a valid sweep at `plan --check`,
// as if the runs were at fault; the check's scratch folder goes to /tmp then.
TEST(UserTextTest, AnUnusableTmpdirIsNotASweepsFault) {
    const std::string dir = test::makeTempDir("user-text-tmpdir");
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::twoRunSweep());
    const Result r = shell("TMPDIR=\"$(printf '" + dir + "/t\\nx')\" " + kBin + " sweep plan " + file + " --check");
    EXPECT_EQ(r.rc, 0) << r.out;
}

TEST(UserTextTest, AnEmptyOutIsRefused) {
    const Result r = shell(kBin + " run " + kSmoke + " --out ''");
    EXPECT_EQ(r.rc, 2) << r.out;
    EXPECT_NE(r.out.find("--out"), std::string::npos) << r.out;
}

// ---- A second probe's findings (each a reproduction kept as a test) --------------------------------

std::string readText(const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// A tiny config (one algorithm, a small frame) for the output-place cases: they fail before any frame.
std::string tinyConfig(const std::string& dir) {
    Json c = test::smallSweep()["base"];
    c["name"] = "tiny";
    c["frames"] = 1;
    c["algorithms"] = Json::array({Json{{"algorithm", "shadow_map"}}});
    c["reference"] = false;
    return test::writeJson(dir + "/tiny.json", c);
}

// D1: a sweep's name forms its default folder results/NAME, so it must be one path component, as
// a run's name must ("../../x" wrote the sweep outside results/).
TEST(UserTextTest, ASweepNameThatIsAPathIsRefused) {
    const std::string dir = test::makeTempDir("user-text-sweep-name");
    for (const char* name : {"../../esc_sweep", "..", ".", "a/b"}) {
        Json sw = test::smallSweep();
        sw["name"] = name;
        const std::string file = test::writeJson(dir + "/s.sweep.json", sw);
        expectOneLineNaming(shell(kBin + " sweep plan " + file), "/name");
    }
    EXPECT_FALSE(fs::exists(dir + "/../esc_sweep"));
}

// D2: a sweep's folder is checked as a run's is, and must be empty or a sweep's: the working
// directory, a symbolic link and a folder of the user's were adopted, and `sweep merge` then wrote
// over the user's own sweep.md, sweep.csv and plan.json there.
TEST(UserTextTest, ASweepFolderIsEmptyOrASweepsOwn) {
    const std::string dir = test::makeTempDir("user-text-sweep-place");
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep());
    fs::create_directories(dir + "/mine");
    for (const char* name : {"sweep.md", "sweep.csv", "plan.json", "file.txt"}) std::ofstream(dir + "/mine/" + name) << "keep\n";
    fs::create_directories(dir + "/target");
    fs::create_symlink(dir + "/target", dir + "/link");
    fs::create_directories(dir + "/cwd/inner");
    for (const std::string& out : {dir + "/mine", dir + "/link"}) {
        const Result r = shell(kBin + " sweep run " + file + " --out " + out);
        EXPECT_EQ(r.rc, 2) << out << ": " << r.out;
        EXPECT_LE(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    }
    for (const char* out : {".", ".."}) {
        const Result r = shell("cd " + dir + "/cwd/inner && " + kBin + " sweep run " + file + " --out " + out);
        EXPECT_EQ(r.rc, 2) << out << ": " << r.out;
    }
    for (const char* name : {"sweep.md", "sweep.csv", "plan.json", "file.txt"}) EXPECT_EQ(readText(dir + "/mine/" + name), "keep\n");
    EXPECT_FALSE(fs::exists(dir + "/mine/sweep.json"));
    EXPECT_FALSE(fs::exists(dir + "/target/sweep.json"));
    EXPECT_FALSE(fs::exists(dir + "/cwd/sweep.json"));
    EXPECT_FALSE(fs::exists(dir + "/cwd/inner/sweep.json"));
}

// D3, D4: nothing goes inside a sweep but its own runs: a sweep into another's runs/xx (it left a
// sweep skeleton there), a run into a runs/NAME the sweep never planned (it was accepted).
TEST(UserTextTest, NothingButASweepsOwnRunsGoesInsideIt) {
    const std::string dir = test::makeTempDir("user-text-sweep-nest");
    fs::create_directories(dir + "/sw/runs");
    std::ofstream(dir + "/sw/sweep.json") << "{}\n";
    const std::string file = test::writeJson(dir + "/s.sweep.json", test::smallSweep());
    expectOneLineNaming(shell(kBin + " sweep run " + file + " --out " + dir + "/sw/runs/xx"), "sweep");
    EXPECT_FALSE(fs::exists(dir + "/sw/runs/xx"));
    const std::string config = tinyConfig(dir);
    expectOneLineNaming(shell(kBin + " validate " + config + " --set output.dir=" + dir + "/sw/runs/abc"), "sweep");
    // The sweep's own slot, where it wrote the run's config: accepted for that config only, as it
    // is (third probe: a run of another config, or changed by --set, was taken there too).
    Json slotConfig = Json::parse(readText(config));
    slotConfig["output"]["dir"] = dir + "/sw/runs/abc";
    test::writeJson(dir + "/sw/runs/abc.config.json", slotConfig);
    const Result ok = shell(kBin + " validate " + dir + "/sw/runs/abc.config.json");
    EXPECT_EQ(ok.rc, 0) << ok.out;
    expectOneLineNaming(shell(kBin + " validate " + config + " --set output.dir=" + dir + "/sw/runs/abc"), "takes only a run of its own config");
    expectOneLineNaming(shell(kBin + " validate " + dir + "/sw/runs/abc.config.json --set frames=2"), "takes only a run of its own config");
}

// D7: DIR.lock holds "shadowlab-lock PID"; a user's file there, even an empty one or one holding
// only digits, is refused and left as it was (it was taken for a stale lock and deleted).
TEST(UserTextTest, AUsersFileAtTheLockIsNeverTakenForALock) {
    const std::string dir = test::makeTempDir("user-text-lock");
    const std::string config = tinyConfig(dir);
    for (const char* content : {"", "1", "0", "99999999999999999999"}) {
        std::ofstream(dir + "/out.lock") << content;
        const Result r = shell(kBin + " run " + config + " --out " + dir + "/out --no-progress");
        EXPECT_EQ(r.rc, 2) << "\"" << content << "\": " << r.out;
        EXPECT_EQ(readText(dir + "/out.lock"), content);
        EXPECT_FALSE(fs::exists(dir + "/out"));
    }
}

// D8: --force replaces only a directory marked as a run's output (.shadowlab-output, or the
// summary.json a run writes), not one that merely holds files of those names: a folder with a
// directory named summary.json, or an empty config.resolved.json, was replaced with its contents.
TEST(UserTextTest, ForceNeedsARealOutputNotItsFileNames) {
    const std::string dir = test::makeTempDir("user-text-force");
    const std::string config = tinyConfig(dir);
    fs::create_directories(dir + "/a/summary.json");
    std::ofstream(dir + "/a/precious.txt") << "keep\n";
    fs::create_directories(dir + "/b");
    std::ofstream(dir + "/b/config.resolved.json") << "{}\n";
    std::ofstream(dir + "/b/precious.txt") << "keep\n";
    fs::create_directories(dir + "/c"); // a third probe: an empty JSON object is nobody's summary
    std::ofstream(dir + "/c/summary.json") << "{}\n";
    std::ofstream(dir + "/c/precious.txt") << "keep\n";
    for (const char* name : {"a", "b", "c"}) {
        const Result r = shell(kBin + " run " + config + " --out " + dir + "/" + name + " --force --no-progress");
        expectOneLineNaming(r, name);
        EXPECT_EQ(readText(dir + "/" + name + "/precious.txt"), "keep\n");
    }
}

// D6: an area light's sides are bounded as every position is (sample points at ±5e37 validated,
// ran, and gave a silently wrong line_space image).
TEST(UserTextTest, AnAreaLightsSizeIsBounded) {
    const std::string dir = test::makeTempDir("user-text-area");
    const std::string config = tinyConfig(dir);
    expectOneLineNaming(shell(kBin + " validate " + config + " --set light.type=area --set 'light.size=[1e38,1e38]'"),
                        "/light/size");
}

} // namespace
} // namespace shadowlab
