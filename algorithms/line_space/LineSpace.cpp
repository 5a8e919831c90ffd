#include "algorithms/line_space/LineSpace.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/SharedParams.h"
#include "framework/accel/BvhGpu.h"
#include "algorithms/line_space/LineSpaceCache.h"
#include "algorithms/line_space/NTree.h"
#include "algorithms/line_space/SampleClassifier.h"
#include "framework/core/CheckedMath.h"
#include "framework/core/DiskCache.h"
#include "framework/core/Error.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>

namespace shadowlab {
namespace {

enum class LineSpaceLastLevel { Leaves, Shaft };
enum class LineSpaceStartTriangles { Culled, All };

struct LineSpaceParams {
    int n, d;          ///< N-tree branching factor and depth
    bool cache, classify;
    int maxBlockMib;   ///< 0 = the context's storage block limit
    float rayOffset;   ///< × scene radius
    ls::StartMode startRegion;
    LineSpaceLastLevel lastLevel;
    LineSpaceStartTriangles startTriangles; ///< how the exact start region tests a leaf's triangles
    int leafSplit;                       ///< sub-cells per axis of an occupied leaf (1: the leaf decides)
    float startCells, startMaxCells;     ///< leaf widths
    bool rebuildEveryFrame;              ///< allows moving scenes: the whole precomputation each frame
    int samplesPerDispatch;              ///< most light samples per pixel one dispatch traces
};

/// What one of its storage blocks may hold here: max_block_mib (0: no cap) within the context's limit.
size_t poolBlockLimit(int maxBlockMib) {
    const size_t cap = size_t(maxBlockMib) << 20;
    return cap > 0 ? std::min(cap, maxShaderStorageBlockBytes()) : maxShaderStorageBlockBytes();
}

const ParamStruct<LineSpaceParams>& lineSpaceParams() {
    using P = LineSpaceParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        // The paper uses N in 4..8 with d = 4 for N ≤ 5 and d = 3 above; (6, 3) is its mid-size set.
        .integer("n", &P::n, 6, 2, ls::kMaxN, "children per axis",
                 "branching factor N of the N-tree: N³ children per subdivided node, 15 N⁴ shaft bits each",
                 ParamChange::Rebuild)
        .integer("d", &P::d, 3, 1, ls::kMaxDepth, "levels",
                 "depth d of the N-tree: levels 0..d-1 hold line spaces, level d (N^d cells per axis) is implicit",
                 ParamChange::Rebuild)
        .apply(cacheRow(&P::cache, "line_space"))
        // Off by default: it traces every sample again on the CPU, far slower than the GPU pass.
        .boolean("classify", &P::classify, false,
                 "also trace every sample exactly on the CPU (untimed) and report over-/under-occluded shares",
                 ParamChange::Update)
        // A GPU's limit is usually 128 MiB to 2 GiB; a smaller cap shows how a big line-space pool is
        // split (and lets the tests exercise the split on small scenes).
        .integer("max_block_mib", &P::maxBlockMib, 0, 0, 1 << 16, "MiB",
                 "cap on one SSBO (0 = GL_MAX_SHADER_STORAGE_BLOCK_SIZE); the line-space pool may span 4 of them",
                 ParamChange::Rebuild)
        .apply(rayOffsetRow(&P::rayOffset))
        // "node" is Algorithm 1 as published: its start region (the last-level node holding the
        // origin) is too short, the next node's shaft holds the receiver's own surface and lit
        // surfaces shadow themselves (docs/algorithms/line_space.md, "Where the error comes from").
        // "bvh" by measurement (docs/algorithms/line_space.md, "Cost model"): as accurate as "exact"
        // at about half its trace time here.
        .choice("start_region", &P::startRegion, ls::StartMode::Bvh,
                {{"exact", ls::StartMode::Exact}, {"distance", ls::StartMode::Distance}, {"node", ls::StartMode::Node},
                 {"bvh", ls::StartMode::Bvh}},
                "where the line space is not used next to the receiver: the last-level nodes a ray enters before "
                "rising start_cells leaf widths above the receiver's tangent plane, tested against their triangles "
                "(exact: a hybrid that keeps the scene's triangles on the GPU) or with geometry before that height "
                "ignored and the rest of those nodes by leaf occupancy (distance); node = the paper's Algorithm 1, "
                "the last-level node holding the origin skipped; bvh = the distance region's walk, the segment before "
                "its end traced exactly through a BVH of the scene (bvh_raytrace's build and traversal)",
                ParamChange::Rebuild)
        // "shaft" is Algorithm 1's "deep enough": the shaft of a last-level node stands for its
        // leaves, so shadows grow by up to a shaft's width around every occluder.
        .choice("last_level", &P::lastLevel, LineSpaceLastLevel::Leaves,
                {{"leaves", LineSpaceLastLevel::Leaves}, {"shaft", LineSpaceLastLevel::Shaft}},
                "a non-empty shaft of a last-level node: leaves = the leaves the ray crosses there decide "
                "(occupancy mask); shaft = the ray is blocked (the paper's)",
                ParamChange::Rebuild)
        // The leaf of growth: an occupied leaf blocks every ray through it, so shadows grow by up to a
        // leaf around every occluder (docs/algorithms/line_space.md, "Where the error comes from").
        // Split, only the occupied sub-cells the ray crosses block it.
        // 4 by measurement: worst-frame RMSE 0.047 -> 0.016 on the 882 k-triangle side-by-side scene at
        // 1024² for 1.33x the trace time (docs/algorithms/line_space.md, "The leaf of growth").
        .integer("leaf_split", &P::leafSplit, 4, 1, 4, "sub-cells per axis",
                 "where an occupied leaf would block a ray (last_level leaves, the start region after its end), "
                 "its leaf_split³ sub-cells decide instead, by their own occupancy bits (64 bits per occupied leaf "
                 "at 4); 1 = the leaf decides",
                 ParamChange::Rebuild)
        // "culled" by measurement (docs/algorithms/line_space.md, "Cost model"): the same decisions
        // for a fraction of the watertight tests; "all" is the leaf walk as it was, for the A/B.
        .choice("start_triangles", &P::startTriangles, LineSpaceStartTriangles::Culled,
                {{"culled", LineSpaceStartTriangles::Culled}, {"all", LineSpaceStartTriangles::All}},
                "start_region exact: how a start-region leaf's triangles are tested: culled = empty leaves skipped "
                "in a loop of their own, then a plane test of the segment's part in the leaf against each "
                "triangle's plane and the watertight test only for those it cannot rule out; all = every "
                "triangle by the watertight test, in one loop with the leaf steps",
                ParamChange::Rebuild)
        // 6 and 64 by measurement: fewer leaf widths leave self-shadowing, more cost nothing but
        // leave the error where it is (docs/algorithms/line_space.md, Parameters).
        .real("start_cells", &P::startCells, 6.0, 0.0, 64.0, "leaf widths",
              "start_region exact/distance: height above the receiver's tangent plane (in leaf widths along its "
              "normal) at which a ray's start region ends",
              ParamChange::Update)
        .real("start_max_cells", &P::startMaxCells, 64.0, 0.0, 1024.0, "leaf widths",
              "start_region exact/distance: most leaf widths along the ray a start region spans (grazing rays)",
              ParamChange::Update)
        // The method precomputes for static scenes; rebuilding shows what moving geometry costs it.
        .boolean("rebuild_every_frame", &P::rebuildEveryFrame, false,
                 "allow a scene with moving parts: rebuild the N-tree and its line spaces from the posed triangles "
                 "every frame they move (the `rebuild` stage; the disk cache is bypassed)",
                 ParamChange::Update)
        // 8: at the defaults one sample of every pixel of a 4K frame costs ~42 ms on a GPU (~4.2 s on
        // llvmpipe here, ~100x slower) on an 882 k-triangle scene: ~0.34 s a dispatch, 6x under 2 s
        // (docs/algorithms/line_space.md, "Dispatches").
        .apply(samplesPerDispatchRow(&P::samplesPerDispatch, 8));
    return s;
}

const ParamSchema& lineSpaceSchema() { return lineSpaceParams().schema(); }

class LineSpace final : public ShadowAlgorithm {
public:
    LineSpace(const ParamValues& p, const AlgorithmOptions& o) : p_(lineSpaceParams().read(p)), options_(o) {
        instrumentParams();
        compile();
    }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        build(scene.cpu(), p_.cache);
    }

    // Only with rebuild_every_frame (the host refuses a moving scene otherwise): the posed triangles
    // are read back and everything setScene() does is done again on them.
    void sceneMoved(const FrameInputs& f) override {
        f.timer.begin("rebuild", false);
        posed_ = scene_->posedScene();
        build(posed_, false);
        f.timer.end();
    }

    /// The whole precomputation for `cpu`: the N-tree with its line spaces (from the disk cache when
    /// allowed), what the start region reads, the pools uploaded, and the loop caps.
    void build(const Scene& cpu, bool useCache) {
        freePools();
        const size_t limit = poolBlockLimit(p_.maxBlockMib);
        tree_ = obtainTree(cpu, p_.n, p_.d, limit, useCache);
        const StartData start = buildStartData(cpu, limit);
        uploadPools(start, limit);
        planeEps_ = planeEpsilon(tree_);
        setLoopCaps(start.longestList);
        counters_.allocate();
        // The GPU holds the pools now; the CPU keeps only the node pool (start-node boxes for classify).
        tree_.tree = {};
        tree_.bits = {};
        tree_.occupancy = {};
        classes_.reset();
    }

    void resize(glm::ivec2 resolution) override {
        resolution_ = resolution;
        if (!options_.statistics) return; // the timed pass: no debug image
        nodesVisited_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
        loopCapped_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
    }

    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = lineSpaceParams().read(p);
        instrumentParams();
        // setScene() follows a Rebuild (ShadowAlgorithm.h) and compiles for the new tree's block count.
        // (start_region, a Rebuild, changes a define too.)
        if (change == ParamChange::Rebuild) bitChunks_ = 0;
    }

    void computeVisibility(const FrameInputs& f) override {
        const bool classify = p_.classify;
        const int sampleCount = uploadLightSamples(samples_, f.light);
        const int budget = p_.samplesPerDispatch;
        const glm::ivec2 res = f.gbuffer.resolution();
        const size_t classifyBytes = size_t(resolution_.x) * size_t(resolution_.y) * ls::classifyStride(size_t(sampleCount)) * 4;
        if (classify && classifyBytes > classifyBuf_.size()) classifyBuf_ = GlBuffer(classifyBytes, nullptr, 0);
        if (classify && !classifyProgram_)
            classifyProgram_ = ShaderProgram::compute("line_space/trace.comp", defines(true));
        const ShaderProgram& p = classify ? classifyProgram_ : trace_;

        // One stage over every dispatch: the frame's cost, however it is split.
        f.timer.begin("trace");
        counters_.clear();
        setLightUniforms(p, f.light);
        p.set("uRayOffset", rayOffset());
        p.set("uSampleCount", sampleCount);
        p.set("uWalkCap", unsigned(walkCap_));
        p.set("uLeafWalkCap", unsigned(leafWalkCap_));
        p.set("uNodeCount", unsigned(tree_.nodes.size()));
        p.set("uNodesPerChunk", unsigned(nodesPerChunk_));
        const ls::StartRegion region = startRegion();
        p.set("uLeafCell", region.leafCell);
        p.set("uStartCells", region.cells);
        p.set("uStartMaxCells", region.maxCells);
        p.set("uPlaneEps", planeEps_);
        p.set("uLeafMargin", 0.0625f * std::max({region.leafCell.x, region.leafCell.y, region.leafCell.z}));
        if (region.mode == ls::StartMode::Exact) scene_->bindStorage(); // the positions' buffer texture
        if (region.mode == ls::StartMode::Bvh) {
            p.set("uBvhStepCap", unsigned(near_.stepCap));
            near_.bind(LS_BVH_NODE_UNIT, LS_BVH_TRI_UNIT);
        }
        for (size_t u = 0; u < kTexelUnits; ++u)
            if (texels_[u]) glBindTextureUnit(GLuint(LS_NODE_UNIT + u), texels_[u].id());
        samples_.bindBase(GL_SHADER_STORAGE_BUFFER, LS_SAMPLE_BINDING);
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, LS_COUNTER_BINDING);
        if (classify) classifyBuf_.bindBase(GL_SHADER_STORAGE_BUFFER, LS_CLASSIFY_BINDING);
        bindPixelPassInputs(f);
        if (options_.statistics) bindDebugImage(1, nodesVisited_), bindDebugImage(2, loopCapped_);
        // The state between dispatches (layout.glsl); a single dispatch never touches it.
        batches_.begin(sampleCount, budget, res, options_.statistics, LS_ACCUM_UNIT);
        batches_.dispatch(p, res);
        finishPixelPass();
        f.timer.end();
        counters_.markStale();
        classes_.reset();
        if (classify) { // classified lazily in counters(), outside the timed stages
            pendingG_ = f.cpuGBuffer();
            pendingLight_ = f.light;
        }
    }

    std::vector<Counter> counters() const override {
        const auto& c = counters_.read();
        auto wide = [&](size_t lo) { return double(counters_.wide(lo)); };
        const double rays = wide(LS_C_RAYS_LO);
        auto perRay = [&](double v) { return rays > 0 ? v / rays : 0.0; };
        // The structure and what is measured in both modes; the timed pass compiles the rest out.
        std::vector<Counter> out = {{"truncated_pixels", double(c[LS_C_TRUNCATED])},
                                    {"loop_capped_pixels", double(c[LS_C_CAPPED])},
                                    {"sample_dispatches", double(batches_.dispatches())},
                                    {"subdivided_nodes", double(tree_.nodes.size())},
                                    {"build_ms", tree_.buildMs},
                                    {"cache_hit", cacheHit_ ? 1.0 : 0.0},
                                    {"node_pool_bytes", double(poolBytes_[0])},
                                    {"tree_pool_bytes", double(poolBytes_[1])},
                                    {"line_space_pool_bytes", double(poolBytes_[2])},
                                    {"occupancy_pool_bytes", double(poolBytes_[3])},
                                    {"exact_start_bytes", double(poolBytes_[4])}};
        if (!options_.statistics) return out;
        out.insert(out.begin(), {{"nodes_visited_mean", perRay(wide(LS_C_VISITED_LO))},
                                 {"nodes_visited_max", double(c[LS_C_VISITED_MAX])},
                                 {"shafts_tested_mean", perRay(wide(LS_C_SHAFTS_LO))},
                                 {"cells_stepped_mean", perRay(wide(LS_C_CELLS_LO))},
                                 {"leaf_cells_mean", perRay(wide(LS_C_LEAVES_LO))},
                                 {"triangles_tested_mean", perRay(wide(LS_C_TRIS_LO))},
                                 {"near_nodes_mean", perRay(wide(LS_C_NEAR_NODES_LO))},
                                 {"occluded_share", perRay(wide(LS_C_OCCLUDED_LO))},
                                 {"rays", rays},
                                 {"traced_pixels", double(c[LS_C_PIXELS])}});
        for (size_t l = 0; l < tree_.nodesPerLevel.size(); ++l)
            out.push_back({"nodes_level_" + std::to_string(l), double(tree_.nodesPerLevel[l])});
        // The SIMD probe: per section, the lane slots a ray pays (its subgroup's passes × width, per
        // ray) and the share of them doing its work (utilisation); absent without a ballot.
        static_assert(LS_SIMD_SECTIONS == 8);
        appendSimdProbeCounters(out, {"walk", "node", "leaf", "plane", "triangle", "sub_cell", "near_node", "near_triangle"}, LS_C_SIMD_BASE,
                                c[LS_C_SIMD_WIDTH], rays, wide);
        if (p_.classify && pendingG_.width > 0) {
            const ls::SampleClasses& k = classify();
            const double n = k.samples > 0 ? double(k.samples) : 1.0;
            out.push_back({"classified_samples", double(k.samples)});
            out.push_back({"exact_occluded_share", double(k.exactOccluded) / n});
            out.push_back({"over_occluded_share", double(k.over) / n});
            out.push_back({"under_occluded_share", double(k.under) / n});
            out.push_back({"under_occluded_start_node_share", double(k.underInStart) / n});
            out.push_back({"under_occluded_elsewhere", double(k.underElsewhere)});
        }
        return out;
    }

    std::vector<DebugView> debugViews() const override {
        if (!options_.statistics) return {};
        return {{"nodes_visited", nodesVisited_.id(), 0.0f, "nodes/pixel"}, {"loop_capped", loopCapped_.id(), 1.0f, "flag"}};
    }

    /// The three pools (the paper's Table 1 size), plus the occupancy pool when the start region
    /// reads it, plus the leaf lists and the scene's triangle positions for the exact start region
    /// (the paper's method, start_region node, holds no geometry at all). Not counted: the sample
    /// list, the per-pixel heat map and the classify buffer (debug only).
    size_t memoryBytes() const override {
        size_t sum = 0;
        for (size_t b : poolBytes_) sum += b;
        return sum;
    }

    /// Traversal stack overflows (one frame per level always suffices, so 0 unless the pools are
    /// corrupt; such a ray is counted occluded) plus pixels whose sample loop the driver cut short
    /// or with a ray whose walk reached its loop cap (both written shadowed): never lit by mistake.
    uint64_t overflowCount() const override {
        const auto& c = counters_.read();
        return uint64_t(c[LS_C_OVERFLOW]) + c[LS_C_TRUNCATED] + c[LS_C_CAPPED];
    }

    /// The storage block size build() splits the line-space pool by, in MiB, on this device.
    std::vector<std::pair<std::string, std::string>> resolvedParams() const override {
        return {{"max_block_mib", std::to_string(poolBlockLimit(p_.maxBlockMib) >> 20)}};
    }

private:
    /// What the start region reads besides the tree: the near field's BVH (start_region bvh), the
    /// leaf lists (exact start region, or split leaves) and the triangles' planes (culled).
    struct StartData {
        ls::LeafLists lists;
        std::vector<glm::vec4> planes; ///< culled: per scene triangle its plane (unit normal, offset)
        uint64_t longestList = 0;      ///< triangles of the largest leaf list (exact)
        size_t nearBytes = 0;          ///< the near field's BVH on the GPU
    };

    void freePools() {
        tracer_.reset();
        texels_ = {}; // the views first: a buffer texture keeps its buffer alive
        nodesBuf_ = GlBuffer(), treeBuf_ = GlBuffer(), occBuf_ = GlBuffer(); // free the old pools first
        for (GlBuffer& b : bitsBuf_) b = GlBuffer();
        leafBase_ = GlBuffer(), leafPrefix_ = GlBuffer(), leafTris_ = GlBuffer(), triPlanes_ = GlBuffer(), leafSub_ = GlBuffer();
        near_ = bvh::BvhGpu();
    }

    bool listsNeeded() const { return startMode() == ls::StartMode::Exact || leafSplit() > 1; }

    StartData buildStartData(const Scene& cpu, size_t limit) {
        StartData out;
        // start_region bvh: bvh_raytrace's tree of the scene with its default build (SAH, leaves of 4).
        if (startMode() == ls::StartMode::Bvh) {
            near_ = bvh::uploadBvh(bvh::buildBvh(cpu, bvh::BuildOptions{}), limit, 0, "line_space");
            out.nearBytes = near_.bytes();
        }
        if (culledStart()) out.planes = ls::trianglePlanes(cpu);
        if (!listsNeeded()) return out;
        out.lists = ls::buildLeafLists(cpu, tree_, 0, leafSplit());
        for (size_t i = 1; i < out.lists.prefix.size(); ++i)
            out.longestList = std::max<uint64_t>(out.longestList, out.lists.prefix[i] - out.lists.prefix[i - 1]);
        // The shader numbers a leaf by the occupancy bits below it: one occupied leaf without a list
        // (or the reverse) would shift every later list, so the two must agree exactly.
        size_t occupied = 0;
        const size_t words = ls::occupancyWords(p_.n);
        for (size_t i = 0; i < tree_.nodes.size(); ++i)
            if (int(tree_.nodes[i].level) == p_.d - 1)
                for (size_t w = 0; w < words; ++w) occupied += size_t(std::popcount(tree_.occupancy[i * words + w]));
        if (occupied + 1 != out.lists.prefix.size())
            throw RuntimeError("line_space: the leaf lists (" + std::to_string(out.lists.prefix.size() - 1) +
                               " leaves) disagree with the occupancy pool (" + std::to_string(occupied) + " leaves)");
        return out;
    }

    static std::string mib(size_t bytes) {
        char text[32];
        std::snprintf(text, sizeof text, "%.1f", double(bytes) / double(1u << 20));
        return std::string(text);
    }

    /// Node and tree pools are one SSBO each; the line-space pool is split at node boundaries over
    /// up to LS_BIT_CHUNKS SSBOs. buildNTree() stops at these limits; a cache file written on a GPU
    /// with a larger limit is caught here.
    void uploadPools(const StartData& start, size_t limit) {
        // The occupancy pool is read (and counted) only by the distance and exact start regions; the
        // leaf lists and the scene's triangles only by the exact one.
        const bool occupancy = readsOccupancy(), exact = startMode() == ls::StartMode::Exact;
        const int split = leafSplit();
        const ls::LeafLists& lists = start.lists;
        poolBytes_ = {tree_.nodes.size() * sizeof(ls::NodeGpu), tree_.tree.size() * sizeof(uint32_t),
                      tree_.bits.size() * sizeof(uint32_t), occupancy ? tree_.occupancy.size() * sizeof(uint32_t) : 0,
                      (exact ? lists.bytes() + scene_->positions().size() + start.planes.size() * sizeof(glm::vec4)
                             : listsNeeded() ? (lists.wordRank.size() + lists.sub.size()) * sizeof(uint32_t) : 0) + start.nearBytes};
        nodesPerChunk_ = ls::nodesPerChunk(p_.n, limit);
        const size_t words = ls::wordsPerNode(p_.n), chunks = (tree_.nodes.size() + nodesPerChunk_ - 1) / nodesPerChunk_;
        if (poolBytes_[0] > limit || poolBytes_[1] > limit || chunks > LS_BIT_CHUNKS)
            throw SceneRefusal("line_space: the pools of (N, d) = (" + std::to_string(p_.n) + ", " + std::to_string(p_.d) + ") need " +
                               mib(poolBytes_[0]) + " + " + mib(poolBytes_[1]) + " + " + mib(poolBytes_[2]) +
                               " MiB (node, tree, line space); one SSBO may hold " + mib(limit) +
                               " MiB here (GL_MAX_SHADER_STORAGE_BLOCK_SIZE, or max_block_mib) and the line space may span " +
                               std::to_string(LS_BIT_CHUNKS));
        nodesBuf_ = GlBuffer::fromVector(tree_.nodes, 0);
        treeBuf_ = GlBuffer::fromVector(tree_.tree, 0);
        if (occupancy) occBuf_ = GlBuffer::fromVector(tree_.occupancy, 0);
        if (exact) {
            for (auto [what, bytes] : {std::pair{"leaf triangle lists", lists.tris.size() * sizeof(uint32_t)},
                                       std::pair{"scene positions", scene_->positions().size()}})
                if (bytes > limit)
                    throw SceneRefusal(std::string("line_space: the ") + what + " of start_region exact need " + mib(bytes) +
                                       " MiB; one SSBO may hold " + mib(limit) + " MiB here");
            leafPrefix_ = GlBuffer::fromVector(lists.prefix, 0);
            leafTris_ = GlBuffer::fromVector(lists.tris, 0);
            if (culledStart()) triPlanes_ = GlBuffer::fromVector(start.planes, 0);
        }
        if (listsNeeded()) leafBase_ = GlBuffer::fromVector(lists.wordRank, 0);
        if (split > 1) leafSub_ = GlBuffer::fromVector(lists.sub, 0);
        for (size_t c = 0; c < LS_BIT_CHUNKS; ++c) {
            // Unused chunks get a 4-byte buffer so every buffer texture the shader may declare has one.
            const size_t first = std::min(tree_.bits.size(), c * nodesPerChunk_ * words);
            const size_t last = std::min(tree_.bits.size(), (c + 1) * nodesPerChunk_ * words);
            bitsBuf_[c] = GlBuffer((last - first) * sizeof(uint32_t), last > first ? tree_.bits.data() + first : nullptr, 0);
        }
        makeTexels(occupancy, exact, culledStart(), split > 1);
        // The shader reads the line-space pool with one load when it is a single block; a tree that
        // needs more blocks gets the program that picks the block per node.
        const int usedChunks = int(std::max<size_t>(1, chunks));
        if (usedChunks != bitChunks_) {
            bitChunks_ = usedChunks;
            compile();
        }
    }

    /// A point's distance to a triangle's plane, computed in float, is off by a few units in the
    /// last place of the coordinates (the plane's offset is of their size): 4e-5 of the largest
    /// coordinate is ~300 of them and far below a leaf (1/343 of the scene at (7, 3)).
    static float planeEpsilon(const ls::NTree& tree) {
        if (tree.nodes.empty()) return 0.0f;
        float eps = 0.0f;
        const ls::NodeGpu& root = tree.nodes[0];
        for (int k = 0; k < 3; ++k) eps = std::max({eps, std::abs(root.lo[k]), std::abs(root.lo[k] + root.size[k])});
        return eps * 4e-5f;
    }

    /// The loop caps of the trace (the reasoning is at its loops): a node's DDA visits at most
    /// 3N - 2 cells, one more pass leaves it; a ray walks each node above the last level at most
    /// once, and at most (3N - 2)^l nodes of level l.
    void setLoopCaps(uint64_t longestList) {
        const uint64_t cells = uint64_t(3 * p_.n - 2);
        uint64_t walked = 0, perLevel = 1, geometric = 0;
        for (const ls::NodeGpu& node : tree_.nodes) walked += int(node.level) < p_.d - 1;
        for (int l = 0; l < p_.d - 1; ++l, perLevel *= cells) geometric += perLevel;
        auto clampCap = [](uint64_t v) { return uint32_t(std::clamp<uint64_t>(v, 1, UINT32_MAX)); };
        walkCap_ = clampCap((cells + 1) * std::min(walked, geometric));
        leafWalkCap_ = clampCap((cells + 1) * (1 + longestList));
    }

    ShaderDefines defines(bool classify) const {
        return {{"LS_N", std::to_string(p_.n)},
                {"LS_DEPTH", std::to_string(p_.d)},
                {"LS_CLASSIFY", classify ? "1" : "0"},
                {"LS_BIT_CHUNK_COUNT", std::to_string(bitChunks_)},
                {"LS_START_MODE", std::to_string(int(startMode()))},
                {"LS_LAST_LEAVES", lastLeaves() ? "1" : "0"},
                {"LS_LEAF_SPLIT", std::to_string(leafSplit())},
                {"LS_CULL_TRIANGLES", culledStart() ? "1" : "0"},
                simdProbeDefine(options_),
                statisticsDefine(options_)};
    }

    bool lastLeaves() const { return p_.lastLevel == LineSpaceLastLevel::Leaves; }
    /// The occupancy pool is read by every start region but the paper's, and by last_level leaves.
    bool readsOccupancy() const { return startMode() != ls::StartMode::Node || lastLeaves(); }
    /// Sub-cells per axis of an occupied leaf where occupancy is read at all (1 elsewhere).
    int leafSplit() const { return readsOccupancy() ? p_.leafSplit : 1; }
    /// The exact start region with its triangles culled by their planes.
    bool culledStart() const { return startMode() == ls::StartMode::Exact && p_.startTriangles == LineSpaceStartTriangles::Culled; }

    ls::StartMode startMode() const { return p_.startRegion; }

    /// The start region the shader uses (valid after setScene()); leaf cells from the root's size.
    ls::StartRegion startRegion() const {
        ls::StartRegion r;
        r.mode = startMode();
        r.cells = p_.startCells;
        r.maxCells = p_.startMaxCells;
        if (!tree_.nodes.empty()) {
            const ls::NodeGpu& root = tree_.nodes[0];
            const float leaves = std::pow(float(tree_.n), float(tree_.d));
            r.leafCell = glm::vec3(root.size[0], root.size[1], root.size[2]) / leaves;
        }
        return r;
    }

    /// The trace's buffer-texture views of the pools, one per texture unit from LS_NODE_UNIT on
    /// (layout.glsl); the occupancy pool and the leaf lists only where the start region reads them.
    void makeTexels(bool occupancy, bool exact, bool culled, bool split) {
        static_assert(LS_BITS_UNIT + LS_BIT_CHUNKS == LS_TRI_PLANE_UNIT && LS_LEAF_SUB_UNIT - LS_NODE_UNIT + 1 == kTexelUnits);
        texels_[0] = makeBufferTexture(nodesBuf_, GL_RGBA32UI, 16, "line_space node pool");
        texels_[LS_TREE_UNIT - LS_NODE_UNIT] = makeBufferTexture(treeBuf_, GL_R32UI, 4, "line_space tree pool");
        if (occupancy) texels_[LS_OCC_UNIT - LS_NODE_UNIT] = makeBufferTexture(occBuf_, GL_R32UI, 4, "line_space occupancy pool");
        if (exact || split) texels_[LS_LEAF_RANK_UNIT - LS_NODE_UNIT] = makeBufferTexture(leafBase_, GL_R32UI, 4, "line_space leaf ranks");
        if (split) texels_[LS_LEAF_SUB_UNIT - LS_NODE_UNIT] = makeBufferTexture(leafSub_, GL_RG32UI, 8, "line_space leaf sub-cells");
        if (exact) {
            texels_[LS_LEAF_PREFIX_UNIT - LS_NODE_UNIT] = makeBufferTexture(leafPrefix_, GL_R32UI, 4, "line_space leaf prefixes");
            texels_[LS_LEAF_TRIS_UNIT - LS_NODE_UNIT] = makeBufferTexture(leafTris_, GL_R32UI, 4, "line_space leaf triangles");
        }
        if (culled) texels_[LS_TRI_PLANE_UNIT - LS_NODE_UNIT] = makeBufferTexture(triPlanes_, GL_RGBA32F, 16, "line_space triangle planes");
        for (size_t c = 0; c < LS_BIT_CHUNKS; ++c)
            texels_[LS_BITS_UNIT - LS_NODE_UNIT + c] = makeBufferTexture(bitsBuf_[c], GL_R32UI, 4, "line_space line-space pool");
    }

    void compile() {
        trace_ = ShaderProgram::compute("line_space/trace.comp", defines(false));
        classifyProgram_ = ShaderProgram(); // compiled on first use
    }

    float rayOffset() const { return rayOffsetLength(p_.rayOffset, *scene_); }

    /// The tree from the disk cache when allowed and valid, else built (and cached).
    ls::NTree obtainTree(const Scene& scene, int n, int d, size_t blockLimit, bool useCache) {
        const std::string dir = useCache ? ls::cacheDirectory() : std::string();
        const uint64_t hash = dir.empty() ? 0 : scene.contentHash();
        const std::string path = dir.empty() ? std::string() : ls::cacheFile(dir, hash, n, d);
        return diskcache::loadOrBuild(
            "line_space", path, [&](std::string* why) { return ls::loadCache(path, hash, n, d, why); },
            [&] { return ls::buildNTree(scene, n, d, 0, blockLimit); },
            [&](const ls::NTree& t, std::string* why) { return ls::saveCache(path, hash, t, why); }, &cacheHit_);
    }

    const ls::SampleClasses& classify() const {
        if (!classes_) {
            if (!tracer_) tracer_ = std::make_unique<EmbreeTracer>(posed_.triangleCount() ? posed_ : scene_->cpu());
            std::vector<uint32_t> perPixel = classifyBuf_.read<uint32_t>(
                size_t(pendingG_.width) * size_t(pendingG_.height) * ls::classifyStride(pendingLight_.samplePoints().size()));
            classes_ = ls::classifySamples(*tracer_, pendingG_, pendingLight_, rayOffset(), tree_.nodes, perPixel, startRegion());
        }
        return *classes_;
    }

    /// The timed pass compiles the statistics out: the sample classification (a debug aid) too.
    void instrumentParams() {
        if (!options_.statistics) p_.classify = false;
    }

    LineSpaceParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    Scene posed_; ///< rebuild_every_frame: the scene as last posed (empty until a part moves)
    glm::ivec2 resolution_{0, 0};
    ShaderProgram trace_, classifyProgram_;
    ls::NTree tree_; ///< node pool and statistics (the tree and line-space pools live on the GPU only)
    bool cacheHit_ = false;
    /// Node, tree, line-space pools; (if read) occupancy pool; (exact) leaf lists + scene positions.
    /// A GlBuffer rounds empty ones up to 4 bytes; these are the bytes the shader uses.
    std::array<size_t, 5> poolBytes_{};
    GlBuffer nodesBuf_, treeBuf_, occBuf_, leafBase_, leafPrefix_, leafTris_, triPlanes_, leafSub_, samples_, classifyBuf_;
    bvh::BvhGpu near_; ///< start_region bvh: the near field's tree
    float planeEps_ = 0; ///< culled start region: distances to a triangle's plane within this are too close to call
    GpuCounters<LS_COUNTER_WORDS> counters_;
    std::array<GlBuffer, LS_BIT_CHUNKS> bitsBuf_; ///< the line-space pool, split at node boundaries
    static constexpr size_t kTexelUnits = 12;
    std::array<GlTexture, kTexelUnits> texels_; ///< the pools as buffer textures (makeTexels): how the trace reads them
    size_t nodesPerChunk_ = 1;
    int bitChunks_ = 1; ///< line-space pool blocks the compiled programs read (LS_BIT_CHUNK_COUNT)
    GlTexture nodesVisited_, loopCapped_;
    SampleBatches batches_; ///< the light's samples over dispatches, and their state between them
    uint32_t walkCap_ = 1, leafWalkCap_ = 1; ///< most passes of a ray's walk and of one leaf walk
    // classify: the frame to classify, the exact tracer (built on first use) and the result.
    CpuGBuffer pendingG_;
    Light pendingLight_;
    mutable std::unique_ptr<EmbreeTracer> tracer_;
    mutable std::optional<ls::SampleClasses> classes_;
};

/// An upper bound of the N-tree's pools for `triangles` triangles, without the scene: level l of the
/// tree has k³ cells (k = N^l), of which a triangle, lying in a plane, touches at most 4k² (a plane
/// crosses at most three cells of each column along its normal's largest axis, four with the cells
/// it only touches), and a cell is a node only where a triangle touches it. Every node holds its
/// line space (wordsPerNode words), its occupancy bits, its entry in the node pool and a children
/// group of N³ entries in the tree pool. The build refuses more than LS_BIT_CHUNKS storage blocks of
/// line space and one block of nodes, tree or occupancy (NTreeBuilder), so none can exceed that.
size_t lineSpaceNodeBound(int n, int d, size_t triangles) {
    size_t nodes = 0, k = 1;
    for (int level = 0; level < d; ++level, k = saturatingMul(k, size_t(n))) {
        const size_t cells = saturatingMul(saturatingMul(k, k), k);
        nodes = saturatingSum({nodes, std::min(cells, saturatingMul(saturatingMul(4, saturatingMul(k, k)), std::max<size_t>(triangles, 1)))});
    }
    return nodes;
}

size_t lineSpacePoolBound(int n, int d, size_t triangles, size_t blockBytes) {
    const size_t nodes = lineSpaceNodeBound(n, d, triangles);
    const size_t cube = size_t(n) * size_t(n) * size_t(n);
    size_t bits = saturatingMul(nodes, 4 * ls::wordsPerNode(n));
    size_t nodePool = saturatingMul(nodes, sizeof(ls::NodeGpu)), treePool = saturatingMul(nodes, 4 * cube);
    size_t occupancy = saturatingMul(nodes, 4 * ls::occupancyWords(n));
    if (blockBytes > 0) {
        bits = std::min(bits, saturatingMul(LS_BIT_CHUNKS, blockBytes));
        nodePool = std::min(nodePool, blockBytes);
        treePool = std::min(treePool, blockBytes);
        occupancy = std::min(occupancy, blockBytes);
    }
    return saturatingSum({bits, nodePool, treePool, occupancy});
}

} // namespace

/// Its pools: lineSpacePoolBound (held on the host while they are built, then on the GPU). Besides,
/// what grows with the scene is the exact start region's leaf lists (>= 4 bytes a triangle) and its check that the
/// scene positions fit one storage block (the reported size), as setScene does; with
/// start_triangles culled a plane per triangle (16 bytes), with leaf_split > 1 8 bytes per occupied
/// leaf (at most about one per triangle).
Footprint lineSpaceFootprint(const FootprintQuery& q) {
    Footprint f;
    const LineSpaceParams p = lineSpaceParams().read(*q.params);
    const bool exact = p.startRegion == ls::StartMode::Exact;
    const bool culled = exact && p.startTriangles == LineSpaceStartTriangles::Culled;
    const bool split = p.leafSplit > 1;
    const size_t n = q.triangles;
    // Limits not known yet (the GUI's check before its window; the device's follows before the
    // first frame): the pools capped at the least storage block GL 4.5 allows, so that this early
    // check never refuses what the device's own limits admit (twenty-third probe: planned
    // uncapped, (6, 4) came to 32 GiB where run planned 2.45).
    constexpr size_t kGlMinStorageBlockBytes = size_t(1) << 27;
    const size_t block = q.reportedStorageBlockBytes > 0 ? q.reportedStorageBlockBytes : kGlMinStorageBlockBytes;
    const size_t pools = lineSpacePoolBound(p.n, p.d, n, block);
    // The pools are built on the host and uploaded: both copies are held while setScene() runs.
    f.bytes = saturatingSum({saturatingMul(8 + (culled ? 16 : 0) + (split ? 8 : 0), n), pools});
    f.peakBytes = saturatingSum({pools, saturatingMul(8, n)});
    if (exact) f.refusal = storageRefusal(q, "the scene positions its exact start region reads", saturatingMul(36, n), true);
    if (p.startRegion == ls::StartMode::Bvh) {
        // bvh_raytrace's tree with its default leaves of 4: triangles 48 bytes, nodes ~32 bytes a triangle.
        f.bytes = saturatingSum({f.bytes, saturatingMul(80, n)});
        f.peakBytes = saturatingSum({f.peakBytes, saturatingMul(152, n)});
        f.refusal = storageRefusal(q, "the near field's leaf-ordered triangles", saturatingMul(48, n), true);
    }
    return f;
}
/// The tree's shape for this scene (nodes, tree and occupancy, no line spaces) against the same
/// limits build() checks, and with start_region exact the leaf lists' triangles: a parameter set the
/// build would refuse is refused here, in the time of its occupancy tests.
std::string lineSpaceSceneCheck(const Scene& scene, const ParamValues& params) {
    const LineSpaceParams p = lineSpaceParams().read(params);
    const size_t limit = poolBlockLimit(p.maxBlockMib);
    const int n = p.n, d = p.d;
    const bool exact = p.startRegion == ls::StartMode::Exact;
    // Where even the bound of the tree's nodes fits every pool (the build's checks), no tree can fail
    // them: the shape is built only for the leaf lists, or when the bound does not fit.
    const size_t nodes = lineSpaceNodeBound(n, d, scene.triangleCount());
    const size_t cube = size_t(n) * size_t(n) * size_t(n);
    const bool boundFits = nodes <= ls::nodesPerChunk(n, limit) * LS_BIT_CHUNKS && saturatingMul(nodes, sizeof(ls::NodeGpu)) <= limit &&
                           saturatingMul(nodes, 4 * ls::occupancyWords(n)) <= limit && saturatingMul(nodes, 4 * cube) <= limit;
    if (boundFits && !exact) return "";
    try {
        const ls::NTree shape = ls::buildNTree(scene, n, d, 0, limit, true);
        if (!exact) return "";
        const size_t listBytes = ls::buildLeafLists(scene, shape).tris.size() * sizeof(uint32_t);
        if (listBytes > limit)
            return "the leaf triangle lists of start_region exact need " + std::to_string((listBytes + (1u << 20) - 1) >> 20) +
                   " MiB; one storage block may hold " + std::to_string(limit >> 20) + " MiB here";
    } catch (const SceneRefusal& e) {
        return e.what();
    }
    return "";
}

AlgorithmInfo lineSpaceInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<LineSpace>(
        "line_space", "approximate shadows from precomputed line-space visibility in an N-tree (no triangle tests)",
        {LightType::Point, LightType::Spot, LightType::Directional, LightType::Area}, false, &lineSpaceSchema);
    info.motion = MotionHandling::StaticOnly;
    info.rebuildParam = "rebuild_every_frame";
    info.footprint = &lineSpaceFootprint;
    info.sceneCheck = &lineSpaceSceneCheck;
    return info;
}

} // namespace shadowlab
