#include "algorithms/psv/Psv.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/PixelList.h"
#include "framework/algorithm/SharedParams.h"
#include "algorithms/psv/PsvGpuLayout.h"
#include "algorithms/psv/PsvPermutation.h"
#include "framework/core/CheckedMath.h"
#include "framework/core/Error.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"

#include <algorithm>
#include <bit>
#include <array>
#include <climits>

namespace shadowlab {
namespace {

/// The values are the shaders' PSV_WEDGE_BOUND.
enum class PsvWedgeBound { Exact = 0, Distance = 1, Vertices = 2 };
const std::vector<Choice<PsvWedgeBound>> kPsvWedgeBounds = {
    {"exact", PsvWedgeBound::Exact}, {"distance", PsvWedgeBound::Distance}, {"vertices", PsvWedgeBound::Vertices}};
/// The values are the shaders' PSV_TRAVERSAL; auto resolves to one of them (Psv::traversal()).
enum class PsvTraversal { Auto = -1, Stack = 0, Stackless = 1, Hybrid = 2 };
const std::vector<Choice<PsvTraversal>> kPsvTraversals = {{"auto", PsvTraversal::Auto},
                                                       {"stack", PsvTraversal::Stack},
                                                       {"stackless", PsvTraversal::Stackless},
                                                       {"hybrid", PsvTraversal::Hybrid}};

struct PsvParams {
    bool wedge, randomOrder, frontFaceCulling, depthSkip, transparency;
    PsvWedgeBound wedgeBound;
    PsvTraversal traversal;
    int hybridStack; ///< hybrid traversal's stack, nodes
    int seed;        ///< of the insertion order
    int stackSize;   ///< query stack, nodes
    float rayOffset; ///< × scene radius
};

const ParamStruct<PsvParams>& psvParams() {
    using P = PsvParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        .boolean("wedge", &P::wedge, true,
                 "wedge optimisation (paper 3.5): an intersection child is visited only inside its wedge; off = the paper's \"No opt\"",
                 ParamChange::Recompile)
        // The paper's wedge takes the vertices' angles; the largest angle can lie inside an edge, so
        // that value can be too small and miss an occluder: not exact, measured, never the default.
        // "distance" by default: conservative (exact images) and, on the peer engine scene at 512²,
        // a third cheaper to build than "exact" for 5 % more traversal (results/reference/psv/ablation.md).
        .choice("wedge_bound", &P::wedgeBound, PsvWedgeBound::Distance, kPsvWedgeBounds,
                "point light: the wedge as the largest angle over the whole triangle seen from the light "
                "(exact), as the vertices' largest plane distance over the triangle's distance to the light "
                "(distance: wider, cheaper, still conservative) or over its vertices only (vertices: the "
                "paper's, may be too narrow, so not exact)",
                ParamChange::Recompile)
        .boolean("random_order", &P::randomOrder, true,
                 "merge triangles in a seeded pseudo-random order (paper 3.3) instead of scene order; off = \"No rand\"",
                 ParamChange::Recompile)
        .integer("seed", &P::seed, 1, 0, INT_MAX, "", "seed of the insertion order (with random_order)", ParamChange::Update)
        // Off by default: it is exact only for closed, consistently wound meshes (a ground plane
        // facing the light is dropped, fine; an open mesh would leak light through its back).
        .boolean("front_face_culling", &P::frontFaceCulling, false,
                 "only triangles facing away from the light cast (paper 4.2, its setting); exact for closed meshes only",
                 ParamChange::Recompile)
        // Off by default: measured slower on every scene it was tried on (its atomicMin per capping
        // node crossed in the build, a compare per capping node in the query; results/reference/psv/ablation.md).
        .boolean("depth_skip", &P::depthSkip, false,
                 "skip a capping node's subtree when the point is nearer the light than all of it (Mora et al. 2016); off = the 2015 paper",
                 ParamChange::Recompile)
        // auto: stackless on every device (docs/algorithms/psv.md, "Traversals": it cannot overflow
        // and was the fastest measured); the stack walk for x-ray shadows, which need it.
        .choice("traversal", &P::traversal, PsvTraversal::Auto, kPsvTraversals,
                "query walk (Mora et al. 2016): an explicit stack (the 2015 paper; may overflow), none "
                "(stackless: each triangle's escape node, written by the build, leads back up), or a "
                "short stack that walks stacklessly where it is full (hybrid); the same image; auto: "
                "see docs/algorithms/psv.md",
                ParamChange::Recompile)
        // 16 by measurement: on llvmpipe the hybrid is the faster the fewer times it switches (4, 8,
        // 16, 32 entries: 1.41, 1.46, 1.21, 1.13 x the stack walk's traversal, engine scene, 512²),
        // and 16 still halves the stack walk's 32 registers' worth of stack, the hybrid's point.
        .integer("hybrid_stack", &P::hybridStack, 16, 1, 256, "nodes",
                 "hybrid traversal: stack entries before an intersection child is walked stacklessly",
                 ParamChange::Recompile)
        .apply(stackSizeRow(&P::stackSize, 32))
        .boolean("transparency", &P::transparency, false,
                 "x-ray shadows (paper 4.3): multiply (1 - opacity) of every frustum containing the point",
                 ParamChange::Recompile)
        .apply(rayOffsetRow(&P::rayOffset))
        .rule("traversal", [](const P& p) {
            return p.transparency && (p.traversal == PsvTraversal::Stackless || p.traversal == PsvTraversal::Hybrid)
                       ? "traversal = " + std::string(choiceName(kPsvTraversals, p.traversal)) + " cannot take transparency (a capping plane's negative child would be "
                         "a second pending side of one node): use traversal = stack or auto"
                       : std::string();
        });
    return s;
}

const ParamSchema& psvSchema() { return psvParams().schema(); }

constexpr GLuint kBuildGroup = 64;  ///< local_size_x of frusta.comp and build.comp

class Psv final : public ShadowAlgorithm {
public:
    Psv(const ParamValues& p, const AlgorithmOptions& o) : p_(psvParams().read(p)), options_(o) { compile(); }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        const size_t n = scene.triangleCount();
        if (psv::nodeCount(n) > size_t(UINT32_MAX))
            throw RuntimeError("psv: " + std::to_string(n) + " triangles exceed 32-bit node indices");
        nodes_ = GlBuffer(psv::nodeCount(n) * PSV_NODE_BYTES, nullptr, 0);
        counters_.allocate();
        nodes_.clearUint(0);
        nodeTexels_ = makeBufferTexture(nodes_, GL_RGBA32UI, 16, "psv nodes");
        permutation_ = psv::makePermutation(uint32_t(n), uint32_t(p_.seed));
    }

    void resize(glm::ivec2 resolution) override {
        deferred_.resize(resolution);
        if (!options_.statistics) return; // the timed pass: no debug images
        nodesVisited_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
        overflow_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
    }

    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = psvParams().read(p);
        // The seed only keys the insertion order's bijection, passed as uniforms each frame.
        if (scene_) permutation_ = psv::makePermutation(uint32_t(scene_->triangleCount()), uint32_t(p_.seed));
        if (change == ParamChange::Recompile) compile();
    }

    void computeVisibility(const FrameInputs& f) override {
        setUniforms(f.light);

        f.timer.begin("build");
        counters_.clear();
        // Node 0 is the sentinel whose `pos` is the root pointer: emptying it empties the tree.
        // The other nodes need no clearing: frusta.comp rewrites every node that can be linked.
        if (shaderFaultActive("SHADOWLAB_FAULT_STALE_PLANES")) {
            // Test fault: every node left holding a plane that has everything inside it (a buffer
            // GL never initialised, or a previous scene's), which only a node frusta.comp did not
            // rewrite can show.
            const float inside[4] = {0.0f, 0.0f, 0.0f, -1.0f};
            glClearNamedBufferData(nodes_.id(), GL_RGBA32F, GL_RGBA, GL_FLOAT, inside);
        }
        // The sentinel's plane carries the tolerance to every pass (psv/tree.glsl, psvReadMargins).
        const uint32_t sentinelPlane[4] = {0, 0, 0, std::bit_cast<uint32_t>(tolerance_)}, noChildren[4] = {0, 0, 0, 0};
        glClearNamedBufferSubData(nodes_.id(), GL_RGBA32UI, 0, 16, GL_RGBA_INTEGER, GL_UNSIGNED_INT, sentinelPlane);
        glClearNamedBufferSubData(nodes_.id(), GL_RGBA32UI, 16, 16, GL_RGBA_INTEGER, GL_UNSIGNED_INT, noChildren);
        scene_->bindStorage();
        nodes_.bindBase(GL_SHADER_STORAGE_BUFFER, PSV_NODE_BINDING);
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, PSV_COUNTER_BINDING);
        glBindTextureUnit(PSV_NODE_UNIT, nodeTexels_.id());
        if (scene_->triangleCount() > 0) {
            dispatchPerTriangle(frusta_);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
            dispatchPerTriangle(build_);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        }
        f.timer.end();

        // Light culling: a point light sees every direction and a directional light the whole
        // scene; a spot light's cone culls the triangles wholly outside it (frusta.comp).
        f.timer.begin("traverse");
        traverse(f);
        // Test fault: a GL error in the frame (what a failed allocation raises), which must stop
        // the run before it saves anything.
        if (shaderFaultActive("SHADOWLAB_FAULT_GL_ERROR")) glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0xFFFFFFF0u);
        // Test fault: the traverse stage done N more times (the same image), a planted slowdown
        // for the checks that must catch one (expectations, compare).
        for (int extra = shaderFaultCount("SHADOWLAB_FAULT_SLOW_TRAVERSE"); extra > 0; --extra) traverse(f);
        f.timer.end();
        counters_.markStale();
    }

    std::vector<Counter> counters() const override {
        const auto& c = counters_.read();
        static_assert(PSV_C_VISITED_HI == PSV_C_VISITED_LO + 1);
        const double visited = double(counters_.wide(PSV_C_VISITED_LO));
        const double traversed = c[PSV_C_TRAVERSED];
        if (!options_.statistics) // the timed pass: what is still measured
            return {{"stack_overflow_pixels", double(c[PSV_C_STACK_OVERFLOW])},
                    {"loop_capped_pixels", double(c[PSV_C_LOOP_CAPPED])},
                    {"build_errors", double(c[PSV_C_BUILD_ERRORS])}};
        return {{"nodes_visited_mean", traversed > 0 ? visited / traversed : 0.0},
                {"nodes_visited_max", double(c[PSV_C_VISITED_MAX])},
                {"stack_overflow_pixels", double(c[PSV_C_STACK_OVERFLOW])},
                {"loop_capped_pixels", double(c[PSV_C_LOOP_CAPPED])},
                {"traversed_pixels", traversed},
                {"casters_inserted", double(c[PSV_C_INSERTED])},
                {"culled_front_facing", double(c[PSV_C_CULLED_FACING])},
                {"culled_edge_on", double(c[PSV_C_CULLED_EDGE_ON])},
                {"culled_outside_cone", double(c[PSV_C_CULLED_CONE])},
                {"culled_occluded", double(c[PSV_C_CULLED_OCCLUDED])},
                {"insert_depth_max", double(c[PSV_C_INSERT_DEPTH_MAX])},
                {"close_calls", double(c[PSV_C_CLOSE_CALLS])},
                {"deferred_pixels", double(c[PSV_C_DEFERRED])},
                {"stackless_walks", double(c[PSV_C_STACKLESS_WALKS])},
                {"build_errors", double(c[PSV_C_BUILD_ERRORS])}};
    }

    std::vector<DebugView> debugViews() const override {
        if (!options_.statistics) return {};
        return {{"nodes_visited", nodesVisited_.id(), 0.0f, "nodes"}, {"stack_overflow", overflow_.id(), 1.0f, "flag"}};
    }

    std::vector<std::pair<std::string, std::string>> resolvedParams() const override {
        return {{"traversal", choiceName(kPsvTraversals, traversal())}};
    }

    /// The tree (4n + 1 nodes of 32 bytes) plus the 96-byte counter block: exactly 128 (n + 1) bytes.
    /// Not counted: the per-pixel debug images (nodes_visited, stack_overflow), which every image
    /// algorithm could add and which do not depend on the scene.
    size_t memoryBytes() const override { return nodes_.size() + counters_.size(); }

    /// Pixels whose query stack overflowed or whose stackless walk hit its escape cap (both written
    /// shadowed) plus build errors (must be 0).
    uint64_t overflowCount() const override {
        const auto& c = counters_.read();
        return uint64_t(c[PSV_C_STACK_OVERFLOW]) + c[PSV_C_LOOP_CAPPED] + c[PSV_C_BUILD_ERRORS];
    }

private:
    /// The query: with the plane walk, every pixel by planes alone and then the pixels it listed
    /// (a close call met) by the exact walk (query.comp); otherwise the exact walk on every pixel.
    void traverse(const FrameInputs& f) const {
        if (planeWalk_) deferred_.begin();
        if (options_.statistics) runPixelPass(f, query_, {&nodesVisited_, &overflow_});
        else runPixelPass(f, query_, {});
        if (!planeWalk_) return;
        deferred_.dispatch(exactPass_); // the inputs and debug images are still bound
        finishPixelPass();
    }

    /// `auto`: stackless, or the stack walk for x-ray shadows (docs/algorithms/psv.md, "Traversals").
    PsvTraversal traversal() const {
        if (p_.traversal != PsvTraversal::Auto) return p_.traversal;
        return p_.transparency ? PsvTraversal::Stack : PsvTraversal::Stackless;
    }

    void compile() {
        auto flag = [](bool on) { return on ? std::string("1") : std::string("0"); };
        const PsvTraversal walk = traversal();
        if (p_.transparency && walk != PsvTraversal::Stack)
            throw RuntimeError("psv: traversal = " + std::string(choiceName(kPsvTraversals, walk)) + " cannot take transparency (a capping plane's negative "
                               "child would be a second pending side of one node): use traversal = stack");
        // The plane walk first where the walk can stop at a close call and leave the pixel to the
        // exact walk: not with x-ray shadows (a close call's transmission is a factor of the
        // product) nor the hybrid walk (whose stackless subtrees return to the stack walk).
        planeWalk_ = !p_.transparency && walk != PsvTraversal::Hybrid;
        ShaderDefines defines = {{"PSV_WEDGE", flag(p_.wedge)},
                                 {"PSV_WEDGE_BOUND", std::to_string(int(p_.wedgeBound))},
                                 {"PSV_RANDOM_ORDER", flag(p_.randomOrder)},
                                 {"PSV_FRONT_FACE_CULLING", flag(p_.frontFaceCulling)},
                                 {"PSV_DEPTH_SKIP", flag(p_.depthSkip)},
                                 {"PSV_TRANSPARENCY", flag(p_.transparency)},
                                 {"PSV_STACK_SIZE", std::to_string(p_.stackSize)},
                                 {"PSV_TRAVERSAL", std::to_string(int(walk))},
                                 {"PSV_HYBRID_STACK", std::to_string(p_.hybridStack)},
                                 {"PSV_PLANE_WALK", flag(planeWalk_)},
                                 statisticsDefine(options_)};
        frusta_ = ShaderProgram::compute("psv/frusta.comp", defines);
        build_ = ShaderProgram::compute("psv/build.comp", defines);
        query_ = ShaderProgram::compute("psv/query.comp", defines);
        exactPass_ = ShaderProgram();
        if (planeWalk_) {
            defines.push_back({"PSV_QUERY_PASS", "1"});
            exactPass_ = ShaderProgram::compute("psv/query.comp", defines);
            deferred_.compile(PSV_DEFER_LIST_BINDING, PSV_DEFER_ARGS_BINDING);
        }
    }

    void setUniforms(const Light& light) {
        const Bounds& b = scene_->bounds();
        const float radius = b.empty() ? 1.0f : b.radius();
        const glm::vec3 center = b.empty() ? glm::vec3(0.0f) : b.center();
        // Rounding of a plane evaluation grows with the coordinates' magnitude (and the light's:
        // shadow planes pass through it); 4e-6 of it is well above float error, and only costs
        // extra intersection-child visits for triangles that close to a plane.
        float magnitude = glm::length(center) + radius;
        if (light.type != LightType::Directional) magnitude = std::max(magnitude, glm::length(light.position));
        const float tolerance = 4e-6f * magnitude;
        const glm::vec3 depthOrigin = center - light.direction() * (2.0f * radius);
        const float rayOffset = rayOffsetLength(p_.rayOffset, *scene_);
        const uint32_t n = uint32_t(scene_->triangleCount());
        for (const ShaderProgram* p : {&frusta_, &build_, &query_, &exactPass_}) {
            if (!*p) continue; // no exact pass without the plane walk
            setLightUniforms(*p, light);
            p->set("uTriangleCount", unsigned(n));
            p->set("uDepthOrigin", depthOrigin);
            glProgramUniform4ui(p->id(), p->location("uPermKeys"), permutation_.keys[0], permutation_.keys[1],
                                permutation_.keys[2], permutation_.keys[3]);
            p->set("uPermHalfBits", unsigned(permutation_.halfBits));
        }
        for (const ShaderProgram* p : {&query_, &exactPass_})
            if (*p) p->set("uRayOffset", rayOffset);
        tolerance_ = tolerance; // the query's close-call margin is half of it (query.comp)
    }

    /// One invocation per triangle, as a 2D grid when n needs more than 65535 groups of 64.
    void dispatchPerTriangle(const ShaderProgram& p) const { p.dispatchLinear(scene_->triangleCount(), kBuildGroup); }

    PsvParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    ShaderProgram frusta_, build_, query_, exactPass_; ///< exactPass_: the listed pixels' exact walk
    bool planeWalk_ = false;
    float tolerance_ = 0.0f; ///< the build's tolerance, written into the sentinel node each frame
    PixelList deferred_; ///< the pixels the plane walk left to the exact walk
    GlBuffer nodes_;
    GpuCounters<PSV_COUNTER_WORDS> counters_;
    GlTexture nodesVisited_, overflow_;
    GlTexture nodeTexels_; ///< nodes_ as a buffer texture: how the build reads planes and the query whole nodes
    psv::Permutation permutation_;
};

} // namespace

/// The node pool (the paper's 128 bytes a triangle) is one storage block and one RGBA32UI view of
/// two texels a node; the frusta and the close calls read the scene's positions through its view.
Footprint psvFootprint(const FootprintQuery& q) {
    Footprint f;
    const size_t n = q.triangles;
    // Per pixel: the two debug images (8 bytes) and the plane walk's list of close calls (4).
    f.bytes = saturatingSum({psv::memoryBytes(n), saturatingMul(12, saturatingMul(size_t(q.resolution.x), size_t(q.resolution.y)))});
    f.refusal = storageRefusal(q, "its node pool", saturatingMul(psv::nodeCount(n), PSV_NODE_BYTES));
    if (f.refusal.empty()) f.refusal = texelRefusal(q, "its node pool's view", saturatingMul(2, psv::nodeCount(n)));
    if (f.refusal.empty()) f.refusal = texelRefusal(q, "the scene positions' view it reads", saturatingMul(3, n));
    return f;
}

AlgorithmInfo psvInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<Psv>("psv",
                                    "partitioned shadow volumes: per-frame TOP tree of shadow frusta (compute), per-pixel stack, stackless or hybrid query",
                                    {LightType::Point, LightType::Spot, LightType::Directional}, true, &psvSchema);
    info.footprint = &psvFootprint;
    info.takesOpacity = [](const ParamValues& params) { return std::get<bool>(params.get("transparency")); };
    return info;
}

} // namespace shadowlab
