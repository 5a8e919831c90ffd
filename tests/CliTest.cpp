// The command line as a user meets it: exit codes, one-line errors, and malformed scene files.
#include "framework/core/JsonNode.h"
#include "tests/HostileInputs.h"
#include "tests/SweepTestData.h"
#include "tests/TestSupport.h"

#include <algorithm>

#include <filesystem>
#include <fstream>

namespace shadowlab {
namespace {

std::string bin() { return SHADOWLAB_BINARY; }

TEST(CliTest, HelpAndListSucceed) {
    std::string out;
    EXPECT_EQ(test::runCommand(bin() + " --help", out), 0);
    EXPECT_NE(out.find("shadowlab run CONFIG.json"), std::string::npos);
    EXPECT_NE(out.find("shadowlab sweep run SWEEP.json"), std::string::npos);
    EXPECT_EQ(test::runCommand(bin() + " list", out), 0);
    EXPECT_NE(out.find("shadow_map"), std::string::npos);
    EXPECT_NE(out.find("reference"), std::string::npos);
}

// Eighteenth probe: `--version --bogus` printed the version and exited 0.
TEST(CliTest, VersionTakesNoArguments) {
    EXPECT_EQ(test::runArgs({bin(), "--version"}).rc, 0);
    for (const char* extra : {"--bogus", "extra"}) {
        const test::Ran r = test::runArgs({bin(), "--version", extra});
        EXPECT_EQ(r.rc, 2) << r.err;
        EXPECT_NE(r.err.find("--version takes no arguments"), std::string::npos) << r.err;
        EXPECT_EQ(r.out, "");
    }
}

// Every command and subcommand: --help and -h print that command's usage on stdout, exit code 0,
// whatever else is on the line.
TEST(CliTest, HelpOnEveryCommand) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> commands = {
        {{}, "shadowlab run CONFIG.json"},
        {{"run"}, "shadowlab run CONFIG.json"},
        {{"validate"}, "shadowlab validate CONFIG.json"},
        {{"list"}, "shadowlab list ["},
        {{"info"}, "shadowlab info [--json]"},
        {{"plan"}, "shadowlab plan CONFIG.json"},
        {{"sweep"}, "shadowlab sweep merge DIR"},
        {{"sweep", "plan"}, "shadowlab sweep plan SWEEP.json"},
        {{"sweep", "config"}, "shadowlab sweep config SWEEP.json INDEX"},
        {{"sweep", "run"}, "shadowlab sweep run SWEEP.json"},
        {{"sweep", "slurm"}, "shadowlab sweep slurm SWEEP.json"},
        {{"sweep", "merge"}, "shadowlab sweep merge DIR"},
    };
    const std::string config = std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json";
    for (const auto& [command, usage] : commands) {
        for (const char* flag : {"--help", "-h"}) {
            for (bool withArgs : {false, true}) {
                std::vector<std::string> argv = {bin()};
                argv.insert(argv.end(), command.begin(), command.end());
                // Also after the command's own arguments: help wins, nothing runs.
                if (withArgs && !command.empty() && command[0] != "list") argv.push_back(config);
                argv.push_back(flag);
                const test::Ran r = test::runArgs(argv);
                std::string shown;
                for (const auto& a : argv) shown += a + " ";
                EXPECT_EQ(r.rc, 0) << shown << r.err;
                EXPECT_NE(r.out.find(usage), std::string::npos) << shown << ":\n" << r.out;
                EXPECT_EQ(r.err, "") << shown;
                if (command.size() == 2) EXPECT_EQ(r.out.find("shadowlab run CONFIG"), std::string::npos) << "only " << command[1] << "'s usage";
            }
        }
    }
}

// A name is one line of plain text of at most 200 bytes (it titles the report): a longer one is bad
// input, refused in one short line that names its JSON path instead of echoing it.
TEST(CliTest, RunRefusesAHugeNameInOneShortLine) {
    const std::string dir = test::makeTempDir("cli-name");
    const std::string name(100000, 'n'); // below the kernel's 128 KiB per argument
    const test::Ran r = test::runArgs({bin(), "run", std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json", "--out", dir + "/out",
                                       "--no-progress", "--set", "name=" + name});
    EXPECT_EQ(r.rc, 2) << r.err.substr(0, 2000);
    EXPECT_LT(r.err.size(), 1000u) << r.err.substr(0, 2000);
    EXPECT_NE(r.err.find("/name"), std::string::npos) << r.err.substr(0, 2000);
    EXPECT_FALSE(std::filesystem::exists(dir + "/out"));
    // Bad input that echoes a typed value: one short line too.
    const test::Ran bad = test::runArgs({bin(), "run", "--" + name});
    EXPECT_EQ(bad.rc, 2);
    EXPECT_LT(bad.err.size(), 1000u);
}

// Twenty-fourth probe: a name that cannot be results/NAME was refused although --out named the
// folder; validate, which has no --out, still refuses it.
TEST(CliTest, OutLiftsTheNameRuleOfTheDefaultFolder) {
    const std::string dir = test::makeTempDir("cli-name-out");
    std::ofstream(dir + "/c.json") << test::configWith({{"name", "\"a/b\""}, {"resolution", "[16, 16]"}, {"frames", "1"},
                                                        {"output", R"({"plots": false})"}});
    const test::Ran ran = test::runArgs({bin(), "run", dir + "/c.json", "--out", dir + "/out", "--no-progress"});
    EXPECT_EQ(ran.rc, 0) << ran.err;
    EXPECT_TRUE(std::filesystem::exists(dir + "/out/summary.json"));
    const test::Ran checked = test::runArgs({bin(), "validate", dir + "/c.json"});
    EXPECT_EQ(checked.rc, 2) << checked.err;
    EXPECT_NE(checked.err.find("/name"), std::string::npos) << checked.err;
}

// A scene an algorithm cannot take on this device is refused before it is made: exit 2, one line
// naming the entry and the structure, nothing written, and no time spent making 1.2 M triangles.
// `plan` says the same without running, and gives every algorithm's verdict.
TEST(CliTest, ARunAnAlgorithmCannotTakeIsRefusedBeforeTheSceneIsMade) {
    const std::string dir = test::makeTempDir("cli-plan");
    const std::string config = dir + "/big.json";
    std::ofstream(config) << R"({"name": "big", "resolution": [32, 32], "frames": 1,
      "scene": {"objects": [{"procedural": "grid", "count": [12, 1, 10],
                             "object": {"procedural": "sphere", "triangles": 10000}}]},
      "camera": {"position": [0, 30, 60], "target": [0, 0, 0]},
      "light": {"type": "point", "position": [0, 50, 0]},
      "algorithms": [{"algorithm": "metric_tree"}, {"id": "ptsv", "algorithm": "ptsv"}]})";
    const test::Ran r = test::runArgs({bin(), "run", config, "--out", dir + "/out", "--no-progress"});
    EXPECT_EQ(r.rc, 2) << r.err;
    EXPECT_NE(r.err.find("at /algorithms/1: ptsv cannot run this scene"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("shadow-volume planes"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("wrote"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/out")) << "a refused run left an output";
    const test::Ran plan = test::runArgs({bin(), "plan", config});
    EXPECT_EQ(plan.rc, 2) << plan.err;
    // 120 spheres of 10,000: that request tessellates to exactly 50 bands × 100 segments.
    EXPECT_NE(plan.out.find("scene: up to 1200000 triangles"), std::string::npos) << plan.out;
    EXPECT_NE(plan.out.find("metric_tree (metric_tree): "), std::string::npos) << plan.out;
    EXPECT_NE(plan.out.find("ptsv (ptsv): refuses: its shadow-volume planes"), std::string::npos) << plan.out;
    // Without ptsv the same scene plans, and a hypothetical size is asked with --triangles.
    const test::Ran fits = test::runArgs({bin(), "plan", config, "--set", "algorithms=[{\"algorithm\": \"metric_tree\"}]"});
    EXPECT_EQ(fits.rc, 0) << fits.err;
    EXPECT_NE(fits.out.find("plan: "), std::string::npos) << fits.out;
    const test::Ran asked = test::runArgs({bin(), "plan", config, "--triangles", "1000"});
    EXPECT_EQ(asked.rc, 0) << asked.err;
    EXPECT_NE(asked.out.find("scene: up to 1000 triangles"), std::string::npos) << asked.out;
}

// A count the plan cannot hold is refused with one line naming where it came from: a --triangles
// that is past any scene, negative or zero, and a grid whose counts multiply past the scene's
// budget or past 64 bits (2^64 wraps to 0, 1e45 is past any integer), never planned as "nothing".
TEST(CliTest, PlanRefusesCountsPastTheSceneOrPast64Bits) {
    const std::string dir = test::makeTempDir("cli-plan-overflow");
    const std::string config = dir + "/small.json";
    std::ofstream(config) << R"({"name": "small", "resolution": [32, 32], "frames": 1,
      "scene": {"objects": [{"procedural": "sphere", "triangles": 100}]},
      "camera": {"position": [0, 3, 6], "target": [0, 0, 0]},
      "light": {"type": "point", "position": [0, 5, 0]}})";
    for (const char* count : {"4611686018427387904", "18446744073709551616", "-1", "0", "200000001", "1e9", ""}) {
        const test::Ran r = test::runArgs({bin(), "plan", config, "--triangles", count});
        EXPECT_EQ(r.rc, 2) << count << ": " << r.out << r.err;
        EXPECT_NE(r.err.find("--triangles: expected a whole number in [1, 200000000]"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_EQ(r.out, "") << count;
    }
    // Nested grids: 2^48 copies of 2^15 or 2^16 triangles (2^63, 2^64), and three levels of 10^15
    // copies (10^45, refused at the innermost grid, already past the budget).
    const std::string sphere16 = R"({"procedural": "sphere", "triangles": 1})"; // 16 triangles
    auto gridOf = [](const std::string& object, const std::string& count) {
        return R"({"procedural": "grid", "count": )" + count + R"(, "object": )" + object + "}";
    };
    const std::string huge = "[65536, 65536, 65536]", cube = "[100000, 100000, 100000]";
    const std::pair<std::string, std::string> scenes[] = {
        {gridOf(gridOf(sphere16, "[2048, 1, 1]"), huge), "at /scene/objects/0/count"},
        {gridOf(gridOf(sphere16, "[4096, 1, 1]"), huge), "at /scene/objects/0/count"},
        {gridOf(gridOf(gridOf(sphere16, cube), cube), cube), "at /scene/objects/0/object/object/count"},
    };
    for (const auto& [object, where] : scenes) {
        const test::Ran r = test::runArgs({bin(), "plan", config, "--set", "scene.objects=[" + object + "]"});
        EXPECT_EQ(r.rc, 2) << where << ": " << r.out << r.err;
        // Named with the --set that gave the grids (probe 25).
        EXPECT_NE(r.err.find(config + ": " + where + ": from --set scene.objects="), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(": the grid would have"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("max_triangles"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        // The same scene asked at a size that fits is still refused: the config's own scene is.
        const test::Ran asked = test::runArgs({bin(), "plan", config, "--set", "scene.objects=[" + object + "]", "--triangles", "1000"});
        EXPECT_EQ(asked.rc, 2) << asked.err;
    }
}

// `info` says what a run would run on: the implementation, the subgroup width and what each auto
// parameter resolves to, as text and as JSON with the same values.
TEST(CliTest, InfoPrintsTheDeviceAndTheResolvedAutos) {
    const test::Ran j = test::runArgs({bin(), "info", "--json"});
    ASSERT_EQ(j.rc, 0) << j.err;
    EXPECT_EQ(j.err, "");
    const Json info = Json::parse(j.out);
    const Json& device = info.at("device");
    for (const char* key : {"vendor", "renderer", "version", "glsl_version"})
        EXPECT_FALSE(device.at(key).get<std::string>().empty()) << key;
    EXPECT_EQ(device.at("backend"), "OSMesa");
    const int subgroup = device.at("subgroup_size").get<int>();
    EXPECT_GE(subgroup, 0);
    EXPECT_GT(device.at("limits").at("GL_MAX_SHADER_STORAGE_BLOCK_SIZE").get<long long>(), 0);
    EXPECT_EQ(device.at("limits").at("GL_MAX_COMPUTE_WORK_GROUP_COUNT").size(), 3u);
    // The extensions the shaders name, each with whether the context has it.
    for (const char* ext : {"GL_ARB_shader_ballot", "GL_ARB_gpu_shader_int64"}) EXPECT_TRUE(device.at("extensions").at(ext).is_boolean()) << ext;
    EXPECT_EQ(device.at("extensions").at("GL_ARB_shader_ballot").get<bool>(), subgroup > 0);
    const Json& ptsv = info.at("algorithms").at("ptsv").at("resolved_params");
    const std::string traversal = ptsv.at("traversal").get<std::string>();
    EXPECT_NE(traversal, "auto");
    for (const char* key : {"vote", "lanes", "split_level", "jobs_per_workgroup"}) EXPECT_TRUE(ptsv.contains(key)) << key;
    EXPECT_TRUE(info.at("algorithms").at("metric_tree").at("resolved_params").contains("tile"));
    // Every registered algorithm has an entry, none failed.
    std::string list;
    ASSERT_EQ(test::runCommand(bin() + " list --json 2>/dev/null", list), 0);
    for (const auto& a : Json::parse(list)) {
        ASSERT_TRUE(info["algorithms"].contains(a["name"].get<std::string>())) << a["name"];
        EXPECT_FALSE(info["algorithms"][a["name"].get<std::string>()].contains("error")) << a["name"];
    }

    const test::Ran t = test::runArgs({bin(), "info"});
    ASSERT_EQ(t.rc, 0) << t.err;
    EXPECT_NE(t.out.find(device.at("renderer").get<std::string>()), std::string::npos) << t.out;
    EXPECT_NE(t.out.find("subgroup width " + std::to_string(subgroup)), std::string::npos) << t.out;
    EXPECT_NE(t.out.find("traversal = " + traversal), std::string::npos) << t.out;
    EXPECT_NE(t.out.find("GL_MAX_TEXTURE_BUFFER_SIZE"), std::string::npos) << t.out;
}

// Bad input to `info` is exit code 2 and one line, with nothing on stdout.
TEST(CliTest, InfoRefusesUnknownArguments) {
    for (const std::vector<std::string>& extra : {std::vector<std::string>{"--jsn"}, {"--json", "extra"}, {"-x"}}) {
        std::vector<std::string> argv = {bin(), "info"};
        argv.insert(argv.end(), extra.begin(), extra.end());
        const test::Ran r = test::runArgs(argv);
        EXPECT_EQ(r.rc, 2) << extra.back();
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find(extra.back()), std::string::npos) << r.err;
        EXPECT_EQ(r.out, "");
    }
}

// Fifth probe: `run C --out --force` made a folder named "--force", an option given twice took
// its last value silently, `--partition ""` dropped the partition. Each is a one-line usage error.
TEST(CliTest, AnOptionTwiceOrWithoutItsValueIsBadInput) {
    const std::string dir = test::makeTempDir("cli-options");
    const std::string config = dir + "/c.json";
    std::ofstream(config) << test::configWith({});
    const std::string sweep = test::writeJson(dir + "/s.sweep.json", test::smallSweep());
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"run " + config + " --out --force", "not the option --force"},
        {"run " + config + " --out " + dir + "/a --out " + dir + "/b", "--out is given twice"},
        {"plan " + config + " --triangles 10 --triangles 20", "--triangles is given twice"},
        {"validate " + config + " --set frames=2 --set frames=3", "--set frames is given twice"},
        {"sweep run " + sweep + " --out " + dir + "/a --out " + dir + "/b", "is given twice"},
        {"sweep run " + sweep + " --out --jobs 2", "not the option --jobs"},
        {"sweep slurm " + sweep + " --out " + dir + "/sw --partition ''", "must not be empty"},
        // Probe 25: flags twice were refused by some commands and taken by others; one rule now.
        {"run " + config + " --out " + dir + "/a --force --force", "--force is given twice"},
        {"run " + config + " --out " + dir + "/a --no-progress --no-progress", "--no-progress is given twice"},
        {"info --json --json", "--json is given twice"},
        {"sweep plan " + sweep + " --check --check", "--check: is given twice"},
        {"compare " + dir + " " + dir + " --force --force", "--force: is given twice"},
        {"history " + dir + " --by-name --by-name", "--by-name: is given twice"},
    };
    for (const auto& [args, cause] : cases) {
        std::string out;
        EXPECT_EQ(test::runCommand("cd " + dir + " && " + bin() + " " + args, out), 2) << args << ": " << out;
        EXPECT_NE(out.find(cause), std::string::npos) << args << ": " << out;
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << args << ": " << out;
    }
    for (const char* made : {"--force", "a", "b", "sw", "--jobs"}) EXPECT_FALSE(std::filesystem::exists(dir + "/" + made)) << made;
}

// A run whose expectations fail writes every result and exits 3 (not 0, not 1): what a CI job keys on.
TEST(CliTest, UnmetExpectationsExitThreeWithEveryResultWritten) {
    const std::string dir = test::makeTempDir("cli-expect");
    std::ofstream(dir + "/c.json") << test::configWith(
        {{"expect", R"([{"id": "shadow_map", "measure": "overflow", "max": 0},
                        {"id": "shadow_map", "measure": "memory_bytes", "max": 1, "note": "planted: no map fits in a byte"}])"}});
    std::string log;
    EXPECT_EQ(test::runCommand(bin() + " run " + dir + "/c.json --out " + dir + "/out --no-progress", log), 3) << log;
    EXPECT_NE(log.find("expectation FAILED: shadow_map: memory_bytes = "), std::string::npos) << log;
    EXPECT_NE(log.find("expectations: 1 of 2 failed (exit 3; every result was written)"), std::string::npos) << log;
    const Json summary = JsonNode::parseFile(dir + "/out/summary.json");
    EXPECT_TRUE(summary["complete"].get<bool>());
    ASSERT_EQ(summary["expectations"].size(), 2u);
    EXPECT_TRUE(summary["expectations"][0]["passed"].get<bool>());
    EXPECT_FALSE(summary["expectations"][1]["passed"].get<bool>());
    std::ifstream junit(dir + "/out/expectations.junit.xml"), report(dir + "/out/report.md");
    const std::string xml((std::istreambuf_iterator<char>(junit)), {}), md((std::istreambuf_iterator<char>(report)), {});
    EXPECT_NE(xml.find("tests=\"2\" failures=\"1\""), std::string::npos) << xml;
    EXPECT_NE(md.find("## Expectations: 1 of 2 failed"), std::string::npos) << md;
    EXPECT_NE(md.find("planted\\: no map fits in a byte"), std::string::npos) << md; // literal Markdown
    // Met, the same run exits 0.
    EXPECT_EQ(test::runCommand(bin() + " run " + dir + "/c.json --out " + dir + "/out --force --no-progress --set expect.1.max=1e12", log), 0)
        << log;
    EXPECT_NE(log.find("expectations: all 2 met"), std::string::npos) << log;
}

// compare on the command line: two run folders give a report and exit 0 for one build against
// itself; bad arguments are one line and exit 2; --out writes the report, JUnit and json.
TEST(CliTest, CompareTwoRunsAndRefuseBadArguments) {
    const std::string dir = test::makeTempDir("cli-compare");
    std::ofstream(dir + "/c.json") << test::configWith({});
    std::string log;
    ASSERT_EQ(test::runCommand(bin() + " run " + dir + "/c.json --out " + dir + "/a --no-progress", log), 0) << log;
    EXPECT_EQ(test::runCommand("(" + bin() + " compare " + dir + "/a " + dir + "/a >" + dir + "/same.md)", log), 0) << log;
    std::ifstream same(dir + "/same.md");
    const std::string md((std::istreambuf_iterator<char>(same)), {});
    EXPECT_NE(md.find("## No regression"), std::string::npos) << md;
    EXPECT_EQ(test::runCommand(bin() + " compare " + dir + "/a " + dir + "/a --relative-to '*' --out " + dir + "/cmp", log), 0) << log;
    for (const char* f : {"compare.md", "compare.html", "compare.junit.xml", "compare.json"})
        EXPECT_TRUE(std::filesystem::exists(dir + "/cmp/" + f)) << f;
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"compare " + dir + "/a", "expects two run folders"},
        {"compare " + dir + "/a " + dir + "/a --threshold x", "expected a percentage"},
        {"compare " + dir + "/a " + dir + "/a --relative-to nope", "not an algorithm id of both runs"},
        {"compare " + dir + "/a " + dir, "is not a run's output folder"},
    };
    for (const auto& [args, cause] : bad) {
        EXPECT_EQ(test::runCommand("(" + bin() + " " + args + " >/dev/null)", log), 2) << args << ": " << log;
        EXPECT_NE(log.find(cause), std::string::npos) << args << ": " << log;
        EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
    }
}

TEST(CliTest, UnknownCommandIsBadInput) {
    std::string out;
    EXPECT_EQ(test::runCommand(bin() + " frobnicate", out), 2);
    // Fourteenth probe: an empty name printed every algorithm's table.
    EXPECT_EQ(test::runCommand(bin() + " list --markdown ''", out), 2) << out;
    EXPECT_NE(out.find("the name is empty"), std::string::npos) << out;
}

TEST(CliTest, EveryShippedConfigValidates) {
    size_t n = 0;
    for (const auto& e : std::filesystem::recursive_directory_iterator(std::string(SHADOWLAB_SOURCE_DIR) + "/configs")) {
        if (e.path().extension() != ".json") continue;
        // A sweep file (docs/sweep.md) is checked run by run by `sweep plan`.
        const bool sweep = e.path().string().ends_with(".sweep.json");
        std::string out;
        EXPECT_EQ(test::runCommand(bin() + (sweep ? " sweep plan " : " validate ") + e.path().string(), out), 0) << out;
        ++n;
    }
    EXPECT_GE(n, 2u);
}

TEST(CliTest, SetOverridesAValueAndIsValidatedLikeTheFile) {
    const std::string smoke = std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json";
    std::string out;
    // (…) 2>/dev/null: only the resolved config (stdout) is read back.
    ASSERT_EQ(test::runCommand("(" + bin() + " validate " + smoke + " --set resolution=[32,48] --set algorithms.0.params.pcf=0" +
                                   " --set light.type=directional 2>/dev/null)", out), 0) << out;
    Json resolved = Json::parse(out);
    EXPECT_EQ(resolved["resolution"], Json::array({32, 48}));
    EXPECT_EQ(resolved["algorithms"][0]["params"]["pcf"], 0);
    EXPECT_EQ(resolved["light"]["type"], "directional");
    // A typo or a bad index is bad input: exit code 2 and one line naming the path.
    for (const char* bad : {"algorithms.0.params.pfc=1", "algorithms.99.params.pcf=1", "resolution", "frames.x=1"}) {
        EXPECT_EQ(test::runCommand(bin() + " validate " + smoke + " --set " + bad, out), 2) << bad;
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
    }
}

#ifdef SHADOWLAB_EGL_BINARY
// shadowlab-egl is the runner for GPU servers; Mesa's EGL (surfaceless llvmpipe) runs it here, so
// its context, function loading and outputs are tested even without a GPU.
TEST(CliTest, EglRunnerRunsTheSmokeConfig) {
    const std::string dir = test::makeTempDir("egl") + "/out";
    std::string out;
    ASSERT_EQ(test::runCommand(std::string(SHADOWLAB_EGL_BINARY) + " run " + std::string(SHADOWLAB_SOURCE_DIR) +
                                   "/configs/smoke.json --no-progress --out " + dir +
                                   " --set resolution=[64,64] --set frames=2 --set output.images_at_frames=[1]",
                               out), 0) << out;
    std::ifstream in(dir + "/summary.json");
    Json s = Json::parse(in);
    EXPECT_EQ(s["backend"], "EGL");
    for (const auto& [id, a] : s["algorithms"].items())
        if (a["algorithm"] == "psv" || a["algorithm"] == "bvh_raytrace")
            EXPECT_LE(a["accuracy"]["mismatch_ratio_max"].get<double>(), 0.001) << id; // exact, as on OSMesa
    EXPECT_EQ(s["device"]["backend"], "EGL");
}

TEST(CliTest, EglInfoNamesItsBackend) {
    const test::Ran r = test::runArgs({SHADOWLAB_EGL_BINARY, "info", "--json"});
    ASSERT_EQ(r.rc, 0) << r.err;
    const Json info = Json::parse(r.out);
    EXPECT_EQ(info["device"]["backend"], "EGL");
    EXPECT_TRUE(info["algorithms"]["ptsv"]["resolved_params"].contains("traversal"));
}
#endif

// Every malformed glTF of Debian's assimp-testmodels: a one-line error naming the file, exit code 2.
const char* kMalformed[] = {
    "IndexOutOfRange/IndexOutOfRange.gltf",
    "IndexOutOfRange/AllIndicesOutOfRange.gltf",
    "wrongTypes/badArray.gltf",
    "wrongTypes/badNumber.gltf",
    "wrongTypes/badObject.gltf",
    "wrongTypes/badString.gltf",
    "wrongTypes/badUint.gltf",
    "MissingBin/BoxTextured.gltf",
    "SchemaFailures/sceneWrongType.gltf",
    "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
    "IncorrectVertexArrays/Cube.gltf",
    "RecursiveNodes/RecursiveNodes.gltf",
};

class CliMalformedGltfTest : public ::testing::TestWithParam<const char*> {};

TEST_P(CliMalformedGltfTest, ExitsWithCode2AndOneLine) {
    std::string dir = test::makeTempDir("gltf");
    std::string file = test::kAssimpGltf + "/" + GetParam();
    std::ofstream(dir + "/cfg.json") << R"({"scene": {"objects": [{"gltf": ")" << file << R"("}]}})";
    std::string out;
    int rc = test::runCommand(bin() + " validate " + dir + "/cfg.json", out);
    EXPECT_EQ(rc, 2) << out;
    // One line on stderr (the trailing newline aside) naming the glTF file.
    std::string trimmed = out.substr(0, out.find_last_not_of('\n') + 1);
    EXPECT_EQ(trimmed.find('\n'), std::string::npos) << out;
    EXPECT_NE(out.find(file), std::string::npos) << out;
}

INSTANTIATE_TEST_SUITE_P(AssimpTestModels, CliMalformedGltfTest, ::testing::ValuesIn(kMalformed), [](const auto& info) {
    std::string n = info.param;
    for (char& c : n)
        if (!isalnum(static_cast<unsigned char>(c))) c = '_';
    return n;
});

} // namespace
} // namespace shadowlab
