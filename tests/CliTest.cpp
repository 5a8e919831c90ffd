// The command line as a user meets it: exit codes, one-line errors, and malformed scene files.
#include "tests/TestSupport.h"

#include <filesystem>
#include <fstream>

namespace shadowlab {
namespace {

std::string bin() { return SHADOWLAB_BINARY; }

TEST(CliTest, HelpAndListSucceed) {
    std::string out;
    EXPECT_EQ(test::runCommand(bin() + " --help", out), 0);
    EXPECT_NE(out.find("shadowlab run CONFIG.json"), std::string::npos);
    EXPECT_EQ(test::runCommand(bin() + " list", out), 0);
    EXPECT_NE(out.find("shadow_map"), std::string::npos);
    EXPECT_NE(out.find("reference"), std::string::npos);
}

TEST(CliTest, UnknownCommandIsBadInput) {
    std::string out;
    EXPECT_EQ(test::runCommand(bin() + " frobnicate", out), 2);
}

TEST(CliTest, ShippedConfigsValidate) {
    for (const char* cfg : {"smoke.json", "demo.json"}) {
        std::string out;
        EXPECT_EQ(test::runCommand(bin() + " validate " + std::string(SHADOWLAB_SOURCE_DIR) + "/configs/" + cfg, out), 0) << out;
    }
}

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
