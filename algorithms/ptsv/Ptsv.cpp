#include "algorithms/ptsv/Ptsv.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/SharedParams.h"
#include "algorithms/ptsv/PtsvLayout.h"
#include "framework/core/CheckedMath.h"
#include "framework/core/Error.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"

#include <algorithm>
#include <atomic>
#include <array>
#include <cstdio>
#include <functional>

namespace shadowlab {
namespace {

enum class PtsvBounds { Explicit, Implicit };
enum class PtsvVote { Auto, Ballot, Shared };
enum class PtsvLeafSamples { Tile, Cluster };
enum class PtsvTraversal { Auto, Cooperative, Invocation, Packet };
const std::vector<Choice<PtsvTraversal>> kPtsvTraversals = {{"auto", PtsvTraversal::Auto},
                                                        {"cooperative", PtsvTraversal::Cooperative},
                                                        {"invocation", PtsvTraversal::Invocation},
                                                        {"packet", PtsvTraversal::Packet}};

struct PtsvParams {
    PtsvBounds bounds;
    bool cullingPlanes, twoPass, frontFaceCulling, jobIterations, heatMap;
    int splitLevel, tileSize, maxKeyBits, jobCapacity, jobsPerWorkgroup, lanes;
    float planeBias, rayOffset; ///< × scene radius
    PtsvVote vote;
    PtsvLeafSamples leafSamples;
    PtsvTraversal traversal;
};

const ParamStruct<PtsvParams>& ptsvParams() {
    using P = PtsvParams;
    // Shader variants are Recompile: the per-frame layout (ensureLayout) follows them without a
    // setScene(). Buffer capacities are Rebuild.
    static const ParamStruct<P> s = ParamStruct<P>()
        .choice("bounds", &P::bounds, PtsvBounds::Explicit, {{"explicit", PtsvBounds::Explicit}, {"implicit", PtsvBounds::Implicit}},
                "node bounds: the tight box of its samples (paper 2.1) or the cluster frustum its key implies",
                ParamChange::Recompile)
        .boolean("culling_planes", &P::cullingPlanes, true,
                 "the three additional culling planes through the light and each vertex (paper 2, Figure 4)",
                 ParamChange::Recompile)
        .boolean("two_pass", &P::twoPass, true,
                 "two-pass traversal (paper 2.2): pass one stops at split_level and queues jobs, pass two finishes them",
                 ParamChange::Recompile)
        .integer("split_level", &P::splitLevel, 0, 0, PTSV_MAX_LEVELS, "tree depth",
                 "depth L where pass one queues its jobs (root 0, clusters = levels); 0 = levels - 1 with "
                 "cooperative traversal, levels (one cluster per job) with invocation traversal",
                 ParamChange::Update)
        .integer("tile_size", &P::tileSize, 8, 2, 16, "px", "cluster tile width and height (paper: 8)", ParamChange::Recompile)
        // 22 bits keep the full tree's explicit bounds under 100 MiB (the paper's 1024² needs 24:
        // there slices become 4× deeper than wide).
        .integer("max_key_bits", &P::maxKeyBits, 22, 10, PTSV_MAX_KEY_BITS, "bits",
                 "cluster key length cap: beyond it depth slices are merged in pairs (bounds memory 24 B × 2^bits)",
                 ParamChange::Rebuild)
        // Off by default: it is exact only for closed, consistently wound meshes (as in psv).
        .boolean("front_face_culling", &P::frontFaceCulling, false,
                 "only triangles facing away from the light cast; exact for closed meshes only",
                 ParamChange::Recompile)
        // 0 by default: the samples already sit ray_offset in front of their own triangle (the
        // reference's convention), and any bias lights receivers just behind a caster (measured on
        // the demo: 1e-6 adds 8 lit pixels to its 60 frames).
        .real("plane_bias", &P::planeBias, 0.0, 0.0, 1e-3, "× scene radius",
              "triangle plane moved away from the light when front faces cast (paper 2), against self-shadowing",
              ParamChange::Update)
        .apply(rayOffsetRow(&P::rayOffset))
        // 4 Mi jobs (32 MiB): with one cluster per job (the invocation traversal's split) the peer engine
        // scene queues up to 0.54 M at 1024², and without culling planes about 2 M at 512².
        .integer("job_capacity", &P::jobCapacity, 1 << 22, 1, 1 << 24, "jobs",
                 "two-pass job list; jobs that find it full are finished by pass one (counted in overflow)",
                 ParamChange::Rebuild)
        // 0 = 16 with two passes: on the peer engine scene (512², the timed pass) 1240 / 1432 ms per
        // frame against 1658 / 1592 with 1 and 1363 / 1683 with 64 (results/reference/ptsv/peer_engine.md); 1 with
        // one pass: a batch of 16 whole traversals in one invocation reached llvmpipe's loop cap on
        // configs/ptsv/engine.json's implicit-bounds steps (up to 11,760 truncated jobs a frame).
        .integer("jobs_per_workgroup", &P::jobsPerWorkgroup, 0, 0, 64, "jobs",
                 "consecutive jobs one cooperative traversal workgroup runs in turn (the paper's persistent "
                 "threads run until the queue is empty; bounded here by llvmpipe's per-invocation loop cap); "
                 "0 = 16 with two passes, 1 with one",
                 ParamChange::Recompile)
        // auto: on llvmpipe's 8-lane subgroups a cooperative job takes 4 rounds per node for about 9
        // existing children; one job per invocation measured 3.1x less traversal time on the peer
        // engine scene at 512² and 1024² (results/reference/ptsv/peer_engine.md). Subgroups of 32 or more test a
        // node in one round, the paper's case. One pass stays cooperative: a large triangle's whole traversal in one invocation can
        // reach llvmpipe's loop cap (configs/ptsv/engine.json's implicit-bounds rows did).
        // packet: pass one's walks of neighbouring triangles share their nodes, so the lanes of a
        // subgroup loop over one node's children together (traverse 10-12 % less than invocation at
        // 512² on the peer engine scene, the same at 1024²).
        .choice("traversal", &P::traversal, PtsvTraversal::Auto, kPtsvTraversals,
                "who walks a job: cooperative (paper: a subgroup per job, its lanes testing a node's 32 children "
                "together, see vote and lanes), invocation (each invocation its own job, testing a node's "
                "existing children in turn; no votes), packet (as invocation, but in pass one the lanes of a "
                "subgroup, each with its own triangle, walk the union of their paths together; needs "
                "ARB_shader_ballot), auto (with two passes on subgroups narrower than 32 lanes packet, or invocation "
                "without ARB_shader_ballot; else cooperative)",
                ParamChange::Recompile)
        .choice("vote", &P::vote, PtsvVote::Auto,
                {{"auto", PtsvVote::Auto}, {"ballot", PtsvVote::Ballot}, {"shared", PtsvVote::Shared}},
                "how a node's 32 children are tested together: ballot (ARB_shader_ballot: one subgroup, each "
                "invocation testing 32 / width children, no barrier), shared (32 invocations, shared memory and a "
                "barrier per node), auto (ballot where the driver has it)",
                ParamChange::Recompile)
        .integer("lanes", &P::lanes, 0, 0, 64, "invocations",
                 "traversal workgroup width: 0 = the device's subgroup width with ballots (32 with shared votes); "
                 "4, 8, 16, 32 or 64 compiles for that width (ballot workgroups whose subgroups differ at run "
                 "time are reported as overflow, and ptsv switches to shared votes from the next frame)",
                 ParamChange::Recompile)
        .choice("leaf_samples", &P::leafSamples, PtsvLeafSamples::Tile,
                {{"tile", PtsvLeafSamples::Tile}, {"cluster", PtsvLeafSamples::Cluster}},
                "samples tested at a leaf: the whole tile (paper) or only the cluster's (its key compared first)",
                ParamChange::Recompile)
        .boolean("job_iterations", &P::jobIterations, false,
                 "record every job's traversal iterations and report the mean of the 1024 largest (Figure 7)",
                 ParamChange::Recompile)
        .boolean("heat_map", &P::heatMap, false,
                 "count test-and-set operations per pixel (debug view, costs one atomic per test)", ParamChange::Recompile)
        .rule("lanes", [](const P& p) {
            const bool supported = p.lanes == 0 || p.lanes == 4 || p.lanes == 8 || p.lanes == 16 || p.lanes == 32 || p.lanes == 64;
            return supported ? std::string() : "lanes must be 0 (auto), 4, 8, 16, 32 or 64, not " + std::to_string(p.lanes);
        });
    return s;
}

const ParamSchema& ptsvSchema() { return ptsvParams().schema(); }

constexpr GLuint kSetupGroup = 64;   ///< local_size_x of setup.comp and reduce.comp
constexpr GLuint kMaxGroups = 65535; ///< GL's minimum max work group count per dimension

/// Vote paths (PTSV_BALLOT in traverse.comp), reported as the `vote_path` counter.
enum Vote { kVoteShared = 0, kVoteBallot = 1, kVoteNone = 2 /* traversal = invocation */ };

class Ptsv final : public ShadowAlgorithm {
public:
    Ptsv(const ParamValues& p, const AlgorithmOptions& o) : p_(ptsvParams().read(p)), options_(o) {
        instrumentParams();
        subgroupSize_ = querySubgroupSize();
        compile();
    }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        const size_t n = scene.triangleCount();
        if (n * PTSV_PLANES_PER_TRIANGLE * 16 > maxShaderStorageBlockBytes())
            throw RuntimeError("ptsv: " + std::to_string(n) + " triangles exceed the largest storage block");
        planes_ = GlBuffer(std::max<size_t>(n, 1) * PTSV_PLANES_PER_TRIANGLE * 16, nullptr, 0);
        planeTexels_ = makeBufferTexture(planes_, GL_RGBA32F, 16, "ptsv planes");
        counters_.allocate();
        layoutKey_ = {}; // the per-job iteration record is sized by the triangle count
    }

    void resize(glm::ivec2 resolution) override {
        resolution_ = resolution;
        layoutKey_ = {}; // per-sample buffers follow in ensureLayout(), which also needs the camera
        heat_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
    }

    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = ptsvParams().read(p);
        instrumentParams();
        if (change == ParamChange::Recompile) compile();
        if (change != ParamChange::Update) layoutKey_ = {};  // buffers follow at the next frame
    }

    void computeVisibility(const FrameInputs& f) override {
        // The last frame's ballot workgroups found subgroups of another width than compiled (it
        // was reported as overflow): shared-memory votes from now on.
        if (vote_ == kVoteBallot && counters_ && counters_.read()[PTSV_C_SUBGROUP_MISMATCH] != 0) {
            std::fprintf(stderr, "shadowlab: warning: ptsv: subgroups of another width than %d at run time: switching to shared-memory votes\n",
                         lanes_);
            fellBack_ = true;
            compile();
        }
        ensureLayout(f.camera);
        setUniforms(f.camera, f.light);
        bindAll();

        f.timer.begin("hierarchy");
        counters_.clear();
        if (p_.jobIterations) jobIterations_.clearUint(0);
        glClearNamedBufferSubData(masks_.id(), GL_R32UI, 0, GLsizeiptr(layout_.maskWords * 4), GL_RED_INTEGER,
                                  GL_UNSIGNED_INT, nullptr);
        glBindTextureUnit(0, f.gbuffer.position());
        glBindTextureUnit(1, f.gbuffer.normal());
        hierarchy_.use();
        glDispatchCompute(GLuint(layout_.tilesX), GLuint(layout_.tilesY), 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        clusters_.use();
        glDispatchCompute(GLuint(layout_.tilesX), GLuint(layout_.tilesY), 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        for (int d = layout_.levels - 1; d >= 1; --d) {
            const size_t count = layout_.nodesAt(d);
            reduce_.set("uDepth", d);
            reduce_.set("uNodeCount", unsigned(count));
            dispatchLinear(reduce_, count);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
        f.timer.end();

        f.timer.begin("setup");
        const size_t n = scene_->triangleCount();
        if (n > 0) {
            if (shaderFaultActive("SHADOWLAB_FAULT_STALE_PLANES")) {
                // Test fault: planes left over that would shadow every sample (inside all of them),
                // as a buffer GL never initialised or a previous scene may hold.
                const float inside[4] = {0.0f, 0.0f, 0.0f, -1.0f};
                glClearNamedBufferData(planes_.id(), GL_RGBA32F, GL_RGBA, GL_FLOAT, inside);
            }
            setup_.set("uTriangleCount", unsigned(n));
            dispatchLinear(setup_, n);
        }
        // The traversal reads the hierarchy's and setup's output through buffer textures.
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        f.timer.end();

        f.timer.begin("traverse");
        if (n > 0) {
            // One workgroup per batch of triangles (cooperative) or one invocation per triangle, as a
            // 2D grid past 65535 groups.
            const size_t perGroup = perInvocation_ ? size_t(PTSV_INVOCATION_GROUP) : size_t(jobsPerWorkgroup());
            const size_t groups = (n + perGroup - 1) / perGroup;
            const GLuint gx = GLuint(std::min<size_t>(groups, kMaxGroups)), gy = GLuint((groups + gx - 1) / gx);
            pass1_.use();
            glDispatchCompute(gx, gy, 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            if (p_.twoPass) {
                jobArgs_.use();
                glDispatchCompute(1, 1, 1);
                glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
                glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, counters_.id());
                pass2_.use();
                glDispatchComputeIndirect(GLintptr(PTSV_C_DISPATCH * sizeof(uint32_t)));
                glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
            }
            // The resolve pass reads the shadow marks and the masks through buffer textures.
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        }
        f.timer.end();

        f.timer.begin("resolve");
        glBindImageTexture(0, f.visibility, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        bindDebugImage(1, heat_);
        resolve_.use();
        glDispatchCompute(GLuint(layout_.tilesX), GLuint(layout_.tilesY), 1);
        finishPixelPass();
        f.timer.end();
        counters_.markStale();
    }

    std::vector<Counter> counters() const override {
        const auto& c = counters_.read();
        static_assert(PTSV_C_TESTS_HI == PTSV_C_TESTS_LO + 1 && PTSV_C_NODE_TESTS_HI == PTSV_C_NODE_TESTS_LO + 1);
        auto wide = [&](size_t lo) { return double(counters_.wide(lo)); };
        const double jobs1 = c[PTSV_C_JOBS_1];
        const double pushed = std::min<double>(c[PTSV_C_JOBS_PUSHED], double(p_.jobCapacity));
        // The structure's shape and what is measured in both modes; the timed pass compiles the rest out.
        std::vector<Counter> out = {{"jobs", p_.twoPass ? pushed : 0.0},
                                    {"job_overflow", double(c[PTSV_C_JOB_OVERFLOW])},
                                    {"truncated_jobs", double(c[PTSV_C_TRUNCATED])},
                                    {"tree_levels", double(layout_.levels)},
                                    {"key_bits", double(layout_.keyBits)},
                                    {"slices_merged", double(layout_.merged)},
                                    {"split_depth", p_.twoPass ? double(splitDepth()) : 0.0},
                                    {"vote_path", double(vote_)},
                                    {"traversal_lanes", double(lanes_)},
                                    {"packet_traversal", packet_ ? 1.0 : 0.0},
                                    {"subgroup_size", double(subgroupSize_)},
                                    {"subgroup_mismatch_groups", double(c[PTSV_C_SUBGROUP_MISMATCH])},
                                    // Votes or broadcasts that missed a lane and were decided alone (exact).
                                    {"vote_recoveries", double(c[PTSV_C_VOTE_RECOVERED])},
                                    {"subgroup_fallback", fellBack_ ? 1.0 : 0.0}};
        if (!options_.statistics) return out;
        out.insert(out.end(), {{"test_and_set", wide(PTSV_C_TESTS_LO)},
                               {"close_calls", double(c[PTSV_C_CLOSE_CALLS])},
                               {"node_tests", wide(PTSV_C_NODE_TESTS_LO)},
                               {"iterations_max_pass1", double(c[PTSV_C_ITER_MAX_1])},
                               {"iterations_mean_pass1", jobs1 > 0 ? c[PTSV_C_ITER_SUM_1] / jobs1 : 0.0},
                               {"iterations_max_pass2", double(c[PTSV_C_ITER_MAX_2])},
                               {"iterations_mean_pass2", pushed > 0 ? c[PTSV_C_ITER_SUM_2] / pushed : 0.0},
                               {"accepted_nodes", double(c[PTSV_C_ACCEPTED])},
                               {"leaf_visits", double(c[PTSV_C_LEAF_VISITS])},
                               {"clusters", double(c[PTSV_C_CLUSTERS])},
                               {"receivers", double(c[PTSV_C_RECEIVERS])},
                               {"shadowed", double(c[PTSV_C_SHADOWED])},
                               {"casters", jobs1},
                               {"culled_front_facing", double(c[PTSV_C_CULLED_FACING])},
                               {"culled_edge_on", double(c[PTSV_C_CULLED_EDGE_ON])}});
        if (p_.jobIterations) {
            // Figure 7: the jobs that keep a multiprocessor busy longest, against the average.
            const size_t n = scene_ ? scene_->triangleCount() : 0;
            std::vector<uint32_t> it = jobIterations_.read<uint32_t>(n + size_t(pushed));
            auto top = [](std::vector<uint32_t> v) {
                const size_t k = std::min<size_t>(1024, v.size());
                std::partial_sort(v.begin(), v.begin() + ptrdiff_t(k), v.end(), std::greater<>());
                double sum = 0;
                for (size_t i = 0; i < k; ++i) sum += v[i];
                return k ? sum / double(k) : 0.0;
            };
            std::vector<uint32_t> pass1(it.begin(), it.begin() + ptrdiff_t(n)), pass2(it.begin() + ptrdiff_t(n), it.end());
            out.push_back({"iterations_top1024_mean_pass1", top(pass1)});
            out.push_back({"iterations_top1024_mean_pass2", top(pass2)});
        }
        return out;
    }

    std::vector<DebugView> debugViews() const override {
        if (!p_.heatMap) return {};
        return {{"tests_per_pixel", heat_.id(), 0.0f, "test-and-set"}};
    }

    /// Child masks, bounds, per-sample buffers, triangle planes, job list and counters (not the
    /// heat-map image, a debug aid).
    size_t memoryBytes() const override {
        size_t bytes = 0;
        for (const GlBuffer* b : {&masks_, &bounds_, &samples_, &shadow_, &heatCounts_, &planes_, &jobs_, &counters_.buffer(),
                                  &jobIterations_})
            bytes += b->size();
        return bytes;
    }

    /// Jobs that found the job list full (finished by pass one instead, so the image stays exact: the
    /// count says the list was too small for the two-pass balance), plus jobs the driver's loop cap
    /// cut short (their shadows may be missing: must stay 0).
    uint64_t overflowCount() const override {
        const auto& c = counters_.read();
        return uint64_t(c[PTSV_C_JOB_OVERFLOW]) + c[PTSV_C_TRUNCATED] + c[PTSV_C_SUBGROUP_MISMATCH];
    }

    /// What compile() chose on this device: the traversal, the vote (none without cooperative
    /// traversal), the workgroup width, and the split depth (its rule, "levels" or "levels - 1",
    /// until a frame has laid out the tree) and jobs per workgroup that 0 stands for.
    std::vector<std::pair<std::string, std::string>> resolvedParams() const override {
        const PtsvTraversal traversal = packet_ ? PtsvTraversal::Packet : perInvocation_ ? PtsvTraversal::Invocation
                                                                                     : PtsvTraversal::Cooperative;
        const std::string vote = vote_ == kVoteBallot ? "ballot" : vote_ == kVoteShared ? "shared" : "none";
        const std::string split = layout_.levels > 0     ? std::to_string(splitDepth())
                                  : p_.splitLevel != 0   ? std::to_string(p_.splitLevel)
                                  : perInvocation_       ? "levels"
                                                         : "levels - 1";
        return {{"split_level", split},
                {"jobs_per_workgroup", std::to_string(jobsPerWorkgroup())},
                {"traversal", choiceName(kPtsvTraversals, traversal)},
                {"vote", vote},
                {"lanes", std::to_string(lanes_)}};
    }

private:
    /// The timed pass compiles the statistics out: the heat map and the per-job iteration record too.
    void instrumentParams() {
        if (options_.statistics) return;
        p_.heatMap = false;
        p_.jobIterations = false;
    }

    int jobsPerWorkgroup() const { return p_.jobsPerWorkgroup != 0 ? p_.jobsPerWorkgroup : p_.twoPass ? 16 : 1; }

    int splitDepth() const {
        const int l = p_.splitLevel;
        // 0: the parents of the clusters (paper), or the clusters themselves with one job per
        // invocation (on the peer engine scene at 512², 266 against 289 ms of traversal).
        if (l == 0) return perInvocation_ ? layout_.levels : std::max(1, layout_.levels - 1);
        return std::min(l, layout_.levels);
    }

    void compile() {
        // The ballot path needs the workgroup to be one subgroup: widths 4 to 32 test 32 / width
        // children per invocation, 64 (AMD waves) two invocations per child. Whether the
        // subgroups really have that width is checked again in the shader, at run time.
        auto supported = [](int w) { return w == 4 || w == 8 || w == 16 || w == 32 || w == 64; };
        if (p_.lanes != 0 && !supported(p_.lanes))
            throw RuntimeError("ptsv: lanes must be 0 (auto), 4, 8, 16, 32 or 64, not " + std::to_string(p_.lanes));
        const bool ballotUsable = supported(subgroupSize_);
        if (p_.vote == PtsvVote::Ballot && !ballotUsable)
            throw RuntimeError("ptsv: vote = ballot needs ARB_shader_ballot with a subgroup width of 4, 8, 16, 32 or "
                               "64 (this context: " + std::to_string(subgroupSize_) + ")");
        if (p_.traversal == PtsvTraversal::Packet && !ballotUsable)
            throw RuntimeError("ptsv: traversal = packet needs ARB_shader_ballot (this context: subgroup width " +
                               std::to_string(subgroupSize_) + ")");
        const bool narrow = p_.traversal == PtsvTraversal::Auto && p_.twoPass && !(ballotUsable && subgroupSize_ >= 32);
        packet_ = p_.traversal == PtsvTraversal::Packet || (narrow && ballotUsable);
        perInvocation_ = packet_ || p_.traversal == PtsvTraversal::Invocation || narrow;
        vote_ = perInvocation_ ? kVoteNone : p_.vote != PtsvVote::Shared && ballotUsable && !fellBack_ ? kVoteBallot : kVoteShared;
        lanes_ = perInvocation_ ? 1 : p_.lanes != 0 ? p_.lanes : vote_ == kVoteBallot ? subgroupSize_ : 32;
        auto flag = [&](bool b) { return b ? std::string("1") : std::string("0"); };
        ShaderDefines defines = {statisticsDefine(options_),
                                 {"PTSV_TILE", std::to_string(p_.tileSize)},
                                 {"PTSV_EXPLICIT_BOUNDS", flag(p_.bounds == PtsvBounds::Explicit)},
                                 {"PTSV_CULLING_PLANES", flag(p_.cullingPlanes)},
                                 {"PTSV_TWO_PASS", flag(p_.twoPass)},
                                 {"PTSV_FRONT_FACE_CULLING", flag(p_.frontFaceCulling)},
                                 {"PTSV_LEAF_CLUSTER_ONLY", flag(p_.leafSamples == PtsvLeafSamples::Cluster)},
                                 {"PTSV_HEAT_MAP", flag(p_.heatMap)},
                                 {"PTSV_JOB_ITERATIONS", flag(p_.jobIterations)},
                                 {"PTSV_PER_INVOCATION", flag(perInvocation_)},
                                 {"PTSV_PACKET", flag(packet_)},
                                 {"PTSV_BALLOT", flag(vote_ == kVoteBallot)},
                                 {"PTSV_LANES", std::to_string(lanes_)},
                                 {"PTSV_JOBS_PER_GROUP", std::to_string(jobsPerWorkgroup())}};
        hierarchy_ = ShaderProgram::compute("ptsv/hierarchy.comp", defines);
        clusters_ = ShaderProgram::compute("ptsv/clusters.comp", defines);
        reduce_ = ShaderProgram::compute("ptsv/reduce.comp", defines);
        setup_ = ShaderProgram::compute("ptsv/setup.comp", defines);
        resolve_ = ShaderProgram::compute("ptsv/resolve.comp", defines);
        ShaderDefines d1 = defines, d2 = defines;
        d1.push_back({"PTSV_PASS", "1"});
        d2.push_back({"PTSV_PASS", "2"});
        pass1_ = ShaderProgram::compute("ptsv/traverse.comp", d1);
        pass2_ = ShaderProgram::compute("ptsv/traverse.comp", d2);
        jobArgs_ = ShaderProgram::compute("ptsv/jobs.comp", defines);
    }

    /// The hierarchy's shape follows the resolution and the camera's field of view and near/far:
    /// (re)allocated when one of them changes.
    void ensureLayout(const Camera& camera) {
        const std::array<float, 6> key = {float(resolution_.x), float(resolution_.y), camera.fovYDeg, camera.nearPlane,
                                          camera.farPlane, float(p_.tileSize)};
        if (key == layoutKey_ && masks_) return;
        layoutKey_ = key;
        const int tile = p_.tileSize;
        layout_ = ptsv::makeKeyLayout(resolution_, tile, camera.fovYDeg, camera.nearPlane, camera.farPlane,
                                      p_.maxKeyBits);
        const bool explicitBounds = p_.bounds == PtsvBounds::Explicit;
        const size_t boundsBytes = explicitBounds ? layout_.boundsNodes * 6 * sizeof(float) : 4;
        if (boundsBytes > maxShaderStorageBlockBytes())
            throw RuntimeError("ptsv: explicit bounds of a full tree with " + std::to_string(layout_.keyBits) +
                               "-bit keys need " + std::to_string(boundsBytes >> 20) +
                               " MiB, over this context's storage block limit: use bounds = implicit, a larger "
                               "tile_size, a lower resolution or a smaller far/near ratio");
        const size_t slots = size_t(layout_.tilesX) * size_t(layout_.tilesY) * size_t(tile) * size_t(tile);
        masks_ = GlBuffer(layout_.maskWords * 4, nullptr, 0);
        bounds_ = GlBuffer(boundsBytes, nullptr, 0);
        samples_ = GlBuffer(slots * 16, nullptr, 0);
        shadow_ = GlBuffer(slots * 4, nullptr, 0);
        heatCounts_ = GlBuffer(p_.heatMap ? slots * 4 : 4, nullptr, 0);
        jobs_ = GlBuffer(p_.twoPass ? size_t(p_.jobCapacity) * 8 : 8, nullptr, 0);
        const size_t jobSlots = scene_->triangleCount() + (p_.twoPass ? size_t(p_.jobCapacity) : 0);
        // Zero-filled: a culled triangle (no workgroup writes its slot) counts 0 iterations.
        jobIterations_ = GlBuffer(p_.jobIterations ? std::max<size_t>(jobSlots, 1) * 4 : 4, nullptr, 0);
        boundsTexels_ = makeBufferTexture(bounds_, GL_RGB32F, 12, "ptsv bounds");
        sampleTexels_ = makeBufferTexture(samples_, GL_RGBA32UI, 16, "ptsv samples");
        maskTexels_ = makeBufferTexture(masks_, GL_R32UI, 4, "ptsv masks");
        shadowTexels_ = makeBufferTexture(shadow_, GL_R32UI, 4, "ptsv shadow marks");
    }

    void setUniforms(const Camera& camera, const Light& light) {
        const Bounds& b = scene_->bounds();
        const float radius = b.empty() ? 1.0f : b.radius();
        const glm::vec3 center = b.empty() ? glm::vec3(0.0f) : b.center();
        // Rounding of a plane evaluation grows with the coordinates' magnitude (and the light's:
        // edge planes pass through it); 4e-6 of it is far above float error (psv uses the same) and
        // only sends nodes that close to a plane one level further down.
        float magnitude = glm::length(center) + radius + glm::length(camera.position);
        if (light.type != LightType::Directional) magnitude = std::max(magnitude, glm::length(light.position));
        const float tolerance = 4e-6f * magnitude;
        const float rayOffset = rayOffsetLength(p_.rayOffset, *scene_);
        const float aspect = float(resolution_.x) / float(resolution_.y);
        const float tanHalf = std::tan(glm::radians(camera.fovYDeg) * 0.5f);
        const glm::mat4 view = camera.view();
        const int split = splitDepth();
        // Once a process, not once an instance (the timed and the statistics pass each have one),
        // prefixed as the runner's warnings; summary.json's resolved_params says what was used.
        static std::atomic<bool> warnedSplit{false};
        if (p_.twoPass && p_.splitLevel > layout_.levels && !warnedSplit.exchange(true))
            std::fprintf(stderr, "shadowlab: warning: ptsv: split_level %d is below the %d-level tree: using %d\n",
                         p_.splitLevel, layout_.levels, split);
        for (const ShaderProgram* p : {&hierarchy_, &clusters_, &reduce_, &setup_, &pass1_, &pass2_, &jobArgs_, &resolve_}) {
            setLightUniforms(*p, light);
            p->set("uResolution", resolution_);
            p->set("uTile", layout_.tile);
            p->set("uTilesX", layout_.tilesX);
            p->set("uSlices", layout_.slices);
            p->set("uSliceLog", layout_.sliceLog);
            p->set("uKeyBits", layout_.keyBits);
            p->set("uLevels", layout_.levels);
            glProgramUniform1uiv(p->id(), p->location("uKeyBit"), 32, layout_.keyBit.data());
            glProgramUniform1uiv(p->id(), p->location("uMaskOffset"), GLsizei(layout_.maskOffset.size()),
                                 layout_.maskOffset.data());
            glProgramUniform1uiv(p->id(), p->location("uNodeOffset"), GLsizei(layout_.nodeOffset.size()),
                                 layout_.nodeOffset.data());
            p->set("uView", view);
            p->set("uNear", camera.nearPlane);
            p->set("uTanHalf", glm::vec2(tanHalf * aspect, tanHalf));
        }
        hierarchy_.set("uRayOffset", rayOffset);
        setup_.set("uPlaneBias", p_.planeBias * radius);
        for (const ShaderProgram* p : {&pass1_, &pass2_, &jobArgs_}) {
            p->set("uTriangleCount", unsigned(scene_->triangleCount()));
            p->set("uSplitDepth", split);
            p->set("uJobCapacity", unsigned(p_.jobCapacity));
            p->set("uTolerance", tolerance);
            // q lies within |n| ray_offset of the G-buffer point that chose its implicit node, and
            // the 16-bit normal's length is within 1e-3 of 1.
            p->set("uImplicitPad", rayOffset * 1.01f);
            p->set("uInvView", glm::inverse(view));
            p->set("uRayOffset", rayOffset);
            // Half the tolerance, as psv: a sample this close to a plane is decided by the ray test.
            p->set("uCloseCall", 0.5f * tolerance);
        }
    }

    void bindAll() const {
        scene_->bindStorage();
        masks_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_MASK_BINDING);
        bounds_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_AABB_BINDING);
        samples_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_SAMPLE_BINDING);
        shadow_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_SHADOW_BINDING);
        planes_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_PLANE_BINDING);
        jobs_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_JOB_BINDING);
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_COUNTER_BINDING);
        jobIterations_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_JOB_ITER_BINDING);
        heatCounts_.bindBase(GL_SHADER_STORAGE_BUFFER, PTSV_HEAT_BINDING);
        // Views of what a pass reads but does not write (each writer's barrier includes the
        // texture-fetch bit).
        glBindTextureUnit(PTSV_BOUNDS_UNIT, boundsTexels_.id());
        glBindTextureUnit(PTSV_SAMPLE_UNIT, sampleTexels_.id());
        glBindTextureUnit(PTSV_PLANE_UNIT, planeTexels_.id());
        glBindTextureUnit(PTSV_MASK_UNIT, maskTexels_.id());
        glBindTextureUnit(PTSV_SHADOW_UNIT, shadowTexels_.id());
    }

    /// One invocation per item, as a 2D grid when the count needs more than 65535 groups of 64.
    static void dispatchLinear(const ShaderProgram& p, size_t count) { p.dispatchLinear(count, kSetupGroup); }

    PtsvParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    glm::ivec2 resolution_{0, 0};
    int subgroupSize_ = 0;
    Vote vote_ = kVoteShared;
    int lanes_ = 32; ///< invocations per traversal job (1 with traversal = invocation)
    bool perInvocation_ = false; ///< traversal = invocation (or packet, whose pass two is the same)
    bool packet_ = false;        ///< traversal = packet: pass one walks a subgroup's triangles together
    bool fellBack_ = false; ///< ballots met subgroups of another width: shared votes from then on
    ptsv::KeyLayout layout_;
    std::array<float, 6> layoutKey_{};
    ShaderProgram hierarchy_, clusters_, reduce_, setup_, pass1_, pass2_, jobArgs_, resolve_;
    GlBuffer masks_, bounds_, samples_, shadow_, heatCounts_, planes_, jobs_, jobIterations_;
    GlTexture boundsTexels_, sampleTexels_, planeTexels_, maskTexels_, shadowTexels_; ///< read-only views of those buffers
    GpuCounters<PTSV_COUNTER_WORDS> counters_;
    GlTexture heat_;
};

} // namespace

/// 128 bytes a triangle of planes (one storage block, checked against the reported limit as
/// setScene does), and what ensureLayout() allocates for the config's resolution and camera: the
/// view-sample hierarchy's masks and bounds (refused past a storage block as there), the per-sample
/// slots of whole tiles (a resolution that is no multiple of tile_size is padded), the job list.
Footprint ptsvFootprint(const FootprintQuery& q) {
    Footprint f;
    const PtsvParams p = ptsvParams().read(*q.params);
    const size_t planes = saturatingMul(q.triangles, PTSV_PLANES_PER_TRIANGLE * 16);
    const bool twoPass = p.twoPass;
    const size_t capacity = size_t(p.jobCapacity);
    const size_t jobs = twoPass ? capacity * 8 : 8;
    const size_t jobIterations = p.jobIterations ? saturatingMul(saturatingSum({q.triangles, twoPass ? capacity : 0, 1}), 4) : 4;
    const int tile = p.tileSize;
    ptsv::KeyLayout layout;
    try {
        layout = ptsv::makeKeyLayout(q.resolution, tile, q.fovYDeg, q.nearPlane, q.farPlane, p.maxKeyBits);
    } catch (const RuntimeError& e) {
        f.refusal = std::string(e.what()).substr(std::string("ptsv: ").size());
        return f;
    }
    const size_t bounds = p.bounds == PtsvBounds::Explicit ? layout.boundsNodes * 6 * sizeof(float) : 4;
    const size_t slots = size_t(layout.tilesX) * size_t(layout.tilesY) * size_t(tile) * size_t(tile);
    const size_t pixels = size_t(q.resolution.x) * size_t(q.resolution.y);
    const size_t perSlot = 16 + 4 + (p.heatMap ? 4 : 0); // samples, shadow marks, heat counts
    f.bytes = saturatingSum({planes, layout.maskWords * 4, bounds, saturatingMul(slots, perSlot), 4 * pixels, jobs, jobIterations});
    f.refusal = storageRefusal(q, "its shadow-volume planes", planes, true);
    if (f.refusal.empty()) f.refusal = storageRefusal(q, "the explicit bounds of its view-sample hierarchy", bounds, true);
    return f;
}
AlgorithmInfo ptsvInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<Ptsv>("ptsv",
                                    "per-triangle shadow volumes through a per-frame view-sample cluster hierarchy (compute)",
                                    {LightType::Point, LightType::Spot, LightType::Directional}, true, &ptsvSchema);
    info.footprint = &ptsvFootprint;
    return info;
}

} // namespace shadowlab
