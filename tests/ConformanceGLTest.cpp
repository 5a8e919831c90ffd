// What every registered algorithm (and the template a newcomer copies) must do, driven by the
// registry, so a new algorithm is tested from its first line: for every light type it supports, on
// a few scenes, with its default parameters, it writes visibility in [0, 1], raises no GL error
// (the fixture's debug callback), overflows nothing, and an exact algorithm agrees with the Embree
// reference; every schema key round-trips through a config and the GUI's setter; and an Update, a
// Recompile and a Rebuild change, made and undone through the host, leave the image as it was.
#include "algorithms/template/Template.h"
#include "framework/algorithm/AlgorithmHost.h"
#include "framework/algorithm/SharedParams.h"
#include "tests/AlgorithmHarness.h"
#include "tests/TestSupport.h"

#include <cmath>
#include <cstring>
#include <ostream>

namespace shadowlab {
namespace {

/// The registry plus the template, which only the tests register.
std::vector<const AlgorithmInfo*> conformingAlgorithms() {
    static const AlgorithmInfo templ = templateInfo();
    std::vector<const AlgorithmInfo*> out;
    for (const AlgorithmInfo& a : algorithmRegistry()) out.push_back(&a);
    out.push_back(&templ);
    return out;
}

// Exact algorithms must agree with Embree on every lit pixel; the bound admits one pixel in ten
// thousand for a ray through an edge shared by two triangles, which two watertight tests (or a
// plane through the light) may round to different sides. None was seen at this size.
constexpr double kExactMismatch = 1e-4;
constexpr int kRes = 48;  // GLSL runs on the CPU here: 25 algorithm × light cases, 2 scenes each

struct Case {
    const AlgorithmInfo* info;
    LightType light;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.info->name << " under a " << toString(c.light) << " light"; }

std::vector<Case> cases() {
    std::vector<Case> out;
    for (const AlgorithmInfo* a : conformingAlgorithms())
        for (LightType t : a->lights) out.push_back({a, t});
    return out;
}

class ConformanceGLTest : public test::GLTest, public ::testing::WithParamInterface<Case> {};

TEST_P(ConformanceGLTest, DefaultsGiveValidVisibilityAndExactOnesMatchTheReference) {
    const Case& c = GetParam();
    for (test::Shot (*scene)() : {&test::intersectingTriangles, &test::thousandsOfTriangles}) {
        const test::Shot shot = test::withLight(scene(), c.light);
        test::RunOptions options;
        options.resolution = kRes;
        const test::AlgorithmRun run = test::runAlgorithm(*c.info, shot, {}, options);
        size_t outside = 0;
        for (float v : run.visibility) outside += !(v >= 0.0f && v <= 1.0f);  // NaN counts too
        EXPECT_EQ(outside, 0u) << "pixels with visibility outside [0, 1]";
        EXPECT_EQ(run.overflow, 0u) << "a fixed-size structure overflowed with the defaults";
        EXPECT_GT(run.accuracy.litPixels, 0u) << "the scene must show lit pixels, or nothing is compared";
        if (c.info->exact) EXPECT_LE(run.accuracy.mismatchRatio, kExactMismatch);
    }
}

// The timed pass compiles the statistics out of the shaders; what an algorithm computes must not
// change: the same visibility bit for bit, the same overflow count, and no debug image left to
// write in the timed stages.
TEST_P(ConformanceGLTest, TimedPassGivesBitIdenticalVisibility) {
    const Case& c = GetParam();
    for (test::Shot (*scene)() : {&test::intersectingTriangles, &test::thousandsOfTriangles}) {
        const test::Shot shot = test::withLight(scene(), c.light);
        test::RunOptions options;
        options.resolution = kRes;
        options.withReference = false;
        const test::AlgorithmRun instrumented = test::runAlgorithm(*c.info, shot, {}, options);
        options.statistics = false;
        const test::AlgorithmRun timed = test::runAlgorithm(*c.info, shot, {}, options);
        ASSERT_EQ(instrumented.visibility.size(), timed.visibility.size());
        size_t differing = 0;
        for (size_t i = 0; i < timed.visibility.size(); ++i)
            differing += std::memcmp(&timed.visibility[i], &instrumented.visibility[i], sizeof(float)) != 0;
        EXPECT_EQ(differing, 0u) << "pixels whose visibility differs between the two modes";
        EXPECT_EQ(timed.overflow, instrumented.overflow);
        EXPECT_TRUE(timed.overflowMask.empty()) << "the timed pass still writes the stack_overflow image";
    }
}

class ConformanceTimedPassGLTest : public test::GLTest {};

TEST_F(ConformanceTimedPassGLTest, NoDebugViews) {
    // Every plugin that has statistics drops them, and its debug images, in the timed pass.
    for (const AlgorithmInfo* info : conformingAlgorithms()) {
        AlgorithmHost host(*info, ParamValues(info->schema()), AlgorithmOptions{false});
        EXPECT_TRUE(host.algorithm().debugViews().empty()) << info->name;
        EXPECT_FALSE(host.options().statistics);
    }
}

INSTANTIATE_TEST_SUITE_P(Registry, ConformanceGLTest, ::testing::ValuesIn(cases()), [](const auto& info) {
    return info.param.info->name + "_" + toString(info.param.light);
});

/// Another valid value for a key: the other boolean, another choice, the range's minimum (its
/// maximum where the default is the minimum). Not the maximum first: a size at its maximum can be
/// more than an implementation allocates (shadow_map's 8192² cube map for a point light, 1.5 GiB,
/// is GL_OUT_OF_MEMORY on zink over lavapipe, scripts/portability.sh), and costs time everywhere.
ParamValue alternative(const ParamSpec& s) {
    switch (s.type) {
    case ParamType::Bool: return !std::get<bool>(s.def);
    case ParamType::Int: return std::get<int>(s.def) == int(s.min) ? int(s.max) : int(s.min);
    case ParamType::Float: return std::get<double>(s.def) == s.min ? s.max : s.min;
    case ParamType::Enum:
        for (const auto& choice : s.choices)
            if (choice != std::get<std::string>(s.def)) return choice;
    }
    return s.def;
}

class SchemaConformanceTest : public ::testing::TestWithParam<const AlgorithmInfo*> {};

TEST_P(SchemaConformanceTest, EveryKeyRoundTripsThroughAConfigAndTheGuiSetter) {
    const ParamSchema& schema = GetParam()->schema();
    for (const ParamSpec& s : schema.specs()) {
        SCOPED_TRACE(s.key);
        ParamValues values(schema);
        values.set(s.key, alternative(s));  // the GUI's setter (validated as a config value)
        Json json = values.toJson();
        Json resolved;
        const ParamValues back = ParamValues::parse(schema, JsonNode("config.json", &json, "/params", &resolved));
        EXPECT_EQ(back.toJson(), json);
        EXPECT_EQ(resolved, json);  // what config.resolved.json records
        EXPECT_EQ(back.get(s.key), alternative(s));
        // Out of range or of the wrong type is refused, leaving the value as it was.
        if (s.type == shadowlab::ParamType::Int || s.type == shadowlab::ParamType::Float)
            EXPECT_THROW(values.setJson(s.key, s.max + 1.0), InputError);
        EXPECT_THROW(values.setJson(s.key, Json::array()), InputError);
        EXPECT_EQ(values.get(s.key), alternative(s));
    }
}

INSTANTIATE_TEST_SUITE_P(Registry, SchemaConformanceTest, ::testing::ValuesIn(conformingAlgorithms()),
                         [](const auto& info) { return info.param->name; });

class ChangeConformanceGLTest : public test::GLTest, public ::testing::WithParamInterface<const AlgorithmInfo*> {};

// The host picks the change kind from the keys that changed; each kind, made and undone, must leave
// the algorithm producing the image a fresh instance produces (its structures rebuilt, its programs
// recompiled or its uniforms updated as the kind says, and nothing stale left behind).
TEST_P(ChangeConformanceGLTest, EachChangeKindMadeAndUndoneLeavesTheImageAsItWas) {
    const AlgorithmInfo& info = *GetParam();
    const test::Shot shot = test::withLight(test::thousandsOfTriangles(), info.lights.front());
    SceneGpu gpu(shot.scene);
    GBuffer gbuffer({kRes, kRes});
    gbuffer.render(gpu, shot.camera);
    const CpuGBuffer cpu = gbuffer.readBack();
    const FrameView view{gbuffer, [&]() -> const CpuGBuffer& { return cpu; }, shot.camera, shot.light, 0};
    StageTimer timer;
    const ParamValues defaults(info.schema());
    AlgorithmHost host(info, defaults);
    host.resize({kRes, kRes});
    host.setScene(gpu);
    host.computeFrame(view, timer);
    const std::vector<float> fresh = host.readVisibility();
    int kinds = 0;
    for (ParamChange kind : {ParamChange::Update, ParamChange::Recompile, ParamChange::Rebuild}) {
        const ParamSpec* spec = nullptr;
        for (const ParamSpec& s : info.schema().specs())
            if (s.change == kind && !spec) spec = &s;
        if (!spec) continue;  // the schema has no key of this kind
        ++kinds;
        SCOPED_TRACE(spec->key + " (" + toString(kind) + ")");
        ParamValues changed = defaults;
        changed.set(spec->key, alternative(*spec));
        EXPECT_EQ(host.setParams(changed), kind);
        host.computeFrame(view, timer);  // the changed algorithm runs (its image may differ)
        EXPECT_EQ(host.setParams(defaults), kind);
        host.computeFrame(view, timer);
        const std::vector<float> again = host.readVisibility();
        size_t differ = 0;
        for (size_t i = 0; i < fresh.size(); ++i) differ += std::abs(fresh[i] - again[i]) > 1e-6f;
        EXPECT_EQ(differ, 0u) << "pixels that differ from a fresh instance after the change was undone";
    }
    EXPECT_GE(kinds, 1);
    EXPECT_EQ(host.setParams(defaults), ParamChange::Update) << "no value differs: nothing to apply";
}

INSTANTIATE_TEST_SUITE_P(Registry, ChangeConformanceGLTest, ::testing::ValuesIn(conformingAlgorithms()),
                         [](const auto& info) { return info.param->name; });

} // namespace
} // namespace shadowlab
