// ptsv pieces that need no GL context: the cluster-key layout derived from resolution, tile size
// and near/far, the parameter schema, and the one-line error for bad parameters.
#include "algorithms/ptsv/Ptsv.h"
#include "algorithms/ptsv/PtsvLayout.h"
#include "framework/core/Error.h"
#include "tests/TestSupport.h"

#include <cmath>
#include <fstream>
#include <set>

namespace shadowlab {
namespace {

TEST(PtsvTest, LayoutAtThePapersResolution) {
    // 1024² in 8×8 tiles: 128 tiles a side, 7 bits each (paper 2); z bits follow near/far.
    ptsv::KeyLayout l = ptsv::makeKeyLayout({1024, 1024}, 8, 60.0f, 0.1f, 100.0f, 30);
    EXPECT_EQ(l.tilesX, 128);
    EXPECT_EQ(l.bitsX, 7);
    EXPECT_EQ(l.bitsY, 7);
    // Olsson's slices: log(far / near) / log(1 + 2 tan(30°) / 128) = 6.91 / 0.00898 = 769.
    EXPECT_EQ(l.slices, int(std::ceil(std::log(1000.0) / std::log1p(2.0 * std::tan(M_PI / 6) / 128))));
    EXPECT_EQ(l.bitsZ, 10);
    EXPECT_EQ(l.keyBits, 24);
    EXPECT_EQ(l.levels, 5); // five levels of child masks above the clusters, as in the paper
    EXPECT_EQ(l.nodesAt(0), 1u);
    EXPECT_EQ(l.nodesAt(5), size_t(1) << 24);
    EXPECT_EQ(l.nodesAt(4), size_t(1) << 19);
    EXPECT_EQ(l.maskWords, 1 + (size_t(1) << 4) + (size_t(1) << 9) + (size_t(1) << 14) + (size_t(1) << 19));
}

TEST(PtsvTest, KeyBitCapMergesDepthSlices) {
    // The default cap of 22 bits: the paper's 1024² (24 bits) gets slices 4× as deep, so the full
    // tree's bounds stay at 24 B × 2^22 instead of 2^24.
    ptsv::KeyLayout full = ptsv::makeKeyLayout({1024, 1024}, 8, 60.0f, 0.1f, 100.0f, 30);
    ptsv::KeyLayout capped = ptsv::makeKeyLayout({1024, 1024}, 8, 60.0f, 0.1f, 100.0f, 22);
    EXPECT_EQ(capped.keyBits, 22);
    EXPECT_EQ(capped.bitsX, 7);
    EXPECT_EQ(capped.merged, 2);
    EXPECT_FLOAT_EQ(capped.sliceLog, 4.0f * full.sliceLog);
    EXPECT_EQ(capped.slices, int(std::ceil(std::log(1000.0) / capped.sliceLog)));
    EXPECT_EQ(capped.levels, 5);
    // Under the cap nothing changes.
    ptsv::KeyLayout small = ptsv::makeKeyLayout({256, 256}, 8, 60.0f, 0.1f, 100.0f, 22);
    EXPECT_EQ(small.merged, 0);
    // x and y alone over the cap: refused with a message.
    EXPECT_THROW(ptsv::makeKeyLayout({4096, 4096}, 2, 60.0f, 0.1f, 100.0f, 20), RuntimeError);
}

TEST(PtsvTest, LevelsFollowResolutionTileAndDepthRange) {
    ptsv::KeyLayout small = ptsv::makeKeyLayout({128, 96}, 8, 60.0f, 0.05f, 50.0f);
    EXPECT_EQ(small.tilesX, 16);
    EXPECT_EQ(small.tilesY, 12);
    EXPECT_EQ(small.bitsX, 4);
    EXPECT_EQ(small.bitsY, 4);
    ptsv::KeyLayout deep = ptsv::makeKeyLayout({128, 96}, 8, 60.0f, 0.05f, 500000.0f); // 75 → 176 slices
    EXPECT_GT(deep.slices, small.slices);
    EXPECT_GE(deep.bitsZ, small.bitsZ + 1);
    ptsv::KeyLayout coarse = ptsv::makeKeyLayout({128, 96}, 16, 60.0f, 0.05f, 50.0f);
    EXPECT_EQ(coarse.bitsX, 3);
    EXPECT_LT(coarse.slices, small.slices); // fewer tiles: wider clusters, so deeper slices
    for (const ptsv::KeyLayout& l : {small, deep, coarse}) EXPECT_EQ(l.levels, (l.keyBits + 4) / 5);
    // More than 30 key bits never happens: slices merge first (here 13 + 13 bits of tiles leave 4).
    ptsv::KeyLayout huge = ptsv::makeKeyLayout({16384, 16384}, 2, 60.0f, 1e-4f, 1e6f);
    EXPECT_EQ(huge.keyBits, 30);
    EXPECT_GT(huge.merged, 0);
}

TEST(PtsvTest, KeysAreMortonOrderedAndInvertible) {
    ptsv::KeyLayout l = ptsv::makeKeyLayout({96, 64}, 8, 60.0f, 0.05f, 50.0f); // 12 × 8 tiles
    std::set<uint32_t> keys;
    for (uint32_t z = 0; z < uint32_t(l.slices); ++z)
        for (uint32_t y = 0; y < uint32_t(l.tilesY); ++y)
            for (uint32_t x = 0; x < uint32_t(l.tilesX); ++x) {
                uint32_t k = l.key({x, y, z});
                ASSERT_LT(k, 1u << l.keyBits);
                EXPECT_TRUE(keys.insert(k).second);
                EXPECT_EQ(l.coordinate(k, l.levels), glm::uvec3(x, y, z));
                // A node's coordinate is its clusters' with the bits below its level cleared.
                glm::uvec3 parent = l.coordinate(k >> 5, l.levels - 1);
                EXPECT_EQ(l.key(parent), k & ~31u);
                EXPECT_LE(parent.x, x);
                EXPECT_LE(parent.z, z);
            }
    // Morton from the least significant bit: x0 y0 z0 x1 y1 z1 ...
    EXPECT_EQ(l.key({1, 0, 0}), 1u);
    EXPECT_EQ(l.key({0, 1, 0}), 2u);
    EXPECT_EQ(l.key({0, 0, 1}), 4u);
    EXPECT_EQ(l.key({2, 0, 0}), 8u);
}

TEST(PtsvTest, DepthSlicesAreExponential) {
    ptsv::KeyLayout l = ptsv::makeKeyLayout({256, 256}, 8, 60.0f, 0.1f, 100.0f);
    EXPECT_EQ(ptsv::depthSlice(l, 0.1f, 0.1f), 0);
    EXPECT_EQ(ptsv::depthSlice(l, 100.0f, 0.1f), l.slices - 1);
    // A slice is as deep as a tile is wide at that depth: depth ratio 1 + 2 tan(fov/2) / tilesY.
    const float ratio = std::exp(l.sliceLog);
    EXPECT_NEAR(ratio, 1.0f + 2.0f * std::tan(glm::radians(30.0f)) / 32.0f, 1e-5f);
    int a = ptsv::depthSlice(l, 1.0f, 0.1f), b = ptsv::depthSlice(l, 1.0f * ratio * ratio * 1.0001f, 0.1f);
    EXPECT_EQ(b, a + 2);
}

TEST(PtsvTest, SchemaDeclaresEveryAblation) {
    const AlgorithmInfo info = ptsvInfo();
    for (const char* key : {"bounds", "culling_planes", "two_pass", "split_level", "tile_size", "front_face_culling",
                            "plane_bias", "ray_offset", "job_capacity", "jobs_per_workgroup", "vote", "leaf_samples", "max_key_bits",
                            "job_iterations", "heat_map"})
        EXPECT_NE(info.schema().find(key), nullptr) << key;
    EXPECT_EQ(std::get<std::string>(info.schema().find("bounds")->def), "explicit");
    EXPECT_EQ(std::get<int>(info.schema().find("tile_size")->def), 8);
    EXPECT_TRUE(info.supports(LightType::Point));
    EXPECT_TRUE(info.supports(LightType::Directional));
    EXPECT_TRUE(info.supports(LightType::Spot));
    EXPECT_FALSE(info.supports(LightType::Area));
    EXPECT_TRUE(info.exact);
}

TEST(PtsvTest, BadParameterIsAOneLineErrorWithExitCode2) {
    for (const char* params : {R"({"bounds": "tight"})", R"({"tile_size": 1})", R"({"job_capacity": 0})",
                               R"({"two_passes": true})"}) {
        std::string dir = test::makeTempDir("ptsv");
        std::ofstream(dir + "/cfg.json") << R"({"algorithms": [{"id": "p", "algorithm": "ptsv", "params": )" << params
                                         << "}]}";
        std::string out;
        int rc = test::runCommand(std::string(SHADOWLAB_BINARY) + " validate " + dir + "/cfg.json", out);
        EXPECT_EQ(rc, 2) << params << ": " << out;
        std::string trimmed = out.substr(0, out.find_last_not_of('\n') + 1);
        EXPECT_EQ(trimmed.find('\n'), std::string::npos) << out;
    }
}

} // namespace
} // namespace shadowlab
