// ptsv (per-triangle shadow volumes through a view-sample cluster hierarchy) on OSMesa: visibility
// against the Embree reference on a table of scenes and ablations, the hierarchy built on the GPU
// checked node by node on the CPU, explicit against implicit bounds, the job list's overflow, the
// heat map, and the vote paths agreeing.
#include "algorithms/ptsv/Ptsv.h"
#include "algorithms/ptsv/PtsvLayout.h"
#include "framework/core/Error.h"
#include "framework/scene/GltfLoader.h"
#include "framework/scene/Procedural.h"
#include "tests/AlgorithmHarness.h"
#include "tests/TestSupport.h"

#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <set>

namespace shadowlab {
namespace {

using namespace test;

// ---- Scenes (the shared ones are in tests/ShadowTestScenes.h) -----------------------------------

// The paper's Figure 1 situation: a far building seen through a near fence (every tile holds
// samples at two very different depths), thin posts and a sphere casting in between.
Shot fenceDiscontinuity() {
    Shot s;
    s.scene = ground(30.0f);
    Scene box = makeCylinder(1.0f, 1.0f, 8, Material{glm::vec3(0.6f, 0.5f, 0.4f), 1.0f}); // 4-sided: a box
    s.scene.append(box, translate({0, 0, -12}) * rotate(45, {0, 1, 0}) * scale({4, 4, 4}));
    s.scene.append(makeFence(9, 0.12f, 0.9f, 0.02f, 2, 16, Material{glm::vec3(0.3f, 0.3f, 0.3f), 1.0f}),
                   translate({-0.5f, 0, 1.8f}));
    for (int i = 0; i < 5; ++i)
        s.scene.append(makeCylinder(0.05f, 3.0f, 24, Material{}), translate({-2.0f + i * 1.0f, 0, -4.0f - i}));
    s.scene.append(makeSphere(0.5f, 400, Material{}), translate({1.0f, 1.0f, -6.0f}));
    s.camera = lookAt({0.0f, 0.6f, 2.6f}, {0.0f, 1.0f, -10.0f});
    s.light = pointLight({-4.0f, 7.0f, -2.0f});
    return s;
}

// The two traversals (`traversal` = auto picks one per device), named so every row can say which.
const std::pair<const std::string, ParamValue> kCooperative{"traversal", std::string("cooperative")};
const std::pair<const std::string, ParamValue> kPerInvocation{"traversal", std::string("invocation")};
const std::pair<const std::string, ParamValue> kPacket{"traversal", std::string("packet")};

// ---- Running ptsv and the reference --------------------------------------------------------------

struct Outcome : AlgorithmRun {
    std::vector<float> heat;
};

class PtsvGLTest : public test::GLTest {
protected:
    Outcome run(const Shot& s, const std::map<std::string, ParamValue>& overrides = {}, bool withReference = true,
                const std::function<void()>& inspect = {}) {
        RunOptions options;
        options.withReference = withReference;
        options.debugViews = {"tests_per_pixel"};
        if (inspect) options.inspect = [&](const AlgorithmRun&) { inspect(); }; // ptsv's buffers are still bound here
        Outcome o;
        static_cast<AlgorithmRun&>(o) = runAlgorithm(ptsvInfo(), s, overrides, options);
        o.heat = std::move(o.views["tests_per_pixel"]);
        return o;
    }
    /// Without ARB_shader_ballot ptsv refuses `vote: ballot`: checked here; true when that is all
    /// there is to test on this GL.
    bool refusesBallotVotesHere() {
        if (querySubgroupSize() != 0) return false;
        EXPECT_THROW(run(thousandsOfTriangles(), {kCooperative, {"vote", std::string("ballot")}}), std::exception);
        return true;
    }
};

// ---- Accuracy table ------------------------------------------------------------------------------

// ptsv is exact: its per-sample test is the reference's ray (same origin, same closed-edge
// convention as a watertight ray-triangle test), so every row is held to the goal of 0.01 % of lit
// pixels (the requirement is 0.1 %), which at 96² (4,000 to 9,000 lit pixels) allows no
// mismatching pixel; llvmpipe meets it on every row. The node tests only cull or accept with a
// margin, so no ablation may change a single pixel either.
const AccuracyCase kAccuracy[] = {
    {"intersecting_triangles", intersectingTriangles, {}, 1e-4},
    {"omni_inside_shell", omniInsideShell, {}, 1e-4},
    {"omni_inside_shell_ffc", omniInsideShell, {{"front_face_culling", true}}, 1e-4}, // closed shell and room
    {"directional", directionalObjects, {}, 1e-4},
    {"directional_implicit", directionalObjects, {{"bounds", std::string("implicit")}}, 1e-4},
    {"directional_ffc", directionalObjects, {{"front_face_culling", true}}, 1e-4},
    {"camera_inside_shadow", cameraInsideShadow, {}, 1e-4},
    {"camera_inside_shadow_implicit", cameraInsideShadow, {{"bounds", std::string("implicit")}}, 1e-4},
    {"fence", fenceDiscontinuity, {}, 1e-4},
    {"fence_implicit_one_pass", fenceDiscontinuity,
     {{"bounds", std::string("implicit")}, {"two_pass", false}, {"culling_planes", false}}, 1e-4},
    {"fence_implicit_planes", fenceDiscontinuity, {{"bounds", std::string("implicit")}, {"two_pass", false}}, 1e-4},
    {"fence_explicit_one_pass", fenceDiscontinuity, {{"two_pass", false}}, 1e-4},
    {"fence_split_1", fenceDiscontinuity, {{"split_level", 1}}, 1e-4},
    {"fence_split_leaves", fenceDiscontinuity, {{"split_level", PTSV_MAX_LEVELS}}, 1e-4}, // clamped to the clusters
    {"fence_tile_4", fenceDiscontinuity, {{"tile_size", 4}}, 1e-4},
    {"fence_tile_16_implicit", fenceDiscontinuity, {{"tile_size", 16}, {"bounds", std::string("implicit")}}, 1e-4},
    {"fence_leaf_cluster", fenceDiscontinuity, {{"leaf_samples", std::string("cluster")}}, 1e-4},
    {"fence_batches_of_5", fenceDiscontinuity, {kCooperative, {"jobs_per_workgroup", 5}}, 1e-4},
    {"fence_slices_merged", fenceDiscontinuity, {{"max_key_bits", 11}}, 1e-4}, // 15 bits → 4 merges, 2 levels
    {"fence_slices_merged_implicit", fenceDiscontinuity, {{"max_key_bits", 11}, {"bounds", std::string("implicit")}}, 1e-4},
    {"fence_batches_of_3_shared", fenceDiscontinuity, {kCooperative, {"jobs_per_workgroup", 3}, {"vote", std::string("shared")}}, 1e-4},
    {"thousands_shared_vote", thousandsOfTriangles, {kCooperative, {"vote", std::string("shared")}}, 1e-4},
    {"thousands_shared_vote_implicit", thousandsOfTriangles, {kCooperative, {"vote", std::string("shared")}, {"bounds", std::string("implicit")}}, 1e-4},
    // Both traversals by name (the rows above run the device's `auto` choice).
    {"directional_cooperative", directionalObjects, {kCooperative}, 1e-4},
    {"directional_invocation", directionalObjects, {kPerInvocation}, 1e-4},
    {"fence_cooperative", fenceDiscontinuity, {kCooperative}, 1e-4},
    {"fence_cooperative_implicit_one_pass", fenceDiscontinuity, {kCooperative, {"bounds", std::string("implicit")}, {"two_pass", false}}, 1e-4},
    {"fence_invocation", fenceDiscontinuity, {kPerInvocation}, 1e-4},
    {"fence_invocation_implicit_one_pass", fenceDiscontinuity, {kPerInvocation, {"bounds", std::string("implicit")}, {"two_pass", false}}, 1e-4},
    {"fence_invocation_split_1_cluster", fenceDiscontinuity, {kPerInvocation, {"split_level", 1}, {"leaf_samples", std::string("cluster")}}, 1e-4},
    {"thousands_cooperative", thousandsOfTriangles, {kCooperative}, 1e-4},
    {"thousands_invocation", thousandsOfTriangles, {kPerInvocation}, 1e-4},
    {"engine_cooperative", engineOnGround, {kCooperative}, 1e-4},
    {"engine_invocation", engineOnGround, {kPerInvocation}, 1e-4},
    {"directional_packet", directionalObjects, {kPacket}, 1e-4},
    {"fence_packet", fenceDiscontinuity, {kPacket}, 1e-4},
    {"fence_packet_implicit_one_pass", fenceDiscontinuity, {kPacket, {"bounds", std::string("implicit")}, {"two_pass", false}}, 1e-4},
    {"fence_packet_split_1_cluster", fenceDiscontinuity, {kPacket, {"split_level", 1}, {"leaf_samples", std::string("cluster")}}, 1e-4},
    {"thousands_packet", thousandsOfTriangles, {kPacket}, 1e-4},
    {"engine_packet", engineOnGround, {kPacket}, 1e-4},
    {"thousands_no_planes", thousandsOfTriangles, {{"culling_planes", false}}, 1e-4},
    {"thousands_plane_bias", thousandsOfTriangles, {{"plane_bias", 1e-6}}, 1e-4}, // no caster touches a receiver
    {"engine", engineOnGround, {}, 1e-4},
    // Spot lights: the samples outside the cone take no part; the cone cuts the ground and casters.
    {"spot", smokeSpotShot, {}, 1e-4},
    {"spot_narrow_cooperative", narrowSpot, {kCooperative}, 1e-4},
    {"spot_narrow_invocation_implicit", narrowSpot, {kPerInvocation, {"bounds", std::string("implicit")}}, 1e-4},
};

class PtsvAccuracyGLTest : public PtsvGLTest, public ::testing::WithParamInterface<AccuracyCase> {};

TEST_P(PtsvAccuracyGLTest, MatchesReference) {
    const AccuracyCase& c = GetParam();
    Outcome o = run(c.make(), c.params);
    std::printf("[ptsv] %-30s lit %5zu mismatch %.5f%% (false lit %.5f%%) test-and-set %.0f node tests %.0f "
                "iterations max %.0f/%.0f accepted %.0f\n",
                c.name, o.accuracy.litPixels, 100 * o.accuracy.mismatchRatio, 100 * o.accuracy.falseLit,
                o.counters["test_and_set"], o.counters["node_tests"], o.counters["iterations_max_pass1"],
                o.counters["iterations_max_pass2"], o.counters["accepted_nodes"]);
    EXPECT_GT(o.accuracy.litPixels, size_t(kRes * kRes / 8)) << "the view should show lit surfaces";
    EXPECT_LE(o.accuracy.mismatchRatio, c.maxMismatch);
    EXPECT_EQ(o.overflow, 0u);
    EXPECT_EQ(o.counters["truncated_jobs"], 0.0);
    // Both shadowed and lit pixels must exist, or the scene tests nothing.
    size_t shadowed = 0;
    for (size_t i = 0; i < o.lit.size(); ++i) shadowed += o.lit[i] && o.reference[i] < 0.5f;
    EXPECT_GT(shadowed, size_t(50));
    EXPECT_LT(shadowed + 50, o.accuracy.litPixels);
}

INSTANTIATE_TEST_SUITE_P(Table, PtsvAccuracyGLTest, ::testing::ValuesIn(kAccuracy),
                         [](const auto& info) { return std::string(info.param.name); });

// ---- Cost, structure and robustness ----------------------------------------------------------------

// Paper 2.1: tight bounds cull far more than the clusters' implicit frusta, above all where tiles
// mix near and far samples (Figure 6: often more than 2× fewer test-and-set operations).
TEST_F(PtsvGLTest, ExplicitBoundsNeedFewerTestAndSets) {
    Shot s = fenceDiscontinuity();
    Outcome ex = run(s, {{"two_pass", false}}, false), im = run(s, {{"two_pass", false}, {"bounds", std::string("implicit")}}, false);
    const double ratio = im.counters["test_and_set"] / ex.counters["test_and_set"];
    std::printf("[ptsv] fence: test-and-set explicit %.0f implicit %.0f (x%.2f); node tests %.0f / %.0f\n",
                ex.counters["test_and_set"], im.counters["test_and_set"], ratio, ex.counters["node_tests"],
                im.counters["node_tests"]);
    EXPECT_GE(ratio, 2.0);
    // The additional planes only ever remove work.
    Outcome bare = run(s, {{"two_pass", false}, {"culling_planes", false}}, false);
    EXPECT_LE(ex.counters["test_and_set"], bare.counters["test_and_set"]);
}

// Pass one stops at the split depth; pass two's jobs then need few iterations each (Figure 7: the
// largest jobs of the one-pass traversal take many times the average). The default split: the
// clusters' parents (paper) with cooperative jobs, the clusters themselves with one job per invocation.
TEST_F(PtsvGLTest, TwoPassesSplitTheLargestJobs) {
    Shot s = fenceDiscontinuity();
    for (const auto& traversal : {kCooperative, kPerInvocation, kPacket}) {
        SCOPED_TRACE(std::get<std::string>(traversal.second));
        const bool cooperative = std::get<std::string>(traversal.second) == "cooperative";
        Outcome one = run(s, {traversal, {"two_pass", false}, {"job_iterations", true}}, false);
        Outcome two = run(s, {traversal, {"job_iterations", true}}, false);
        std::printf("[ptsv] fence: largest job %.0f iterations in one pass (1024 largest: mean %.1f, all: %.2f); "
                    "two passes: %.0f / %.0f (1024 largest: %.1f / %.1f), %.0f jobs\n",
                    one.counters["iterations_max_pass1"], one.counters["iterations_top1024_mean_pass1"],
                    one.counters["iterations_mean_pass1"], two.counters["iterations_max_pass1"],
                    two.counters["iterations_max_pass2"], two.counters["iterations_top1024_mean_pass1"],
                    two.counters["iterations_top1024_mean_pass2"], two.counters["jobs"]);
        EXPECT_GT(two.counters["jobs"], 0.0);
        EXPECT_LT(two.counters["iterations_max_pass1"], one.counters["iterations_max_pass1"]);
        EXPECT_LT(two.counters["iterations_max_pass2"], one.counters["iterations_max_pass1"]);
        EXPECT_LT(two.counters["iterations_top1024_mean_pass2"], one.counters["iterations_top1024_mean_pass1"]);
        EXPECT_GE(one.counters["iterations_top1024_mean_pass1"], one.counters["iterations_mean_pass1"]);
        EXPECT_EQ(two.counters["split_depth"], two.counters["tree_levels"] - (cooperative ? 1 : 0));
        EXPECT_EQ(two.visibility, one.visibility);
    }
}

// A job list of one entry overflows at once: every further job is finished by pass one, counted,
// and the image stays exact. Packets need ARB_shader_ballot: without it ptsv must refuse them.
TEST_F(PtsvGLTest, TinyJobListOverflowsButStaysExact) {
    const int width = querySubgroupSize();
    const bool ballotUsable = width == 4 || width == 8 || width == 16 || width == 32 || width == 64;
    for (const auto& traversal : {kCooperative, kPerInvocation, kPacket}) {
        SCOPED_TRACE(std::get<std::string>(traversal.second));
        if (traversal == kPacket && !ballotUsable) {
            EXPECT_THROW(run(thousandsOfTriangles(), {traversal, {"job_capacity", 1}}), RuntimeError);
            continue;
        }
        Outcome o = run(thousandsOfTriangles(), {traversal, {"job_capacity", 1}});
        std::printf("[ptsv] job_capacity 1: %.0f jobs overflowed, overflowCount %llu, mismatch %.5f%%\n",
                    o.counters["job_overflow"], (unsigned long long)o.overflow, 100 * o.accuracy.mismatchRatio);
        EXPECT_GT(o.counters["job_overflow"], 100.0);
        EXPECT_EQ(o.overflow, uint64_t(o.counters["job_overflow"]));
        EXPECT_EQ(o.counters["jobs"], 1.0);
        EXPECT_LE(o.accuracy.mismatchRatio, 1e-4);
    }
}

// ---- Faults a GPU may show and a software GL does not (framework/gl/Shader.h) ----------------------

// A job counter that wraps after capacity + 64 pushes instead of 2^32 (a fault site, test-only: the
// wrap a flood of pushes, ~1,000 times the capacity, would cause) must not hand out the slots of
// live jobs again: a walker whose push overwrote one would leave its subtree to a job nobody runs.
TEST_F(PtsvGLTest, FaultPushFloodOverwritesNoJob) {
    ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_PUSH_FLOOD", "1"}});
    for (const auto& traversal : {kCooperative, kPerInvocation}) {
        SCOPED_TRACE(std::get<std::string>(traversal.second));
        Outcome o = run(thousandsOfTriangles(), {traversal, {"job_capacity", 64}});
        EXPECT_GT(o.counters["job_overflow"], 100.0);
        EXPECT_EQ(o.accuracy.mismatchRatio, 0.0);
        EXPECT_EQ(o.accuracy.falseLit, 0.0);
    }
}

// A culled triangle's status survives a GPU that flushes denormals (GLSL 4.50 section 4.7.1), and
// its planes are never a previous frame's: with every plane read flushed and the plane buffer
// filled beforehand with planes that would shadow everything, every culled triangle (front faces,
// and those whose plane holds the light) still casts nothing. The old status, the bit pattern
// uintBitsToFloat(1u or 2u), read as 0 (= caster) here and shadowed most of the image.
TEST_F(PtsvGLTest, FaultFlushedStatusAndStalePlanesCastNothing) {
    const Shot s = withEdgeOnWall(fenceDiscontinuity()); // status 1: edge-on
    ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_FLUSH_DENORMALS", "1"}, {"SHADOWLAB_FAULT_STALE_PLANES", "1"}});
    for (const auto& traversal : {kCooperative, kPerInvocation, kPacket})
        for (bool ffc : {false, true}) {
            SCOPED_TRACE(std::get<std::string>(traversal.second) + (ffc ? ", front-face culling" : ""));
            if (traversal == kPacket && querySubgroupSize() == 0) { // packets need ARB_shader_ballot: refused
                EXPECT_THROW(run(s, {traversal, {"front_face_culling", ffc}}), std::exception);
                continue;
            }
            Outcome o = run(s, {traversal, {"front_face_culling", ffc}});
            EXPECT_GT(o.counters["culled_edge_on"], 0.0) << "the wall is edge-on";
            if (ffc) EXPECT_GT(o.counters["culled_front_facing"], 0.0);
            EXPECT_LE(o.accuracy.mismatchRatio, 1e-4);
            EXPECT_EQ(o.overflow, 0u);
        }
}

// Lanes need not reconverge after divergent code (ARB_shader_ballot gives no such promise): a vote
// that misses a lane is seen by its paired ballot, and the node is then classified by each lane
// alone, so the image stays exact and the recovery is counted. The fault leaves lane 1 out of every
// vote; the old votes lost its children (missing shadows). A broadcast that does not come from
// lane 0 (the job-list slot in pass one, which matters when the list is full) makes the subtree
// finish where it is.
TEST_F(PtsvGLTest, FaultLaneMissingFromVotesIsRecoveredExactly) {
    if (refusesBallotVotesHere()) return;
    const std::map<std::string, ParamValue> ballot = {kCooperative, {"vote", std::string("ballot")}};
    Outcome clean = run(thousandsOfTriangles(), ballot);
    EXPECT_EQ(clean.counters["vote_recoveries"], 0.0) << "no lane is ever missing on its own";
    {
        ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_VOTE_DROPS_LANE", "1"}});
        for (bool twoPass : {true, false}) {
            SCOPED_TRACE(twoPass ? "two passes" : "one pass");
            std::map<std::string, ParamValue> p = ballot;
            p["two_pass"] = twoPass;
            Outcome o = run(thousandsOfTriangles(), p);
            EXPECT_GT(o.counters["vote_recoveries"], 0.0);
            EXPECT_LE(o.accuracy.mismatchRatio, 1e-4);
            EXPECT_EQ(o.overflow, 0u);
            EXPECT_EQ(o.visibility, clean.visibility);
        }
    }
    ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_BROADCAST_MISSES_LEADER", "1"}});
    std::map<std::string, ParamValue> p = ballot;
    p["job_capacity"] = 1; // almost every push fails: the broadcast slot decides who finishes the subtree
    Outcome o = run(thousandsOfTriangles(), p);
    EXPECT_GT(o.counters["vote_recoveries"], 0.0);
    EXPECT_LE(o.accuracy.mismatchRatio, 1e-4);
    EXPECT_EQ(o.visibility, clean.visibility);
}

// Lanes that part ways once (a fault site, test-only: the odd lanes miss the first vote of their
// workgroup and classify that node alone, conservatively, every child intersected) stand at
// different nodes from then on. Before the lanes went alone for good, they voted again as soon as
// they met at the same ballot, and each lane read the verdicts of the other half's node as its own:
// children lost (lit pixels) and children accepted that the volume never covered (shadowed ones).
// A lane that recovered once now walks alone for the rest of its batch, and the voting lanes
// follow it at their next ballot.
TEST_F(PtsvGLTest, FaultLanesThatPartWaysNeverVoteAgain) {
    if (refusesBallotVotesHere()) return;
    for (bool twoPass : {true, false}) {
        SCOPED_TRACE(twoPass ? "two passes" : "one pass");
        const std::map<std::string, ParamValue> ballot = {kCooperative, {"vote", std::string("ballot")}, {"two_pass", twoPass}};
        const Outcome clean = run(thousandsOfTriangles(), ballot);
        ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_SPLIT_LANES", "1"}});
        Outcome o = run(thousandsOfTriangles(), ballot);
        EXPECT_GT(o.counters["vote_recoveries"], 0.0);
        EXPECT_EQ(o.accuracy.mismatchRatio, 0.0);
        EXPECT_EQ(o.overflow, 0u);
        EXPECT_EQ(o.visibility, clean.visibility);
    }
}

// A ballot workgroup that is not one whole subgroup (a fault site, test-only: as a driver that picks
// another width than the one compiled for) runs its jobs one per invocation, with no vote: that
// frame is as exact as any (it used to run none of its jobs: every shadow of them lit), and it is
// counted, so the host compiles shared-memory votes for the next frame.
TEST_F(PtsvGLTest, FaultSubgroupMismatchFrameStaysExact) {
    if (refusesBallotVotesHere()) return;
    for (bool twoPass : {true, false}) {
        SCOPED_TRACE(twoPass ? "two passes" : "one pass");
        const std::map<std::string, ParamValue> ballot = {kCooperative, {"vote", std::string("ballot")}, {"two_pass", twoPass}};
        const Outcome clean = run(thousandsOfTriangles(), ballot);
        ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_SUBGROUP_MISMATCH", "1"}});
        Outcome o = run(thousandsOfTriangles(), ballot);
        EXPECT_GT(o.counters["subgroup_mismatch_groups"], 0.0);
        EXPECT_EQ(o.accuracy.mismatchRatio, 0.0);
        EXPECT_EQ(o.visibility, clean.visibility);
    }
}

// Every walk and sample loop ended from outside after a few dozen passes (a fault site, test-only:
// llvmpipe's loop limit, one budget for all loops of an invocation). The cut jobs are counted as
// overflow and the subtrees they had still to visit written shadowed: no pixel comes out lighter
// than without the fault (before, their samples were simply left lit).
TEST_F(PtsvGLTest, FaultCutWalksShadowWhatTheyLeft) {
    const Shot shot = thousandsOfTriangles();
    // Not the shared-memory votes: a cut would leave the other invocations of the group waiting at
    // a barrier (the cap itself would too; that path runs where ballots are missing, not llvmpipe).
    std::vector<std::map<std::string, ParamValue>> variants = {{kPerInvocation}};
    if (querySubgroupSize() != 0) {
        variants.push_back({kCooperative, {"vote", std::string("ballot")}});
        variants.push_back({kPacket});
    }
    for (auto p : variants) {
        for (bool twoPass : {true, false}) {
            p["two_pass"] = twoPass;
            SCOPED_TRACE(std::get<std::string>(p.at("traversal")) + (twoPass ? ", two passes" : ", one pass"));
            const Outcome clean = run(shot, p, false);
            Outcome o;
            {
                ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_LOOP_BUDGET", "40"}});
                o = run(shot, p, false);
            }
            EXPECT_GT(o.counters["truncated_jobs"], 0.0);
            EXPECT_GE(o.overflow, uint64_t(o.counters["truncated_jobs"]));
            size_t lighter = 0, darker = 0;
            for (size_t i = 0; i < o.visibility.size(); ++i) {
                lighter += o.visibility[i] > clean.visibility[i];
                darker += o.visibility[i] < clean.visibility[i];
            }
            EXPECT_EQ(lighter, 0u) << "pixels lit by mistake";
            EXPECT_GT(darker, 0u) << "the cut subtrees are written shadowed";
        }
    }
}

// The heat map (Figure 3) counts exactly the test-and-set operations.
TEST_F(PtsvGLTest, HeatMapSumsToTheTestAndSetCount) {
    Outcome o = run(fenceDiscontinuity(), {{"heat_map", true}}, false);
    ASSERT_EQ(o.heat.size(), size_t(kRes * kRes));
    double sum = 0, peak = 0;
    for (float h : o.heat) {
        sum += h;
        peak = std::max(peak, double(h));
    }
    std::printf("[ptsv] heat map: %.0f tests, at most %.0f on one pixel\n", sum, peak);
    EXPECT_EQ(sum, o.counters["test_and_set"]);
    EXPECT_GT(peak, 1.0);
}

// ARB_shader_ballot votes (one subgroup, 32 / width children per invocation; llvmpipe: 8 lanes × 4)
// and shared-memory votes (32 lanes, a barrier per node) give the same image, and so does one job
// per invocation (no votes); the path is reported.
TEST_F(PtsvGLTest, VotePathsAgree) {
    const int width = querySubgroupSize();
    const bool ballotUsable = width == 4 || width == 8 || width == 16 || width == 32 || width == 64;
    Shot s = fenceDiscontinuity();
    Outcome shared = run(s, {kCooperative, {"vote", std::string("shared")}}, false);
    EXPECT_EQ(shared.counters["vote_path"], 0.0);
    EXPECT_EQ(shared.counters["traversal_lanes"], 32.0);
    Outcome perInvocation = run(s, {kPerInvocation}, false);
    EXPECT_EQ(perInvocation.counters["vote_path"], 2.0);
    EXPECT_EQ(perInvocation.counters["traversal_lanes"], 1.0);
    EXPECT_EQ(perInvocation.visibility, shared.visibility);
    EXPECT_EQ(perInvocation.counters["receivers"], shared.counters["receivers"]);
    // auto: cooperative on ballot subgroups of 32 lanes or more, else one job per invocation, whose
    // pass one walks as packets where ARB_shader_ballot is there.
    Outcome autoTraversal = run(s, {}, false);
    EXPECT_EQ(autoTraversal.counters["vote_path"], ballotUsable && width >= 32 ? 1.0 : 2.0);
    EXPECT_EQ(autoTraversal.counters["packet_traversal"], ballotUsable && width < 32 ? 1.0 : 0.0);
    Outcome autoVote = run(s, {kCooperative}, false);
    EXPECT_EQ(autoVote.counters["vote_path"], ballotUsable ? 1.0 : 0.0);
    EXPECT_EQ(autoVote.counters["subgroup_size"], double(width));
    // Only a driver without ARB_shader_ballot (or with an unusual width) has no ballot path to
    // compare; llvmpipe, NVIDIA and AMD all have one.
    if (!ballotUsable) GTEST_SKIP() << "no usable ARB_shader_ballot (subgroup " << width << ")";
    Outcome packet = run(s, {kPacket}, false);
    EXPECT_EQ(packet.counters["packet_traversal"], 1.0);
    EXPECT_EQ(packet.counters["vote_path"], 2.0);
    EXPECT_EQ(packet.visibility, shared.visibility);
    EXPECT_EQ(packet.counters["receivers"], shared.counters["receivers"]);
    Outcome ballot = run(s, {kCooperative, {"vote", std::string("ballot")}}, false);
    EXPECT_EQ(ballot.counters["vote_path"], 1.0);
    EXPECT_EQ(ballot.counters["traversal_lanes"], double(width));
    EXPECT_EQ(ballot.counters["subgroup_mismatch_groups"], 0.0);
    EXPECT_EQ(ballot.visibility, shared.visibility);
    EXPECT_EQ(ballot.counters["receivers"], shared.counters["receivers"]);
    EXPECT_GT(ballot.counters["test_and_set"], 0.0);
}

// A ballot traversal compiled for another width than the subgroups it runs on (a driver free to
// choose SIMD8/16/32, wave32 or wave64) is detected in the shader: its workgroups run nothing and
// are reported as overflow (never a silent wrong image), and ptsv switches to shared-memory votes
// from the next frame on, which is then exact. Forcing the width makes the mismatch here. 64 lanes
// (AMD's waves, two invocations per child) also run through the shared path, so their
// classification is checked on any device.
TEST_F(PtsvGLTest, SubgroupWidthMismatchIsReportedThenFallsBack) {
    const int width = querySubgroupSize();
    const bool ballot = width == 4 || width == 8 || width == 16 || width == 32 || width == 64;
    Shot s = thousandsOfTriangles();
    Outcome base = run(s, {kCooperative, {"vote", std::string("shared")}});
    EXPECT_LE(base.accuracy.mismatchRatio, 1e-4);
    for (int lanes : {8, 16, 32, 64})
        for (const char* vote : {"auto", "shared"}) {
            SCOPED_TRACE(std::string("lanes ") + std::to_string(lanes) + ", vote " + vote);
            const bool mismatch = ballot && std::string(vote) == "auto" && lanes != width;
            RunOptions first;
            first.withReference = false;
            AlgorithmRun once = runAlgorithm(ptsvInfo(), s, {kCooperative, {"lanes", lanes}, {"vote", std::string(vote)}}, first);
            if (mismatch) {
                EXPECT_GT(once.counters["subgroup_mismatch_groups"], 0.0);
                EXPECT_GE(once.overflow, uint64_t(once.counters["subgroup_mismatch_groups"])) << "reported as overflow";
            } else {
                EXPECT_EQ(once.counters["subgroup_mismatch_groups"], 0.0);
                EXPECT_EQ(once.overflow, 0u);
                EXPECT_EQ(once.visibility, base.visibility);
            }
            RunOptions second;
            second.warmUp = true; // the frame after the one that met the mismatch
            AlgorithmRun o = runAlgorithm(ptsvInfo(), s, {kCooperative, {"lanes", lanes}, {"vote", std::string(vote)}}, second);
            EXPECT_EQ(o.counters["subgroup_fallback"], mismatch ? 1.0 : 0.0);
            EXPECT_EQ(o.counters["vote_path"], mismatch || std::string(vote) == "shared" || !ballot ? 0.0 : 1.0);
            EXPECT_EQ(o.counters["traversal_lanes"], double(lanes));
            EXPECT_EQ(o.overflow, 0u);
            EXPECT_LE(o.accuracy.mismatchRatio, 1e-4);
            EXPECT_EQ(o.visibility, base.visibility) << "every width and vote path gives the same image";
        }
}

// The hierarchy built on the GPU, read back and checked against its definition: the GPU's cluster
// keys against the CPU's KeyLayout, every child mask against the keys below it, and every node's
// explicit bounds against its samples. No caster here (only surfaces facing the light, culled by
// front-face culling), so no trivial accept clears a bit before the read-back.
TEST_F(PtsvGLTest, HierarchyMatchesItsSamples) {
    Shot s;
    s.scene = ground(20.0f);
    Scene wall = makePlane({1.5f, 1.5f}, 1, Material{});
    for (int i = 0; i < 6; ++i) // walls at very different depths, facing the camera and the light
        s.scene.append(wall, translate({-2.0f + 0.8f * i, 0.8f, -1.0f - 2.5f * i}) * rotate(90, {1, 0, 0}));
    s.camera = lookAt({0.0f, 1.2f, 3.0f}, {0.0f, 0.6f, -10.0f});
    s.light = pointLight({0.5f, 2.0f, 8.0f});
    std::vector<uint32_t> masks, slotWords; // a sample slot: q's float bits, then its key
    std::vector<float> bounds, samples;
    ptsv::KeyLayout layout = ptsv::makeKeyLayout({kRes, kRes}, 8, s.camera.fovYDeg, s.camera.nearPlane, s.camera.farPlane);
    auto fetch = [](GLuint binding, auto& out) {
        GLint buffer = 0;
        glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, binding, &buffer);
        GLint64 size = 0;
        glGetNamedBufferParameteri64v(GLuint(buffer), GL_BUFFER_SIZE, &size);
        out.resize(size_t(size) / sizeof(out[0]));
        glGetNamedBufferSubData(GLuint(buffer), 0, size, out.data());
    };
    Outcome o = run(s, {{"front_face_culling", true}}, false, [&]() {
        fetch(PTSV_MASK_BINDING, masks);
        fetch(PTSV_AABB_BINDING, bounds);
        fetch(PTSV_SAMPLE_BINDING, samples);
        fetch(PTSV_SAMPLE_BINDING, slotWords);
    });
    ASSERT_EQ(o.counters["casters"], 0.0);
    ASSERT_EQ(masks.size(), layout.maskWords);
    EXPECT_EQ(o.counters["tree_levels"], double(layout.levels));
    EXPECT_EQ(o.counters["key_bits"], double(layout.keyBits));
    const glm::mat4 view = s.camera.view();
    auto slot = [&](int x, int y) {
        return size_t((y / 8) * layout.tilesX + x / 8) * 64 + size_t((y % 8) * 8 + x % 8);
    };
    // Keys: the GPU's against the CPU's (a slice boundary may round either way: allow a few).
    std::map<uint32_t, std::pair<glm::vec3, glm::vec3>> clusters; // key → box of its samples' q
    size_t receivers = 0, differ = 0;
    for (int y = 0; y < kRes; ++y)
        for (int x = 0; x < kRes; ++x) {
            const size_t i = size_t(y) * kRes + x;
            const uint32_t k = slotWords[4 * slot(x, y) + 3];
            if (!o.lit[i]) {
                EXPECT_GE(k, uint32_t(PTSV_KEY_AWAY)) << x << "," << y;
                continue;
            }
            ++receivers;
            const glm::vec3 p = o.gbuffer.positionAt(i);
            const float depth = -(view * glm::vec4(p, 1.0f)).z;
            const uint32_t cpu = layout.key({uint32_t(x / 8), uint32_t(y / 8), uint32_t(ptsv::depthSlice(layout, depth, s.camera.nearPlane))});
            differ += cpu != k;
            const glm::vec3 q(samples[4 * slot(x, y)], samples[4 * slot(x, y) + 1], samples[4 * slot(x, y) + 2]);
            auto [it, inserted] = clusters.try_emplace(k, q, q);
            it->second.first = glm::min(it->second.first, q);
            it->second.second = glm::max(it->second.second, q);
        }
    std::printf("[ptsv] %zu receivers in %zu clusters, %d levels, %zu keys differ from the CPU's\n", receivers,
                clusters.size(), layout.levels, differ);
    EXPECT_EQ(o.counters["receivers"], double(receivers));
    EXPECT_EQ(o.counters["clusters"], double(clusters.size()));
    EXPECT_LE(differ, receivers / 200);
    EXPECT_GT(clusters.size(), size_t(2 * layout.tilesX)); // several depths per column of tiles
    // Leaves: exactly the clusters, each with the exact box of its samples.
    auto box = [&](int depth, uint32_t id) {
        const size_t b = 6 * (layout.nodeOffset[size_t(depth)] + id);
        return std::make_pair(glm::vec3(bounds[b], bounds[b + 1], bounds[b + 2]), glm::vec3(bounds[b + 3], bounds[b + 4], bounds[b + 5]));
    };
    const int L = layout.levels;
    size_t leafBits = 0;
    for (size_t w = 0; w < layout.nodesAt(L - 1); ++w) leafBits += size_t(__builtin_popcount(masks[layout.maskOffset[size_t(L - 1)] + w]));
    EXPECT_EQ(leafBits, clusters.size());
    for (const auto& [k, b] : clusters) {
        EXPECT_TRUE((masks[layout.maskOffset[size_t(L - 1)] + (k >> 5)] >> (k & 31)) & 1u) << "cluster " << k;
        EXPECT_EQ(box(L, k).first, b.first) << "cluster " << k;
        EXPECT_EQ(box(L, k).second, b.second) << "cluster " << k;
    }
    // Inner nodes: a bit is set exactly where the child's mask is not empty, and the node's box is
    // the union of its children's.
    for (int d = L - 2; d >= 0; --d)
        for (uint32_t id = 0; id < layout.nodesAt(d); ++id) {
            const uint32_t mask = masks[layout.maskOffset[size_t(d)] + id];
            glm::vec3 lo(3e38f), hi(-3e38f);
            for (uint32_t c = 0; c < 32; ++c) {
                const uint32_t child = id * 32 + c;
                const bool has = child < layout.nodesAt(d + 1) && masks[layout.maskOffset[size_t(d + 1)] + child] != 0;
                EXPECT_EQ(bool((mask >> c) & 1u), has) << "depth " << d << " node " << id << " child " << c;
                if (!has) continue;
                auto [cl, ch] = box(d + 1, child);
                lo = glm::min(lo, cl);
                hi = glm::max(hi, ch);
            }
            if (mask != 0 && d >= 1) {
                EXPECT_EQ(box(d, id).first, lo);
                EXPECT_EQ(box(d, id).second, hi);
            }
        }
    // Nothing casts: every receiver is lit.
    for (size_t i = 0; i < o.lit.size(); ++i)
        if (o.lit[i]) EXPECT_EQ(o.visibility[i], 1.0f);
}

} // namespace
} // namespace shadowlab
