// What `shadowlab info` and summary.json say about the device: the record of the context, and the
// value each algorithm's device-dependent parameters resolve to (ShadowAlgorithm::resolvedParams),
// checked against the rules the algorithms document.
#include "framework/algorithm/AlgorithmHost.h"
#include "framework/experiment/DeviceReport.h"
#include "framework/gl/DeviceInfo.h"
#include "framework/gl/GlContext.h"
#include "framework/gl/Shader.h"
#include "tests/TestSupport.h"

#include <algorithm>
#include <map>

namespace shadowlab {
namespace {

class DeviceInfoGLTest : public test::GLTest {};

/// resolvedParams() of `name` created with its defaults plus `overrides` (statistics compiled out,
/// as the timed pass creates it).
std::map<std::string, std::string> resolved(const std::string& name, const std::map<std::string, ParamValue>& overrides = {}) {
    const AlgorithmInfo* info = findAlgorithm(name);
    EXPECT_NE(info, nullptr) << name;
    if (!info) return {};
    ParamValues params(info->schema());
    for (const auto& [k, v] : overrides) params.set(k, v);
    AlgorithmHost host(*info, params, AlgorithmOptions{false});
    const auto list = host.algorithm().resolvedParams();
    return std::map<std::string, std::string>(list.begin(), list.end());
}

bool ballotWidth(int w) { return w == 4 || w == 8 || w == 16 || w == 32 || w == 64; }

// Ptsv.cpp's compile(): with two passes, subgroups narrower than 32 lanes get one job per
// invocation (packets in pass one where ARB_shader_ballot is there), wider ones the paper's
// cooperative traversal with ballots as wide as the subgroup; no votes without cooperation.
TEST_F(DeviceInfoGLTest, PtsvResolvesItsAutosByItsRule) {
    const int width = querySubgroupSize();
    const bool ballot = ballotWidth(width);
    const bool narrow = !(ballot && width >= 32);
    const auto d = resolved("ptsv");
    EXPECT_EQ(d.at("traversal"), narrow ? (ballot ? "packet" : "invocation") : "cooperative");
    EXPECT_EQ(d.at("vote"), narrow ? "none" : "ballot");
    EXPECT_EQ(d.at("lanes"), narrow ? "1" : std::to_string(width));
    EXPECT_EQ(d.at("split_level"), narrow ? "levels" : "levels - 1"); // no frame yet: the rule
    EXPECT_EQ(d.at("jobs_per_workgroup"), "16");
    if (glRendererString().find("llvmpipe") != std::string::npos && (width == 8 || width == 16)) {
        // llvmpipe: 8 (or, through some builds on AVX-512, 16) lanes: packets, no votes.
        EXPECT_EQ(d.at("traversal"), "packet");
        EXPECT_EQ(d.at("vote"), "none");
        EXPECT_EQ(d.at("lanes"), "1");
    }

    // Cooperative: ballots as wide as the subgroup, else shared-memory votes over 32 lanes.
    const auto coop = resolved("ptsv", {{"traversal", std::string("cooperative")}});
    EXPECT_EQ(coop.at("traversal"), "cooperative");
    EXPECT_EQ(coop.at("vote"), ballot ? "ballot" : "shared");
    EXPECT_EQ(coop.at("lanes"), ballot ? std::to_string(width) : "32");
    EXPECT_EQ(coop.at("split_level"), "levels - 1");
    const auto shared = resolved("ptsv", {{"traversal", std::string("cooperative")}, {"vote", std::string("shared")}});
    EXPECT_EQ(shared.at("vote"), "shared");
    EXPECT_EQ(shared.at("lanes"), "32");
    // One pass stays cooperative under auto, one job per workgroup.
    const auto onePass = resolved("ptsv", {{"two_pass", false}});
    EXPECT_EQ(onePass.at("traversal"), "cooperative");
    EXPECT_EQ(onePass.at("jobs_per_workgroup"), "1");
    // Values that were given stay as given.
    const auto given = resolved("ptsv", {{"traversal", std::string("invocation")}, {"split_level", 3}, {"jobs_per_workgroup", 4}});
    EXPECT_EQ(given.at("traversal"), "invocation");
    EXPECT_EQ(given.at("vote"), "none");
    EXPECT_EQ(given.at("split_level"), "3");
    EXPECT_EQ(given.at("jobs_per_workgroup"), "4");
}

// autoTilePixels() (MetricTree.h): the tile walkers fill one subgroup, tiles of at least 8 pixels.
TEST_F(DeviceInfoGLTest, MetricTreeTileWalkersFillOneSubgroup) {
    const int width = querySubgroupSize();
    const char* expected = width == 4 ? "8x2" : "4x2";
    EXPECT_EQ(resolved("metric_tree").at("tile"), expected);
    EXPECT_EQ(resolved("metric_tree", {{"tile", std::string("8x4")}}).at("tile"), "8x4");
}

TEST_F(DeviceInfoGLTest, ThreadsAndBlockSizesResolveToTheDevice) {
    // Auto is one thread per 65,536 pixels (EmbreeTracer::threadsFor); before its first frame the
    // reference has no pixels and resolves to one. ReferenceTest.ThreadsFollowTheFramesSize covers sizes.
    EXPECT_EQ(resolved("reference").at("threads"), "1");
    EXPECT_EQ(resolved("reference", {{"threads", 3}}).at("threads"), "3");
    EXPECT_EQ(resolved("line_space").at("max_block_mib"), std::to_string(maxShaderStorageBlockBytes() >> 20));
    EXPECT_EQ(resolved("line_space", {{"max_block_mib", 1}}).at("max_block_mib"), "1");
}

// psv's auto walk: stackless on every device, the stack walk for x-ray shadows.
TEST_F(DeviceInfoGLTest, PsvAutoTraversalIsStacklessBesidesTransparency) {
    EXPECT_EQ(resolved("psv").at("traversal"), "stackless");
    EXPECT_EQ(resolved("psv", {{"transparency", true}}).at("traversal"), "stack");
    EXPECT_EQ(resolved("psv", {{"traversal", std::string("hybrid")}}).at("traversal"), "hybrid");
}

TEST_F(DeviceInfoGLTest, DeviceRecordDescribesTheContext) {
    const Json d = deviceRecord(context_->backend());
    EXPECT_EQ(d.at("renderer"), glRendererString());
    EXPECT_EQ(d.at("version"), glVersionString());
    EXPECT_EQ(d.at("backend"), context_->backend());
    EXPECT_EQ(d.at("subgroup_size").get<int>(), querySubgroupSize());
    EXPECT_FALSE(d.at("glsl_version").get<std::string>().empty());
    EXPECT_EQ(d.at("limits").at("GL_MAX_SHADER_STORAGE_BLOCK_SIZE").get<size_t>(), maxShaderStorageBlockBytes());
    for (const char* key : {"GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS", "GL_MAX_COMBINED_SHADER_STORAGE_BLOCKS",
                            "GL_MAX_TEXTURE_BUFFER_SIZE", "GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS",
                            "GL_MAX_COMPUTE_SHARED_MEMORY_SIZE", "GL_MAX_TEXTURE_SIZE"})
        EXPECT_GT(d.at("limits").at(key).get<long long>(), 0) << key;
    for (const char* key : {"GL_MAX_COMPUTE_WORK_GROUP_COUNT", "GL_MAX_COMPUTE_WORK_GROUP_SIZE"}) {
        ASSERT_EQ(d.at("limits").at(key).size(), 3u) << key;
        for (const auto& v : d.at("limits").at(key)) EXPECT_GT(v.get<long long>(), 0) << key;
    }
    // The extensions come from the shaders' #extension lines, each with whether the context has it.
    const std::vector<ExtensionUse> uses = shaderExtensions();
    auto ballot = std::find_if(uses.begin(), uses.end(), [](const ExtensionUse& u) { return u.name == "GL_ARB_shader_ballot"; });
    ASSERT_NE(ballot, uses.end());
    EXPECT_NE(std::find(ballot->files.begin(), ballot->files.end(), "common/subgroup_size.comp"), ballot->files.end());
    for (const ExtensionUse& u : uses) EXPECT_EQ(d.at("extensions").at(u.name).get<bool>(), hasExtension(u.name.c_str())) << u.name;
    EXPECT_TRUE(d.at("extensions").contains("GL_KHR_debug"));
}

// `shadowlab info` asks every registered algorithm on a tiny scene; each can be made with its
// defaults here, and says what the host made of it.
TEST_F(DeviceInfoGLTest, EveryAlgorithmResolvesWithItsDefaults) {
    const std::vector<ResolvedDefaults> all = resolveDefaults();
    ASSERT_EQ(all.size(), algorithmRegistry().size());
    for (const ResolvedDefaults& a : all) {
        EXPECT_EQ(a.error, "") << a.algorithm;
        if (a.algorithm == "ptsv") {
            const std::map<std::string, std::string> viaInfo(a.params.begin(), a.params.end());
            EXPECT_EQ(viaInfo, resolved("ptsv"));
        }
    }
    const Json j = deviceInfoJson(deviceRecord(context_->backend()), all);
    EXPECT_TRUE(j.at("algorithms").at("metric_tree").at("resolved_params").contains("tile"));
    const std::string text = deviceInfoText(j.at("device"), all);
    EXPECT_NE(text.find("subgroup width " + std::to_string(querySubgroupSize())), std::string::npos) << text;
}

} // namespace
} // namespace shadowlab
