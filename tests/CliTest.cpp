// The command line as a user meets it: exit codes, one-line errors, and malformed scene files.
#include "framework/core/JsonNode.h"
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

// Every command and subcommand: --help and -h print that command's usage on stdout, exit code 0,
// whatever else is on the line.
TEST(CliTest, HelpOnEveryCommand) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> commands = {
        {{}, "shadowlab run CONFIG.json"},
        {{"run"}, "shadowlab run CONFIG.json"},
        {{"validate"}, "shadowlab validate CONFIG.json"},
        {{"list"}, "shadowlab list ["},
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

// What `run` echoes of its input (the config's name, in the progress line) is cut to one short line.
TEST(CliTest, RunEchoesABoundedName) {
    const std::string dir = test::makeTempDir("cli-name");
    const std::string name(100000, 'n'); // below the kernel's 128 KiB per argument
    const test::Ran r = test::runArgs({bin(), "run", std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json", "--out", dir + "/out",
                                       "--no-progress", "--set", "name=" + name, "--set", "resolution=[32,32]", "--set", "frames=1",
                                       "--set", "output.plots=false", "--set", "output.images_at_frames=[]"});
    EXPECT_EQ(r.rc, 0) << r.err.substr(0, 2000);
    EXPECT_LT(r.err.size(), 4000u) << r.err.substr(0, 2000);
    EXPECT_NE(r.err.find("nnnnn..."), std::string::npos) << r.err.substr(0, 2000);
    // Bad input that echoes a typed value: one short line too.
    const test::Ran bad = test::runArgs({bin(), "run", "--" + name});
    EXPECT_EQ(bad.rc, 2);
    EXPECT_LT(bad.err.size(), 1000u);
}

TEST(CliTest, UnknownCommandIsBadInput) {
    std::string out;
    EXPECT_EQ(test::runCommand(bin() + " frobnicate", out), 2);
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
