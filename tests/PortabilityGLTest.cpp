// The GPU-portability table, run by scripts/portability.sh on every cell of the matrix (llvmpipe
// through OSMesa, zink over lavapipe at 4 and 8 lanes, no ARB_shader_ballot; docs/portability.md):
// every exact algorithm of the registry × every light it supports × every kernel path its schema
// offers (traversal, vote and passes, query and tile, stack), on two small shots, held to the
// reference as the conformance suite holds it: at most 1e-4 of the lit pixels mismatched, overflow 0.
// A path the context cannot run (ballot votes or packet traversal without ARB_shader_ballot) is never
// skipped: the case asserts that the algorithm refuses it, and records the refusal. Where
// SHADOWLAB_MATRIX_CSV names a file, each case appends one row per shot to it, under the cell name
// SHADOWLAB_MATRIX_CELL.
//
// PortabilityCellGLTest checks that the context is the one the matrix cell claims (renderer, back
// end, subgroup width, ballot: SHADOWLAB_MATRIX_* below) and prints what it is, so a cell never
// passes on another implementation than its name says.
#include "algorithms/metric_tree/MetricTree.h"
#include "framework/algorithm/ShadowAlgorithm.h"
#include "framework/core/Error.h"
#include "tests/AlgorithmHarness.h"
#include "tests/TestSupport.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>

namespace shadowlab {
namespace {

// As ConformanceGLTest: an exact algorithm agrees with Embree on every lit pixel; the bound admits
// one pixel in ten thousand (none at this size: about 1,000 to 2,000 lit pixels per shot).
constexpr double kExactMismatch = 1e-4;
constexpr int kRes = 48;

std::string env(const char* name) {
    const char* v = std::getenv(name);
    return v ? std::string(v) : std::string();
}

/// ARB_shader_ballot with a subgroup width the ballot paths compile for.
bool ballotUsable(int width) { return width == 4 || width == 8 || width == 16 || width == 32 || width == 64; }

// ---- The cell ---------------------------------------------------------------------------------------

class PortabilityCellGLTest : public test::GLTest {};

// The matrix script sets what the cell must be; without it (the plain test run) only the context's
// own consistency is checked. SHADOWLAB_MATRIX_RENDERER: the start of GL_RENDERER ("llvmpipe",
// "zink"); SHADOWLAB_MATRIX_BACKEND: "OSMesa" or "EGL"; SHADOWLAB_MATRIX_SUBGROUP: the width
// querySubgroupSize() must give (0 without ARB_shader_ballot); SHADOWLAB_MATRIX_BALLOT: 1 or 0.
TEST_F(PortabilityCellGLTest, ContextIsWhatTheCellClaims) {
    const std::string renderer = glRendererString(), version = glVersionString(), backend = context_->backend();
    const bool ballot = hasExtension("GL_ARB_shader_ballot");
    const int width = querySubgroupSize();
    std::printf("[portability-context] cell=%s; backend=%s; subgroup=%d; ballot=%d; version=%s; renderer=%s\n",
                env("SHADOWLAB_MATRIX_CELL").c_str(), backend.c_str(), width, ballot ? 1 : 0, version.c_str(),
                renderer.c_str());
    std::fflush(stdout);
    EXPECT_EQ(width == 0, !ballot) << "querySubgroupSize() is 0 exactly when ARB_shader_ballot is absent";
    if (ballot) EXPECT_TRUE(ballotUsable(width)) << "subgroup width " << width;
    // llvmpipe (and lavapipe under zink) names its vector width: 32-bit lanes of it make a subgroup.
    std::smatch bits;
    if (ballot && renderer.find("llvmpipe") != std::string::npos &&
        std::regex_search(renderer, bits, std::regex("([0-9]+) bits")))
        EXPECT_EQ(width, std::stoi(bits[1]) / 32) << "subgroup width against the renderer's vector width: " << renderer;

    const std::string wantRenderer = env("SHADOWLAB_MATRIX_RENDERER"), wantBackend = env("SHADOWLAB_MATRIX_BACKEND"),
                      wantWidth = env("SHADOWLAB_MATRIX_SUBGROUP"), wantBallot = env("SHADOWLAB_MATRIX_BALLOT");
    if (!wantRenderer.empty()) EXPECT_EQ(renderer.rfind(wantRenderer, 0), 0u) << "renderer " << renderer << ", want " << wantRenderer;
    if (!wantBackend.empty()) EXPECT_EQ(backend, wantBackend);
    if (!wantWidth.empty()) EXPECT_EQ(std::to_string(width), wantWidth) << "subgroup width";
    if (!wantBallot.empty()) EXPECT_EQ(ballot ? "1" : "0", wantBallot) << "GL_ARB_shader_ballot present";
}

// ---- The table -------------------------------------------------------------------------------------

/// One kernel path of an algorithm: parameter overrides, whether it needs ARB_shader_ballot, and
/// the path counters it must report (as a function of the context's subgroup width; 0: none).
struct Variant {
    std::string name;
    std::map<std::string, ParamValue> params;
    bool needsBallot = false;
    std::function<std::map<std::string, double>(int width)> expect;
};

ParamValue str(const char* s) { return std::string(s); }

/// The paths of each exact algorithm; an exact algorithm not named here runs its defaults only.
/// PortabilityTableTest checks that every choice of each algorithm's path keys appears.
const std::map<std::string, std::vector<Variant>>& variants() {
    using Counters = std::map<std::string, double>;
    // ptsv's vote_path counter: 0 shared memory, 1 ballot, 2 none (one job per invocation).
    auto ptsvPath = [](double vote, double packet, int lanes) {
        return [=](int w) { return Counters{{"vote_path", vote}, {"packet_traversal", packet}, {"traversal_lanes", lanes < 0 ? double(w) : double(lanes)}}; };
    };
    auto ptsvCooperativeAuto = [](int w) {
        return Counters{{"vote_path", ballotUsable(w) ? 1.0 : 0.0}, {"traversal_lanes", ballotUsable(w) ? double(w) : 32.0}};
    };
    // auto with two passes: cooperative on ballot subgroups of 32 lanes or more, else one job per
    // invocation, walking as packets in pass one where ARB_shader_ballot is there.
    auto ptsvAuto = [](int w) {
        if (ballotUsable(w) && w >= 32) return Counters{{"vote_path", 1.0}, {"packet_traversal", 0.0}};
        return Counters{{"vote_path", 2.0}, {"packet_traversal", ballotUsable(w) ? 1.0 : 0.0}};
    };
    auto tilePixels = [](double px) { return [=](int) { return Counters{{"tile_pixels", px}, {"stack_overflow_pixels", 0.0}}; }; };
    static const std::map<std::string, std::vector<Variant>> table = {
        {"psv",
         {{"defaults", {}},
          {"no_wedge", {{"wedge", false}}},
          {"exact_wedge", {{"wedge_bound", str("exact")}}},
          {"depth_skip", {{"depth_skip", true}}},
          {"scene_order", {{"random_order", false}}},
          {"transparency", {{"transparency", true}, {"stack_size", 64}}},
          {"stack", {{"traversal", str("stack")}}},
          {"stackless", {{"traversal", str("stackless")}}},
          {"stackless_depth_skip", {{"traversal", str("stackless")}, {"depth_skip", true}}},
          {"hybrid", {{"traversal", str("hybrid")}}},
          {"hybrid_stack_1", {{"traversal", str("hybrid")}, {"hybrid_stack", 1}}}}},
        {"bvh_raytrace", {{"defaults", {}}, {"short_stack", {{"short_stack", true}}}}},
        {"ptsv",
         {{"auto", {}, false, ptsvAuto},
          {"cooperative_ballot", {{"traversal", str("cooperative")}, {"vote", str("ballot")}}, true, ptsvPath(1, 0, -1)},
          {"cooperative_shared", {{"traversal", str("cooperative")}, {"vote", str("shared")}}, false, ptsvPath(0, 0, 32)},
          {"cooperative_auto_vote", {{"traversal", str("cooperative")}}, false, ptsvCooperativeAuto},
          {"invocation", {{"traversal", str("invocation")}}, false, ptsvPath(2, 0, 1)},
          {"packet", {{"traversal", str("packet")}}, true, ptsvPath(2, 1, 1)},
          {"one_pass_auto", {{"two_pass", false}}, false, ptsvCooperativeAuto},
          {"one_pass_cooperative_ballot", {{"two_pass", false}, {"traversal", str("cooperative")}, {"vote", str("ballot")}}, true, ptsvPath(1, 0, -1)},
          {"one_pass_cooperative_shared", {{"two_pass", false}, {"traversal", str("cooperative")}, {"vote", str("shared")}}, false, ptsvPath(0, 0, 32)},
          {"one_pass_invocation", {{"two_pass", false}, {"traversal", str("invocation")}}, false, ptsvPath(2, 0, 1)},
          {"one_pass_packet", {{"two_pass", false}, {"traversal", str("packet")}}, true, ptsvPath(2, 1, 1)},
          {"implicit_bounds", {{"bounds", str("implicit")}}, false, ptsvAuto}}},
        {"metric_tree",
         {{"pixel_query", {{"query", str("pixel")}}, false, tilePixels(0)},
          {"tile_auto", {}, false, [](int w) { return Counters{{"tile_pixels", double(autoTilePixels(w))}}; }},
          {"tile_4x2", {{"tile", str("4x2")}}, false, tilePixels(8)},
          {"tile_8x2", {{"tile", str("8x2")}}, false, tilePixels(16)},
          {"tile_8x4", {{"tile", str("8x4")}}, false, tilePixels(32)},
          {"tile_8x8", {{"tile", str("8x8")}}, false, tilePixels(64)}}},
        // light_facing volumes are exact on closed meshes only, and both shots hold open ones: the
        // accuracy table runs them (ShadowVolumesGLTest.cpp), in every cell through SUITES.
        {"shadow_volumes",
         {{"zfail", {}},
          {"zpass", {{"method", str("zpass")}}},
          {"hardware_depth_test", {{"depth_test", str("hardware")}}},
          {"hardware_zpass", {{"depth_test", str("hardware")}, {"method", str("zpass")}}}}},
        {"izb", {{"defaults", {}}, {"no_cell_test", {{"cell_test", false}}}, {"fitted_grid", {{"grid_fit", str("samples")}}}}},
    };
    return table;
}

/// The keys whose every value is a kernel path of its own (PortabilityTableTest).
const std::map<std::string, std::vector<std::string>> kPathKeys = {
    {"psv", {"wedge", "depth_skip", "random_order", "transparency", "traversal"}},
    {"bvh_raytrace", {"short_stack"}},
    {"ptsv", {"traversal", "vote", "two_pass", "bounds"}},
    {"metric_tree", {"query", "tile"}},
    {"shadow_volumes", {"method", "depth_test"}},
    {"izb", {"cell_test", "grid_fit"}},
};

struct Case {
    const AlgorithmInfo* info;
    LightType light;
    Variant variant;
};

void PrintTo(const Case& c, std::ostream* os) {
    test::printCase(*os, (c.info->name + " " + toString(c.light) + " " + c.variant.name).c_str(), c.variant.params);
}

std::vector<Case> cases() {
    static const std::vector<Variant> defaultsOnly = {{"defaults", {}}};
    std::vector<Case> out;
    for (const AlgorithmInfo& a : algorithmRegistry()) {
        if (!a.exact) continue;
        const auto it = variants().find(a.name);
        for (LightType t : a.lights)
            for (const Variant& v : it == variants().end() ? defaultsOnly : it->second) out.push_back({&a, t, v});
    }
    return out;
}

struct NamedShot {
    const char* name;
    test::Shot (*make)();
};
const NamedShot kShots[] = {{"intersecting_triangles", &test::intersectingTriangles},
                            {"thousands_of_triangles", &test::thousandsOfTriangles}};

/// The path an algorithm reports having taken, for the table (counters of the timed pass).
std::string pathOf(const std::string& algorithm, std::map<std::string, double> c) {
    std::ostringstream s;
    if (algorithm == "ptsv") {
        const int vote = int(c["vote_path"]);
        s << (vote == 1 ? "ballot votes" : vote == 0 ? "shared votes" : "per invocation") << ", lanes "
          << c["traversal_lanes"] << (c["packet_traversal"] > 0 ? ", packets" : "");
    } else if (algorithm == "metric_tree") {
        if (c["tile_pixels"] == 0) s << "pixel query";
        else s << "tile of " << c["tile_pixels"] << " px, " << c["tile_fallbacks"] << " fallbacks";
    }
    return s.str();
}

/// A CSV field: quoted where it holds a comma or a quote.
std::string field(const std::string& v) {
    if (v.find_first_of(",\"\n") == std::string::npos) return v;
    std::string q = "\"";
    for (char ch : v) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
}

constexpr const char* kCsvHeader =
    "cell,algorithm,light,variant,scene,outcome,path,lit_pixels,mismatched_pixels,mismatch,overflow,frame_ms,case_ms\n";

void appendRow(const std::vector<std::string>& fields) {
    const std::string path = env("SHADOWLAB_MATRIX_CSV");
    if (path.empty()) return;
    std::error_code ec;
    const bool fresh = !std::filesystem::exists(path, ec) || std::filesystem::file_size(path, ec) == 0;
    std::string row = fresh ? kCsvHeader : "";
    for (size_t i = 0; i < fields.size(); ++i) row += (i ? "," : "") + field(fields[i]);
    row += "\n";
    FILE* f = std::fopen(path.c_str(), "a");
    ASSERT_NE(f, nullptr) << "cannot append to SHADOWLAB_MATRIX_CSV " << path;
    const bool written = std::fputs(row.c_str(), f) >= 0;
    EXPECT_TRUE(std::fclose(f) == 0 && written) << "writing " << path;
}

std::string number(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

class PortabilityGLTest : public test::GLTest, public ::testing::WithParamInterface<Case> {};

TEST_P(PortabilityGLTest, ExactOnEveryPath) {
    const Case& c = GetParam();
    const int width = querySubgroupSize();
    const std::string cell = env("SHADOWLAB_MATRIX_CELL").empty() ? "unnamed" : env("SHADOWLAB_MATRIX_CELL");
    for (const NamedShot& named : kShots) {
        SCOPED_TRACE(named.name);
        const test::Shot shot = test::withLight(named.make(), c.light);
        test::RunOptions options;
        options.resolution = kRes;
        options.statistics = false;  // the timed pass's shaders, as an experiment times them
        options.warmUp = true;            // the measured frame without the first dispatch's compile
        options.synchronousStages = true; // wall time per stage on every implementation
        const auto start = std::chrono::steady_clock::now();
        auto elapsedMs = [&] { return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count(); };
        std::vector<std::string> row = {cell, c.info->name, toString(c.light), c.variant.name, named.name};
        if (c.variant.needsBallot && !ballotUsable(width)) {
            // Not skipped: without ARB_shader_ballot the algorithm must refuse the path by name.
            std::string refusal;
            try {
                test::runAlgorithm(*c.info, shot, c.variant.params, options);
            } catch (const RuntimeError& e) {
                refusal = e.what();
            }
            EXPECT_NE(refusal.find("ARB_shader_ballot"), std::string::npos)
                << "without ARB_shader_ballot (subgroup width " << width << ") the path must be refused, naming the extension; got: "
                << (refusal.empty() ? "it ran" : refusal);
            std::printf("[portability] %s %s %s %s: refused (%s)\n", c.info->name.c_str(), toString(c.light),
                        c.variant.name.c_str(), named.name, refusal.c_str());
            row.insert(row.end(), {"refused", refusal, "", "", "", "", "", number(elapsedMs(), 1)});
            appendRow(row);
            continue;
        }
        const test::AlgorithmRun run = test::runAlgorithm(*c.info, shot, c.variant.params, options);
        const double caseMs = elapsedMs();
        double frameMs = 0;
        for (const StageTime& s : run.stages) frameMs += s.cpuMs;
        std::map<std::string, double> counters = run.counters;
        const size_t mismatched = size_t(std::llround(run.accuracy.mismatchRatio * double(run.accuracy.litPixels)));
        size_t outside = 0;
        for (float v : run.visibility) outside += !(v >= 0.0f && v <= 1.0f);
        bool pathTaken = true;
        if (c.variant.expect)
            for (const auto& [name, want] : c.variant.expect(width)) {
                const auto it = counters.find(name);
                const bool same = it != counters.end() && it->second == want;
                EXPECT_TRUE(same) << "counter " << name << " is " << (it == counters.end() ? std::string("missing") : number(it->second, 0))
                                  << ", the variant's path gives " << want;
                pathTaken &= same;
            }
        const bool exact = outside == 0 && run.accuracy.litPixels > 0 && run.accuracy.mismatchRatio <= kExactMismatch;
        EXPECT_EQ(outside, 0u) << "pixels with visibility outside [0, 1]";
        EXPECT_GT(run.accuracy.litPixels, 0u) << "the shot must show lit pixels, or nothing is compared";
        EXPECT_LE(run.accuracy.mismatchRatio, kExactMismatch) << mismatched << " of " << run.accuracy.litPixels << " lit pixels";
        EXPECT_EQ(run.overflow, 0u);
        const std::string path = pathOf(c.info->name, counters);
        std::printf("[portability] %s %s %s %s: lit %zu mismatched %zu overflow %llu frame %.2f ms%s%s\n", c.info->name.c_str(),
                    toString(c.light), c.variant.name.c_str(), named.name, run.accuracy.litPixels, mismatched,
                    static_cast<unsigned long long>(run.overflow), frameMs, path.empty() ? "" : ", ", path.c_str());
        const char* outcome = !exact ? "mismatch" : run.overflow ? "overflow" : !pathTaken ? "wrong path" : "exact";
        row.insert(row.end(), {outcome, path, std::to_string(run.accuracy.litPixels),
                               std::to_string(mismatched), number(run.accuracy.mismatchRatio, 6), std::to_string(run.overflow),
                               number(frameMs, 2), number(caseMs, 1)});
        appendRow(row);
    }
}

INSTANTIATE_TEST_SUITE_P(Table, PortabilityGLTest, ::testing::ValuesIn(cases()), [](const auto& info) {
    return info.param.info->name + "_" + toString(info.param.light) + "_" + info.param.variant.name;
});

// ---- The table's coverage (no GL) -------------------------------------------------------------------

// Every exact algorithm is in the table; every variant's keys exist in its schema; every value of
// each path key (each choice, both booleans) is run by some variant, the defaults counting for theirs.
TEST(PortabilityTableTest, CoversEveryPathOfEveryExactAlgorithm) {
    std::set<std::string> exact;
    for (const AlgorithmInfo& a : algorithmRegistry())
        if (a.exact) exact.insert(a.name);
    for (const auto& [name, list] : variants()) {
        SCOPED_TRACE(name);
        ASSERT_TRUE(exact.count(name)) << "not an exact algorithm of the registry";
        const ParamSchema& schema = findAlgorithm(name)->schema();
        for (const Variant& v : list)
            for (const auto& [key, value] : v.params) EXPECT_NE(schema.find(key), nullptr) << v.name << ": no key " << key;
        ASSERT_TRUE(kPathKeys.count(name)) << "its path keys are not listed";
        for (const std::string& key : kPathKeys.at(name)) {
            const ParamSpec* spec = schema.find(key);
            ASSERT_NE(spec, nullptr) << key;
            std::vector<ParamValue> values;
            if (spec->type == ParamType::Bool) values = {true, false};
            else if (spec->type == ParamType::Enum)
                for (const std::string& choice : spec->choices) values.push_back(choice);
            else ADD_FAILURE() << key << " is neither a choice nor a boolean";
            for (const ParamValue& want : values) {
                bool covered = false;
                for (const Variant& v : list) {
                    const auto it = v.params.find(key);
                    covered |= (it == v.params.end() ? spec->def : it->second) == want;
                }
                EXPECT_TRUE(covered) << key << " = " << toString(want) << " is run by no variant";
            }
        }
    }
    EXPECT_GE(cases().size(), exact.size());
}

} // namespace
} // namespace shadowlab
