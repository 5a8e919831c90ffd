#include "algorithms/metric_tree/MetricTree.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/SharedParams.h"
#include "algorithms/metric_tree/ClusterCache.h"
#include "algorithms/metric_tree/Clustering.h"
#include "algorithms/metric_tree/CpuTree.h"
#include "algorithms/metric_tree/MetricTreeGpuLayout.h"
#include "algorithms/metric_tree/MetricTreeMath.h"
#include "framework/core/CheckedMath.h"
#include "framework/core/DiskCache.h"
#include "framework/core/Error.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

namespace shadowlab {
namespace {

enum class MtTreeBuilder { Gpu, Cpu };
enum class MtQuery { Pixel, Tile };
/// A tile's shape; the value is its pixels (MT_TILE_PIXELS), 0 for auto.
enum class MtTile { Auto = 0, T4x2 = 8, T8x2 = 16, T8x4 = 32, T8x8 = 64 };
const std::vector<Choice<MtTile>> kMtTiles = {
    {"auto", MtTile::Auto}, {"4x2", MtTile::T4x2}, {"8x2", MtTile::T8x2}, {"8x4", MtTile::T8x4}, {"8x8", MtTile::T8x8}};
enum class MtMotion { Rigid, Recluster };

struct MetricTreeParams {
    int clusterSize, chunkTriangles, kmeansIterations; ///< the clustering (cached on disk)
    bool capsules, randomOrder, cache;
    int seed;
    bool slabs, overlapInterval, depthSkip, normalConeCulling; ///< the query's tests (shader defines)
    MtTreeBuilder treeBuilder;
    int stackSize;                                             ///< query stack, nodes
    MtQuery query;
    int tileCandidates;                                        ///< tile query: clusters per tile list
    MtTile tile;                                               ///< tile query's shape
    float rayOffset;                                           ///< × scene radius
    MtMotion motion;
    int geometryBlock;                                         ///< triangles per geometry block, 0 = the device's largest
};

const ParamStruct<MetricTreeParams>& metricTreeParams() {
    using P = MetricTreeParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        .integer("cluster_size", &P::clusterSize, 16, 2, 64, "triangles",
                 "most triangles per cluster (paper: 16 to 32); fewer clusters build faster, more triangles are tested",
                 ParamChange::Rebuild)
        .integer("chunk_triangles", &P::chunkTriangles, 512, 16, 65536, "triangles",
                 "triangles per Morton-curve chunk clustered independently by k-means (paper: 512)", ParamChange::Rebuild)
        .integer("kmeans_iterations", &P::kmeansIterations, 8, 1, 100, "iterations", "Lloyd iterations of each k-means split",
                 ParamChange::Rebuild)
        .boolean("capsules", &P::capsules, true,
                 "bound elongated clusters (OBB longest extent >= 2x the others) by capsules, else spheres only",
                 ParamChange::Rebuild)
        .boolean("slabs", &P::slabs, true,
                 "test the shadow ray against a cluster's two slabs before its triangles (paper step 2)",
                 ParamChange::Recompile)
        .boolean("overlap_interval", &P::overlapInterval, true,
                 "visit an overlap child only when the point's distance is inside its [min, max] (paper step 3)",
                 ParamChange::Recompile)
        .boolean("depth_skip", &P::depthSkip, true,
                 "skip a subtree whose geometry is all farther from the light than the point (paper step 1)",
                 ParamChange::Recompile)
        // Off by default: exact for closed meshes only (an open mesh would leak light through its back).
        .boolean("normal_cone_culling", &P::normalConeCulling, false,
                 "drop clusters whose normal cone faces the light (paper 5.3); exact for closed meshes only",
                 ParamChange::Recompile)
        .boolean("random_order", &P::randomOrder, true,
                 "insert the clusters in a seeded shuffled order (pivots spread over the scene) instead of Morton order",
                 ParamChange::Rebuild)
        .integer("seed", &P::seed, 1, 0, INT_MAX, "", "seed of the k-means seeding and of the insertion order",
                 ParamChange::Rebuild)
        .choice("tree_builder", &P::treeBuilder, MtTreeBuilder::Gpu, {{"gpu", MtTreeBuilder::Gpu}, {"cpu", MtTreeBuilder::Cpu}},
                "gpu: concurrent insertion with the delta-halving heuristic (paper 5.3); cpu: median partitioning "
                "with Yianilos pivots (the paper's Table 2 reference, slow)",
                ParamChange::Update)
        .apply(stackSizeRow(&P::stackSize, 64))
        .choice("query", &P::query, MtQuery::Tile, {{"pixel", MtQuery::Pixel}, {"tile", MtQuery::Tile}},
                "pixel: every pixel walks the tree (paper 5.4); tile: a tile of pixels walks it once with the cap "
                "enclosing its points, and each pixel tests the clusters the walk gathered with the per-pixel "
                "query's own tests (the same image; no divergent walk)",
                ParamChange::Recompile)
        .choice("tile", &P::tile, MtTile::Auto, kMtTiles,
                "tile query: the pixels that share one walk; auto = the tile whose walkers (one invocation per tile) "
                "fill one subgroup: 8x2 on 4 lanes, else 4x2 (8 walkers)",
                ParamChange::Recompile)
        .integer("tile_candidates", &P::tileCandidates, 512, 16, 512, "clusters",
                 "tile query: most clusters one tile's list holds; a tile that gathers more falls back to the "
                 "per-pixel query (counter tile_fallbacks)",
                 ParamChange::Recompile)
        .apply(cacheRow(&P::cache, "metric_tree"))
        .apply(rayOffsetRow(&P::rayOffset))
        // The paper's answer to rigid motion: clusters never span two moving parts, and each moves
        // with its part; "recluster" is the alternative it avoids, timed for comparison.
        .choice("motion", &P::motion, MtMotion::Rigid, {{"rigid", MtMotion::Rigid}, {"recluster", MtMotion::Recluster}},
                "moving parts: rigid = clusters are made per part (never spanning two) and their spheres, capsules, "
                "cones and slabs move with it each frame; recluster = the whole clustering is redone on the posed "
                "triangles every frame they move (the `recluster` stage)",
                ParamChange::Rebuild)
        // 0 by default: the fewer blocks, the fewer arms in the query's load (a SIMD back end runs
        // every arm). Smaller values exist to test the split (MetricTreeGLTest) and for devices
        // whose limits lie.
        .integer("geometry_block", &P::geometryBlock, 0, 0, INT_MAX, "triangles",
                 "triangles per block of the cluster-ordered geometry copy (at most 6 blocks); 0 = the largest the "
                 "device allows (a buffer-texture view's texels / 3, or one storage block's for rigid motion)",
                 ParamChange::Rebuild);
    return s;
}

const ParamSchema& metricTreeSchema() { return metricTreeParams().schema(); }

constexpr GLuint kGroup = 64;        ///< local_size_x of prepare.comp and insert.comp
/// Light-space margin of a point light, in radians: above the ~1e-7 rad rounding of the angles and
/// the up to 5e-5 rad error of a short arc's great circle (see prepare.comp).
constexpr float kAngularEps = 1e-4f;

class MetricTree final : public ShadowAlgorithm {
public:
    MetricTree(const ParamValues& p, const AlgorithmOptions& o) : p_(metricTreeParams().read(p)), options_(o) {
        subgroupSize_ = querySubgroupSize();
        compile();
    }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        const size_t n = scene.triangleCount();
        const size_t block = blockTriangles(scene);
        if (n > size_t(MT_GEOMETRY_CHUNKS) * block)
            throw RuntimeError("metric_tree: " + std::to_string(n) + " triangles exceed the " +
                               std::to_string(size_t(MT_GEOMETRY_CHUNKS) * block) + " its " +
                               std::to_string(MT_GEOMETRY_CHUNKS) + " geometry blocks of " + std::to_string(block) +
                               " triangles hold on this device");
        if (block != blockTriangles_) {
            blockTriangles_ = block;
            poseClusters_ = ShaderProgram(), poseGeometry_ = ShaderProgram();
            compile();
        }
        clusters_ = GlBuffer(), nodes_ = GlBuffer();
        for (GlBuffer& g : geometry_) g = GlBuffer();
        // A moving scene: clusters per part in the part's own space, posed each frame (sceneMoved).
        if (!scene.dynamic() || p_.motion != MtMotion::Rigid) {
            upload(cluster(scene.cpu(), p_.cache), scene.cpu());
            return;
        }
        PartClustering pc = clusterByPart(scene.cpu());
        upload(pc.clustering, scene.cpu());
        restClusters_ = GlBuffer::fromVector(pc.clustering.clusters, 0);
        clusterPart_ = GlBuffer::fromVector(pc.parts, 0);
        order_ = GlBuffer::fromVector(pc.clustering.order, 0);
        movingFirst_ = pc.staticTriangles;
        movingClusterFirst_ = pc.staticClusters;
        if (!poseClusters_) {  // only the block size changes their code: compiled again with it, for moving scenes only
            const std::pair<std::string, std::string> block{"MT_TRIANGLES_PER_CHUNK", std::to_string(blockTriangles_)};
            poseClusters_ = ShaderProgram::compute("metric_tree/pose.comp", {{"MT_POSE_CLUSTERS", "1"}, block});
            poseGeometry_ = ShaderProgram::compute("metric_tree/pose.comp", {{"MT_POSE_CLUSTERS", "0"}, block});
        }
    }

    void sceneMoved(const FrameInputs& f) override {
        if (p_.motion == MtMotion::Recluster) {
            f.timer.begin("recluster", false);
            const Scene posed = scene_->posedScene();
            upload(cluster(posed, false), posed);  // no cache: a pose is never seen twice
            f.timer.end();
            return;
        }
        // Rigid: the rest clusters of moving parts through their part's matrix, and the posed
        // triangles (the scene's own floats) gathered into cluster order.
        f.timer.begin("move_clusters");
        restClusters_.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
        clusterPart_.bindBase(GL_SHADER_STORAGE_BUFFER, 2);
        clusters_.bindBase(GL_SHADER_STORAGE_BUFFER, MT_CLUSTER_BINDING);
        scene_->partTransforms().bindBase(GL_SHADER_STORAGE_BUFFER, 4);
        poseClusters_.set("uFirst", unsigned(movingClusterFirst_));
        poseClusters_.set("uCount", unsigned(clusterCount_ - movingClusterFirst_));
        poseClusters_.dispatchLinear(clusterCount_ - movingClusterFirst_, kGroup);
        scene_->positions().bindBase(GL_SHADER_STORAGE_BUFFER, 0);
        order_.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
        bindGeometry();
        const size_t moving = scene_->triangleCount() - movingFirst_;
        poseGeometry_.set("uFirst", unsigned(movingFirst_));
        poseGeometry_.set("uCount", unsigned(moving));
        poseGeometry_.dispatchLinear(moving, kGroup);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT); // the query fetches them
        f.timer.end();
    }

    /// Clusters (GPU) and the triangles in cluster order, split over the geometry blocks.
    void upload(const mt::Clustering& c, const Scene& s) {
        const size_t n = s.triangleCount();
        clusterCount_ = c.clusters.size();
        capsuleCount_ = c.capsules;
        clusters_ = GlBuffer::fromVector(c.clusters, 0);
        nodes_ = GlBuffer(std::max<size_t>(1, clusterCount_) * MT_NODE_BYTES, nullptr, GL_DYNAMIC_STORAGE_BIT);
        counters_.allocate();
        // The triangles in cluster order, split over blocks of at most blockTriangles_, each filled
        // in slices so that no second copy of a block exists on the host.
        geometryBytes_ = 0;
        for (GlBuffer& g : geometry_) g = GlBuffer();
        constexpr size_t kSlice = 1 << 20;
        std::vector<float> v;
        for (size_t chunk = 0; chunk * blockTriangles_ < n; ++chunk) {
            const size_t begin = chunk * blockTriangles_, end = std::min(n, begin + blockTriangles_);
            geometry_[chunk] = GlBuffer(9 * sizeof(float) * (end - begin), nullptr, GL_DYNAMIC_STORAGE_BIT);
            for (size_t from = begin; from < end; from += kSlice) {
                const size_t to = std::min(end, from + kSlice);
                v.clear();
                for (size_t i = from; i < to; ++i)
                    for (int k = 0; k < 3; ++k) {
                        const glm::vec3 p = s.positions[3 * size_t(c.order[i]) + k];
                        v.insert(v.end(), {p.x, p.y, p.z});
                    }
                geometry_[chunk].upload(v.data(), v.size() * sizeof(float), 9 * sizeof(float) * (from - begin));
            }
            geometryBytes_ += geometry_[chunk].size();
        }
        if (!geometry_[0]) geometry_[0] = GlBuffer(36, nullptr, 0); // an empty scene still binds its blocks
        nodeTexels_ = makeBufferTexture(nodes_, GL_RGBA32UI, 16, "metric_tree nodes");
        clusterTexels_ = makeBufferTexture(clusters_, GL_RGBA32UI, 16, "metric_tree clusters");
        for (int i = 0; i < MT_GEOMETRY_CHUNKS; ++i)
            geometryTexels_[i] = geometry_[i] ? makeBufferTexture(geometry_[i], GL_RGB32F, 12, "metric_tree geometry") : GlTexture();
        // The query reads the blocks that hold triangles only (a #define): recompiled when that changes.
        const int used = int(std::max<size_t>(1, (n + blockTriangles_ - 1) / blockTriangles_));
        if (used != geometryUsed_) {
            geometryUsed_ = used;
            compile();
        }
    }

    void resize(glm::ivec2 resolution) override {
        if (!options_.statistics) return; // the timed pass: no debug images
        nodesVisited_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
        triangleTests_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
        fruitless_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
        overflow_ = makeTexture2D(GL_R32F, resolution.x, resolution.y);
    }

    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = metricTreeParams().read(p);
        if (change == ParamChange::Recompile) compile();  // a Rebuild (the clustering) is followed by setScene()
    }

    void computeVisibility(const FrameInputs& f) override {
        setUniforms(f.light);
        bind();

        f.timer.begin("build");
        counters_.clear(); // also empties the tree: its root pointer is counter word 0
        if (clusterCount_ > 0) {
            dispatchPerCluster(prepare_);
            // The insertion and the query read the nodes through their buffer texture.
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
            if (p_.treeBuilder == MtTreeBuilder::Cpu) {
                buildOnCpu(f.light);
            } else {
                dispatchPerCluster(insert_);
                glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
            }
        }
        f.timer.end();

        f.timer.begin("traverse");
        if (options_.statistics) runPixelPass(f, query_, {&nodesVisited_, &triangleTests_, &fruitless_, &overflow_});
        else runPixelPass(f, query_, {});
        f.timer.end();
        counters_.markStale();
    }

    std::vector<Counter> counters() const override {
        const auto& c = counters_.read();
        auto wide = [&](size_t lo) { return double(counters_.wide(lo)); };
        const double px = c[MT_C_TRAVERSED];
        auto perPixel = [&](int lo) { return px > 0 ? wide(lo) / px : 0.0; };
        const double n = double(clusterCount_);
        if (!options_.statistics) // the timed pass: the structure's size and what is still measured
            return {{"clusters", n},
                    {"build_errors", double(c[MT_C_BUILD_ERRORS])},
                    {"stack_overflow_pixels", double(c[MT_C_STACK_OVERFLOW])},
                    {"loop_capped_pixels", double(c[MT_C_LOOP_CAPPED])},
                    {"tile_pixels", tileQueryPixels()},
                    {"tile_fallbacks", double(c[MT_C_TILE_FALLBACKS])},
                    {"cache_hit", cacheHit_ ? 1.0 : 0.0},
                    {"clustering_ms", clusteringMs_},
                    {"cache_read_ms", cacheReadMs_},
                    {"cache_write_ms", cacheWriteMs_},
                    {"geometry_bytes", double(geometryBytes_)},
                    {"geometry_blocks", double(geometryUsed_)}};
        return {{"clusters", n},
                {"capsule_percent", n > 0 ? 100.0 * double(capsuleCount_) / n : 0.0},
                {"triangles_per_cluster", n > 0 ? double(scene_->triangleCount()) / n : 0.0},
                {"bytes_per_cluster", n > 0 ? double(mt::structureBytes(clusterCount_)) / n : 0.0},
                {"geometry_bytes", double(geometryBytes_)},
                {"geometry_blocks", double(geometryUsed_)},
                {"cache_read_ms", cacheReadMs_},
                {"cache_write_ms", cacheWriteMs_},
                {"clusters_inserted", double(c[MT_C_INSERTED])},
                {"clusters_culled", double(c[MT_C_CULLED])},
                {"insert_depth_max", double(c[MT_C_INSERT_DEPTH_MAX])},
                {"build_errors", double(c[MT_C_BUILD_ERRORS])},
                {"traversed_pixels", px},
                {"nodes_visited_mean", perPixel(MT_C_VISITED_LO)},
                {"nodes_visited_max", double(c[MT_C_VISITED_MAX])},
                {"triangle_tests_mean", perPixel(MT_C_TRIANGLES_LO)},
                {"triangle_tests_max", double(c[MT_C_TRIANGLES_MAX])},
                {"fruitless_clusters_mean", perPixel(MT_C_FRUITLESS_LO)},
                {"fruitless_clusters_max", double(c[MT_C_FRUITLESS_MAX])},
                {"cone_hits_mean", perPixel(MT_C_CONE_HITS_LO)},
                {"slab_rejects_mean", perPixel(MT_C_SLAB_REJECTS_LO)},
                {"depth_skips_mean", perPixel(MT_C_DEPTH_SKIPS_LO)},
                {"tile_pixels", tileQueryPixels()},
                {"tile_nodes_per_pixel", perPixel(MT_C_TILE_NODES_LO)},
                {"tile_fallbacks", double(c[MT_C_TILE_FALLBACKS])},
                {"stack_overflow_pixels", double(c[MT_C_STACK_OVERFLOW])},
                {"loop_capped_pixels", double(c[MT_C_LOOP_CAPPED])},
                {"cache_hit", cacheHit_ ? 1.0 : 0.0},
                {"clustering_ms", clusteringMs_}};
    }

    std::vector<DebugView> debugViews() const override {
        if (!options_.statistics) return {};
        return {{"nodes_visited", nodesVisited_.id(), 0.0f, "nodes"},
                {"triangle_tests", triangleTests_.id(), 0.0f, "triangles"},
                {"fruitless_clusters", fruitless_.id(), 0.0f, "clusters"},
                {"stack_overflow", overflow_.id(), 1.0f, "flag"}};
    }

    /// Clusters and nodes (64 bytes each: 128 per cluster, the paper's figure) plus the 128-byte
    /// counter block. Not counted, as in the paper: the triangles themselves, which metric_tree
    /// keeps in cluster order (counter geometry_bytes), and the per-pixel debug images.
    size_t memoryBytes() const override { return mt::structureBytes(clusterCount_) + counters_.size(); }
    size_t residentBytes() const override {
        return memoryBytes() + geometryBytes_ + restClusters_.size() + clusterPart_.size() + order_.size();
    }

    /// Pixels whose query stack overflowed or whose loops were cut (both written shadowed) plus
    /// build errors (must be 0).
    uint64_t overflowCount() const override {
        const auto& c = counters_.read();
        return uint64_t(c[MT_C_STACK_OVERFLOW]) + c[MT_C_LOOP_CAPPED] + c[MT_C_BUILD_ERRORS];
    }

    /// The tile shape tilePixels() gives on this device (used by the tile query).
    std::vector<std::pair<std::string, std::string>> resolvedParams() const override {
        return {{"tile", choiceName(kMtTiles, MtTile(tilePixels()))}};
    }

private:
    void compile() {
        auto flag = [](bool on) { return on ? std::string("1") : std::string("0"); };
        const ShaderDefines defines = {{"MT_SLABS", flag(p_.slabs)},
                                       {"MT_OVERLAP_INTERVAL", flag(p_.overlapInterval)},
                                       {"MT_DEPTH_SKIP", flag(p_.depthSkip)},
                                       {"MT_NORMAL_CONE_CULLING", flag(p_.normalConeCulling)},
                                       {"MT_STACK_SIZE", std::to_string(p_.stackSize)},
                                       {"MT_QUERY_TILE", flag(p_.query == MtQuery::Tile)},
                                       {"MT_TILE_CANDIDATES", std::to_string(p_.tileCandidates)},
                                       {"MT_TILE_PIXELS", std::to_string(tilePixels())},
                                       {"MT_GEOMETRY_USED", std::to_string(geometryUsed_)},
                                       {"MT_TRIANGLES_PER_CHUNK", std::to_string(blockTriangles_)},
                                       statisticsDefine(options_)};
        prepare_ = ShaderProgram::compute("metric_tree/prepare.comp", defines);
        insert_ = ShaderProgram::compute("metric_tree/insert.comp", defines);
        query_ = ShaderProgram::compute("metric_tree/query.comp", defines);
    }

    /// Triangles per geometry block for `scene`: the parameter, else the largest block this device
    /// lets the passes that touch it address. Rigid motion writes the blocks as storage blocks.
    size_t blockTriangles(const SceneGpu& scene) const {
        if (p_.geometryBlock > 0) return size_t(p_.geometryBlock);
        const bool written = scene.dynamic() && p_.motion == MtMotion::Rigid;
        // A multiple of 16 triangles keeps every block's byte offset 16-byte aligned.
        const size_t block = written ? maxShaderStorageBlockBytes() / (9 * sizeof(float)) : maxTextureBufferTexels() / 3;
        return std::max<size_t>(16, block / 16 * 16);
    }

    /// Pixels per tile of the tile query: "WxH" -> W * H; auto -> autoTilePixels().
    int tilePixels() const {
        if (p_.tile != MtTile::Auto) return int(p_.tile);
        return autoTilePixels(subgroupSize_);
    }
    /// The counter tile_pixels: pixels per tile, 0 with the per-pixel query.
    double tileQueryPixels() const { return p_.query == MtQuery::Tile ? double(tilePixels()) : 0.0; }

    mt::ClusteringOptions clusteringOptions() const {
        mt::ClusteringOptions o;
        o.clusterSize = p_.clusterSize;
        o.chunkTriangles = p_.chunkTriangles;
        o.kmeansIterations = p_.kmeansIterations;
        o.capsules = p_.capsules;
        o.randomOrder = p_.randomOrder;
        o.seed = uint32_t(p_.seed);
        return o;
    }

    /// The clustering from the disk cache when `useCache` and valid, else computed (and cached).
    mt::Clustering cluster(const Scene& scene, bool useCache) {
        const auto start = std::chrono::steady_clock::now();
        const mt::ClusteringOptions o = clusteringOptions();
        const std::string dir = useCache ? mt::cacheDirectory() : std::string();
        const uint64_t hash = dir.empty() ? 0 : scene.contentHash();
        const std::string path = dir.empty() ? std::string() : mt::cacheFile(dir, hash, o);
        const size_t n = scene.triangleCount();
        // Each step timed on its own: at tens of millions of triangles the cache's write and read
        // are results of their own (counters cache_read_ms, cache_write_ms).
        auto timed = [](double& ms, auto&& step) {
            const auto t0 = std::chrono::steady_clock::now();
            auto result = step();
            ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            return result;
        };
        cacheReadMs_ = cacheWriteMs_ = 0;
        mt::Clustering c = diskcache::loadOrBuild(
            "metric_tree", path,
            [&](std::string* why) { return timed(cacheReadMs_, [&] { return mt::loadCache(path, hash, o, scene, why); }); },
            [&] { return mt::clusterScene(scene, o); },
            [&](const mt::Clustering& value, std::string* why) {
                return timed(cacheWriteMs_, [&] { return mt::saveCache(path, hash, o, n, value, why); });
            },
            &cacheHit_);
        clusteringMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return c;
    }

    /// A clustering of a moving scene, and for each cluster its part (kStaticPart for static ones).
    struct PartClustering {
        mt::Clustering clustering;
        std::vector<uint32_t> parts;
        size_t staticTriangles = 0, staticClusters = 0; ///< the moving ones follow (in cluster order)
    };

    /// Clusters that never span two parts: the static triangles (world space) first, then each
    /// moving part in its own space; `first` and `order` refer to the whole scene. Not cached: the
    /// cache's validation checks clusters against world positions.
    PartClustering clusterByPart(const Scene& scene) {
        const auto start = std::chrono::steady_clock::now();
        mt::ClusteringOptions o = clusteringOptions();
        o.randomOrder = false; // shuffled once below, over all groups
        PartClustering out;
        mt::Clustering& all = out.clustering;
        std::vector<uint32_t>& parts = out.parts;
        auto addGroup = [&](const std::vector<uint32_t>& triangles, const glm::vec3* local, uint32_t part) {
            if (triangles.empty()) return;
            Scene g;
            g.materials = {Material{}};
            for (size_t i = 0; i < triangles.size(); ++i) {
                const glm::vec3* v = local ? local + 3 * i : &scene.positions[3 * size_t(triangles[i])];
                g.positions.insert(g.positions.end(), {v[0], v[1], v[2]});
                const glm::vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
                g.normals.push_back(glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0, 1, 0));
                g.materialIds.push_back(0);
            }
            g.updateBounds();
            mt::Clustering c = mt::clusterScene(g, o);
            const uint32_t base = uint32_t(all.order.size());
            for (mt::ClusterGpu cl : c.clusters) {
                cl.first += base;
                all.clusters.push_back(cl);
                parts.push_back(part);
            }
            for (uint32_t t : c.order) all.order.push_back(triangles[t]);
            all.capsules += c.capsules;
        };
        std::vector<uint32_t> statics;
        for (auto [from, to] : scene.staticRuns())
            for (size_t t = from; t < to; ++t) statics.push_back(uint32_t(t));
        addGroup(statics, nullptr, kStaticPart);
        out.staticTriangles = statics.size();
        out.staticClusters = all.clusters.size();
        for (uint32_t p = 0; p < scene.moving.size(); ++p) {
            const MovingPart& part = scene.moving[p];
            std::vector<uint32_t> triangles(part.triangleCount);
            std::iota(triangles.begin(), triangles.end(), uint32_t(part.firstTriangle));
            addGroup(triangles, part.local.data(), p);
        }
        // Insertion (pivot) order spread over the scene, as random_order does for a static one; the
        // moving clusters stay last so one dispatch poses them (the shuffle is within each half).
        if (p_.randomOrder) {
            std::mt19937 rng(uint32_t(p_.seed));
            auto shuffleRange = [&](size_t b, size_t e) {
                for (size_t i = e; i > b + 1; --i) {
                    const size_t j = b + size_t(rng() % (i - b));
                    std::swap(all.clusters[i - 1], all.clusters[j]);
                    std::swap(parts[i - 1], parts[j]);
                }
            };
            shuffleRange(0, out.staticClusters);
            shuffleRange(out.staticClusters, all.clusters.size());
        }
        cacheHit_ = false;
        clusteringMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return out;
    }

    void bindGeometry() const {
        for (int i = 0; i < MT_GEOMETRY_CHUNKS; ++i) // unused blocks alias chunk 0: never read, but bound
            (geometry_[i] ? geometry_[i] : geometry_[0]).bindBase(GL_SHADER_STORAGE_BUFFER, MT_GEOMETRY_BINDING_0 + i);
    }

    void bind() const {
        clusters_.bindBase(GL_SHADER_STORAGE_BUFFER, MT_CLUSTER_BINDING);
        nodes_.bindBase(GL_SHADER_STORAGE_BUFFER, MT_NODE_BINDING);
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, MT_COUNTER_BINDING);
        bindGeometry();
        // The views the insertion (nodes) and the query (nodes, clusters, geometry) fetch through.
        glBindTextureUnit(MT_NODE_UNIT, nodeTexels_.id());
        glBindTextureUnit(MT_CLUSTER_UNIT, clusterTexels_.id());
        for (int i = 0; i < MT_GEOMETRY_CHUNKS; ++i) // unused blocks alias chunk 0: never read, but bound
            glBindTextureUnit(MT_GEOMETRY_UNIT_0 + i, (geometryTexels_[i] ? geometryTexels_[i] : geometryTexels_[0]).id());
    }

    void setUniforms(const Light& light) {
        const Bounds& b = scene_->bounds();
        const float radius = b.empty() ? 1.0f : b.radius();
        const glm::vec3 centre = b.empty() ? glm::vec3(0.0f) : b.center();
        const bool directional = light.type == LightType::Directional;
        // Rounding grows with the coordinates' magnitude (and the light's); 4e-6 of it is far above
        // float error and only widens bounds by that much.
        float magnitude = glm::length(centre) + radius;
        if (!directional) magnitude = std::max(magnitude, glm::length(light.position));
        const float tolerance = 4e-6f * magnitude;
        lsEps_ = directional ? tolerance : kAngularEps;
        const glm::vec3 d = light.direction();
        const glm::vec3 helper = std::abs(d.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
        const glm::vec3 u = glm::normalize(glm::cross(d, helper)), v = glm::cross(d, u);
        // The initial partitioning distance: the scene's bounding sphere seen from the light.
        float delta0 = radius;
        if (!directional) {
            const float dist = glm::length(centre - light.position);
            delta0 = radius < 0.999f * dist ? std::asin(radius / dist) : 0.5f * mt::kPi;
        }
        const glm::vec3 depthOrigin = centre - d * (2.0f * radius);
        const unsigned n = unsigned(clusterCount_);
        for (const ShaderProgram* p : {&prepare_, &insert_, &query_}) {
            setLightUniforms(*p, light);
            p->set("uClusterCount", n);
            p->set("uLsEps", lsEps_);
            p->set("uLightU", u);
            p->set("uLightV", v);
            p->set("uDepthOrigin", depthOrigin);
        }
        prepare_.set("uDepthTolerance", tolerance);
        insert_.set("uDelta0", delta0);
        query_.set("uRayOffset", rayOffsetLength(p_.rayOffset, *scene_));
        query_.set("uSlabTolerance", tolerance);
    }

    /// One invocation per cluster, as a 2D grid when the clusters need more than 65535 groups.
    void dispatchPerCluster(const ShaderProgram& p) const { p.dispatchLinear(clusterCount_, kGroup); }

    /// The Table 2 reference: the nodes prepare.comp wrote, linked on the CPU, uploaded back.
    void buildOnCpu(const Light& light) {
        std::vector<mt::NodeGpu> nodes = nodes_.read<mt::NodeGpu>(clusterCount_);
        mt::CpuTreeOptions o;
        o.directional = light.type == LightType::Directional;
        o.lsEps = lsEps_;
        o.overlapInterval = p_.overlapInterval;
        o.depthSkip = p_.depthSkip;
        const uint32_t root = mt::buildCpuTree(nodes, o);
        uint32_t inserted = 0, culled = 0;
        for (const mt::NodeGpu& nd : nodes) (nd.flags & MT_NODE_CULLED ? culled : inserted) += 1;
        nodes_.upload(nodes.data(), nodes.size() * sizeof(mt::NodeGpu));
        const uint32_t head[3] = {root, inserted, culled}; // MT_C_ROOT, MT_C_INSERTED, MT_C_CULLED
        static_assert(MT_C_ROOT == 0 && MT_C_INSERTED == 1 && MT_C_CULLED == 2);
        counters_.upload(head, sizeof head);
    }

    MetricTreeParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    ShaderProgram prepare_, insert_, query_, poseClusters_, poseGeometry_;
    GlBuffer clusters_, nodes_;
    // Rigid motion: rest-pose clusters, each cluster's part, the cluster order of the triangles;
    // the static clusters and triangles come first, moving ones from these indices on.
    static constexpr uint32_t kStaticPart = 0xFFFFFFFFu;
    GlBuffer restClusters_, clusterPart_, order_;
    size_t movingFirst_ = 0, movingClusterFirst_ = 0;
    GpuCounters<MT_COUNTER_WORDS> counters_;
    std::array<GlBuffer, MT_GEOMETRY_CHUNKS> geometry_;
    GlTexture nodeTexels_, clusterTexels_; ///< the query's views of nodes_ and clusters_
    std::array<GlTexture, MT_GEOMETRY_CHUNKS> geometryTexels_;
    GlTexture nodesVisited_, triangleTests_, fruitless_, overflow_;
    size_t clusterCount_ = 0, capsuleCount_ = 0, geometryBytes_ = 0;
    int geometryUsed_ = 1; ///< geometry blocks holding triangles (MT_GEOMETRY_USED)
    size_t blockTriangles_ = MT_TRIANGLES_PER_CHUNK; ///< triangles per geometry block (MT_TRIANGLES_PER_CHUNK)
    int subgroupSize_ = 0; ///< the context's subgroup width (0: unknown), for tile = auto
    float lsEps_ = kAngularEps;
    bool cacheHit_ = false;
    double clusteringMs_ = 0, cacheReadMs_ = 0, cacheWriteMs_ = 0;
};

} // namespace

int autoTilePixels(int subgroupWidth) {
    if (subgroupWidth <= 0) return 8; // no ballot: the width is unknown; the tile llvmpipe measured best
    return std::clamp(64 / subgroupWidth, 8, 64);
}

/// 36 bytes a triangle of cluster-ordered geometry, 128 a cluster (at most 2 n / cluster_size + 1:
/// the demo averages 9.9 triangles a cluster at 16), 16 a pixel of debug images; while the
/// clustering runs, ~20 bytes a triangle (Clustering.cpp) and one upload slice.
Footprint metricTreeFootprint(const FootprintQuery& q) {
    const MetricTreeParams p = metricTreeParams().read(*q.params);
    const size_t n = q.triangles, pixels = size_t(q.resolution.x) * size_t(q.resolution.y);
    const size_t clusters = std::min(n, saturatingMul(2, n) / size_t(p.clusterSize) + 1);
    const bool rigid = q.moving && p.motion == MtMotion::Rigid;
    Footprint f;
    f.bytes = saturatingSum({saturatingMul(36, n), saturatingMul(128, clusters), 16 * pixels,
                             rigid ? saturatingSum({saturatingMul(68, clusters), saturatingMul(4, n)}) : 0});
    f.peakBytes = saturatingSum({saturatingMul(24, n), 36 * (size_t(1) << 20)});
    size_t block = p.geometryBlock > 0 ? size_t(p.geometryBlock)
                   : rigid            ? q.reportedStorageBlockBytes / 36 / 16 * 16
                                      : q.textureBufferTexels / 3 / 16 * 16;
    if (block > 0 && n > saturatingMul(MT_GEOMETRY_CHUNKS, block))
        f.refusal = "its " + std::to_string(MT_GEOMETRY_CHUNKS) + " geometry blocks of " + std::to_string(block) +
                    " triangles hold " + std::to_string(MT_GEOMETRY_CHUNKS * block);
    if (f.refusal.empty()) f.refusal = storageRefusal(q, "its clusters and nodes", saturatingMul(64, clusters));
    return f;
}

AlgorithmInfo metricTreeInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<MetricTree>("metric_tree",
                                    "clusters bounded by spheres/capsules in a per-frame ternary metric tree (compute), per-pixel query",
                                    {LightType::Point, LightType::Spot, LightType::Directional}, true, &metricTreeSchema);
    info.motion = MotionHandling::Rigid;
    info.footprint = &metricTreeFootprint;
    return info;
}

} // namespace shadowlab
