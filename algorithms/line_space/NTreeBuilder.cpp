// Level-by-level construction of the N-tree and its line spaces (see NTree.h). Every node of a level
// is independent, so a level is processed in parallel and then appended in node order: the pools
// are breadth first and identical for any thread count.
#include "algorithms/line_space/NTree.h"

#include "algorithms/line_space/ShaftFill.h"
#include "framework/core/Error.h"
#include "framework/core/Parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

namespace shadowlab::ls {
namespace {

/// A node of the level being built, with the triangles that touch it.
struct Pending {
    glm::vec3 lo, size;
    std::vector<uint32_t> tris;
};

struct NodeResult {
    std::vector<uint8_t> occupied;              ///< N³, child order (z × N + y) × N + x
    std::vector<std::vector<uint32_t>> childTris; ///< per child, only above the last level
    std::vector<uint32_t> words;                ///< the node's line space
};

/// Child cell coordinate k along an axis: the same float expression the shader's DDA evaluates.
float cellLo(float lo, float cell, int k) { return lo + float(k) * cell; }

glm::dvec3 toD(glm::vec3 v) { return glm::dvec3(v); }

class Builder {
public:
    Builder(const Scene& scene, int n, float margin) : scene_(scene), n_(n), margin_(margin) {}

    /// Which children of `node` the triangles touch (and, if `lists`, which triangles touch each).
    void occupancy(const Pending& node, bool lists, NodeResult& r) const {
        const int n = n_, n3 = n * n * n;
        const glm::vec3 cell = node.size / float(n);
        r.occupied.assign(size_t(n3), 0);
        if (lists) r.childTris.assign(size_t(n3), {});
        const double m = margin_;
        for (uint32_t t : node.tris) {
            const glm::dvec3 a = toD(scene_.positions[3 * size_t(t)]), b = toD(scene_.positions[3 * size_t(t) + 1]),
                             c = toD(scene_.positions[3 * size_t(t) + 2]);
            glm::ivec3 i0, i1;
            for (int k = 0; k < 3; ++k) {
                double lo = std::min({a[k], b[k], c[k]}) - m, hi = std::max({a[k], b[k], c[k]}) + m;
                i0[k] = std::clamp(int(std::floor((lo - node.lo[k]) / cell[k])), 0, n - 1);
                i1[k] = std::clamp(int(std::floor((hi - node.lo[k]) / cell[k])), 0, n - 1);
            }
            // A triangle whose widened bounding box lies in one cell touches that cell: no test needed.
            const bool single = i0 == i1;
            for (int z = i0.z; z <= i1.z; ++z)
                for (int y = i0.y; y <= i1.y; ++y)
                    for (int x = i0.x; x <= i1.x; ++x) {
                        const int ci = (z * n + y) * n + x;
                        if (!lists && r.occupied[size_t(ci)]) continue; // occupancy only: known already
                        if (!single) {
                            const glm::vec3 clo(cellLo(node.lo.x, cell.x, x), cellLo(node.lo.y, cell.y, y),
                                                cellLo(node.lo.z, cell.z, z));
                            const DBox box{toD(clo) - m, toD(clo + cell) + m};
                            if (!triangleOverlapsBox(a, b, c, box)) continue;
                        }
                        r.occupied[size_t(ci)] = 1;
                        if (lists) r.childTris[size_t(ci)].push_back(t);
                    }
        }
    }

private:
    const Scene& scene_;
    int n_;
    float margin_;
};

} // namespace

void rootBox(const Scene& scene, glm::vec3& lo, glm::vec3& size, float& margin) {
    glm::vec3 bmin = scene.bounds.empty() ? glm::vec3(-1.0f) : scene.bounds.min;
    glm::vec3 bmax = scene.bounds.empty() ? glm::vec3(1.0f) : scene.bounds.max;
    const float extent = std::max({bmax.x - bmin.x, bmax.y - bmin.y, bmax.z - bmin.z, 1e-6f});
    // A flat scene (a lone plane) would give zero-thickness cells; 1e-3 of the extent avoids it.
    for (int k = 0; k < 3; ++k) {
        const float grow = std::max(0.0f, 1e-3f * extent - (bmax[k] - bmin[k])) * 0.5f;
        bmin[k] -= grow, bmax[k] += grow;
    }
    // The margin covers float rounding of the shader's ray–box and sub-face arithmetic (~1e-6 of
    // the extent); the padding keeps geometry on the bounds strictly inside the root.
    margin = 1e-5f * extent;
    const float pad = 1e-4f * extent;
    lo = bmin - pad;
    size = (bmax - bmin) + 2.0f * pad;
}

DBox subFaceBox(glm::dvec3 lo, glm::dvec3 size, int n, int f, int i, int j) {
    const int a = f >> 1, u = (a + 1) % 3, v = (a + 2) % 3;
    DBox b;
    b.lo[a] = b.hi[a] = lo[a] + double(f & 1) * size[a];
    const double cu = size[u] / n, cv = size[v] / n;
    b.lo[u] = lo[u] + i * cu, b.hi[u] = lo[u] + (i + 1) * cu;
    b.lo[v] = lo[v] + j * cv, b.hi[v] = lo[v] + (j + 1) * cv;
    return b;
}

NTree buildNTree(const Scene& scene, int n, int d, int threads, size_t maxBlockBytes, bool shapeOnly) {
    const auto t0 = std::chrono::steady_clock::now();
    NTree t;
    t.n = n, t.d = d;
    t.nodesPerLevel.assign(size_t(d), 0);
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    glm::vec3 lo, size;
    rootBox(scene, lo, size, t.margin);
    Builder builder(scene, n, t.margin);

    std::vector<Pending> level;
    if (scene.triangleCount() > 0) {
        Pending root{lo, size, {}};
        root.tris.resize(scene.triangleCount());
        for (uint32_t i = 0; i < uint32_t(root.tris.size()); ++i) root.tris[i] = i;
        t.nodes.push_back({{lo.x, lo.y, lo.z}, LS_NO_CHILDREN, {size.x, size.y, size.z}, 0});
        level.push_back(std::move(root));
    }
    const size_t words = wordsPerNode(n);
    const int n3 = n * n * n;
    auto check = [&](const char* pool, size_t bytes, size_t limit) {
        if (bytes <= limit) return;
        auto mib = [](size_t b) { return std::to_string((b + (1u << 20) - 1) >> 20); };
        throw SceneRefusal("line_space: the " + std::string(pool) + " pool of (N, d) = (" + std::to_string(n) + ", " +
                           std::to_string(d) + ") needs at least " + mib(bytes) + " MiB, more than the " + mib(limit) +
                           " MiB it may take here (GL shader storage blocks); use a smaller N or d");
    };
    for (int l = 0; l < d && !level.empty(); ++l) {
        const size_t base = t.nodes.size() - level.size(); // this level's nodes are the last ones added
        const size_t perChunk = nodesPerChunk(n, maxBlockBytes);
        const size_t bitLimit = maxBlockBytes == SIZE_MAX ? SIZE_MAX : perChunk * LS_BIT_CHUNKS * words * sizeof(uint32_t);
        check("line-space", t.nodes.size() * words * sizeof(uint32_t), bitLimit);
        check("node", t.nodes.size() * sizeof(NodeGpu), maxBlockBytes);
        check("occupancy", t.nodes.size() * occupancyWords(n) * sizeof(uint32_t), maxBlockBytes);
        check("tree", (t.tree.size() + (l + 1 < d ? level.size() * size_t(n3) : 0)) * sizeof(uint32_t), maxBlockBytes);
        const bool last = l == d - 1;
        t.nodesPerLevel[size_t(l)] = level.size();
        std::vector<NodeResult> results(level.size());
        parallelFor(level.size(), threads, [&](size_t i) {
            builder.occupancy(level[i], !last, results[i]);
            level[i].tris = {}; // the children's lists replace it
            if (shapeOnly) return;
            results[i].words.assign(words, 0u);
            fillLineSpace(n, level[i].lo, level[i].size, results[i].occupied, t.margin, results[i].words.data());
        });
        if (!shapeOnly) t.bits.resize(t.nodes.size() * words);
        t.occupancy.resize(t.nodes.size() * occupancyWords(n));
        std::vector<Pending> next;
        for (size_t i = 0; i < level.size(); ++i) {
            NodeResult& r = results[i];
            if (!shapeOnly) std::copy(r.words.begin(), r.words.end(), t.bits.begin() + std::ptrdiff_t((base + i) * words));
            uint32_t* occ = t.occupancy.data() + (base + i) * occupancyWords(n);
            for (int c = 0; c < n3; ++c)
                if (r.occupied[size_t(c)]) occ[c >> 5] |= 1u << (c & 31);
            if (last) continue; // children are leaves: nothing stored below
            t.nodes[base + i].children = uint32_t(t.tree.size());
            const glm::vec3 cell = level[i].size / float(n);
            for (int c = 0; c < n3; ++c) {
                if (!r.occupied[size_t(c)]) {
                    t.tree.push_back(LS_EMPTY);
                    continue;
                }
                const int x = c % n, y = (c / n) % n, z = c / (n * n);
                const glm::vec3 clo(cellLo(level[i].lo.x, cell.x, x), cellLo(level[i].lo.y, cell.y, y),
                                    cellLo(level[i].lo.z, cell.z, z));
                t.tree.push_back(uint32_t(t.nodes.size()));
                t.nodes.push_back({{clo.x, clo.y, clo.z}, LS_NO_CHILDREN, {cell.x, cell.y, cell.z}, uint32_t(l + 1)});
                next.push_back({clo, cell, std::move(r.childTris[size_t(c)])});
            }
        }
        level = std::move(next);
    }
    t.buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return t;
}

LeafLists buildLeafLists(const Scene& scene, const NTree& t, int threads, int split) {
    LeafLists out;
    out.wordRank.assign(t.nodes.size() * occupancyWords(t.n), 0);
    out.prefix.push_back(0);
    if (t.nodes.empty()) return out;
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    const int n = t.n, n3 = n * n * n;
    Builder builder(scene, n, t.margin), subBuilder(scene, std::max(1, split), t.margin);
    auto box = [&](uint32_t i) {
        const NodeGpu& node = t.nodes[i];
        return Pending{{node.lo[0], node.lo[1], node.lo[2]}, {node.size[0], node.size[1], node.size[2]}, {}};
    };
    std::vector<uint32_t> index{0}; // the nodes of the level being replayed
    std::vector<Pending> level{box(0)};
    level[0].tris.resize(scene.triangleCount());
    for (uint32_t i = 0; i < uint32_t(level[0].tris.size()); ++i) level[0].tris[i] = i;
    for (int l = 0; l < t.d && !level.empty(); ++l) {
        std::vector<NodeResult> results(level.size());
        // Last level, split: per leaf its sub-cells' occupancy, from the leaf's own triangles.
        std::vector<std::vector<uint64_t>> subMasks(split > 1 && l == t.d - 1 ? level.size() : 0);
        parallelFor(level.size(), threads, [&](size_t i) {
            builder.occupancy(level[i], true, results[i]);
            level[i].tris = {};
            if (subMasks.empty()) return;
            subMasks[i].assign(size_t(n3), 0);
            const glm::vec3 cell = level[i].size / float(n);
            NodeResult leaf;
            for (int c = 0; c < n3; ++c) {
                if (results[i].childTris[size_t(c)].empty()) continue;
                const int x = c % n, y = (c / n) % n, z = c / (n * n);
                // The leaf's box by the float expression of the shader's DDA (cellLo).
                Pending p{{cellLo(level[i].lo.x, cell.x, x), cellLo(level[i].lo.y, cell.y, y), cellLo(level[i].lo.z, cell.z, z)},
                          cell, results[i].childTris[size_t(c)]};
                subBuilder.occupancy(p, false, leaf);
                uint64_t mask = 0;
                for (size_t b = 0; b < leaf.occupied.size(); ++b) mask |= uint64_t(leaf.occupied[b] != 0) << b;
                subMasks[i][size_t(c)] = mask;
            }
        });
        std::vector<uint32_t> nextIndex;
        std::vector<Pending> next;
        for (size_t i = 0; i < level.size(); ++i) {
            const NodeGpu& node = t.nodes[index[i]];
            if (int(node.level) == t.d - 1) { // leaves: append the occupied ones, in child order
                for (int c = 0; c < n3; ++c) {
                    if ((c & 31) == 0) out.wordRank[index[i] * occupancyWords(n) + size_t(c >> 5)] = uint32_t(out.prefix.size() - 1);
                    const auto& tris = results[i].childTris[size_t(c)];
                    if (tris.empty()) continue;
                    out.tris.insert(out.tris.end(), tris.begin(), tris.end());
                    out.prefix.push_back(uint32_t(out.tris.size()));
                    if (!subMasks.empty()) {
                        const uint64_t mask = subMasks[i][size_t(c)];
                        out.sub.push_back(uint32_t(mask));
                        out.sub.push_back(uint32_t(mask >> 32));
                    }
                }
                continue;
            }
            for (int c = 0; c < n3; ++c) {
                const uint32_t child = t.tree[node.children + size_t(c)];
                if (child == LS_EMPTY) continue;
                nextIndex.push_back(child);
                next.push_back(box(child));
                next.back().tris = std::move(results[i].childTris[size_t(c)]);
            }
        }
        // Last-level nodes come in node order (breadth first), so the numbering is node order too.
        index = std::move(nextIndex);
        level = std::move(next);
    }
    return out;
}

std::vector<glm::vec4> trianglePlanes(const Scene& scene) {
    std::vector<glm::vec4> planes(scene.triangleCount(), glm::vec4(0.0f));
    parallelFor(planes.size(), int(std::max(1u, std::thread::hardware_concurrency())), [&](size_t i) {
        const glm::dvec3 a = scene.positions[3 * i], b = scene.positions[3 * i + 1], c = scene.positions[3 * i + 2];
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double len = glm::length(n);
        if (!(len > 0.0) || !std::isfinite(len)) return;
        const glm::dvec3 u = n / len;
        planes[i] = glm::vec4(glm::vec3(u), float(-glm::dot(u, a)));
    });
    return planes;
}

} // namespace shadowlab::ls
