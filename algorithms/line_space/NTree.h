#pragma once
// The N-tree with a line space per subdivided node (Keul et al. 2016, 2017), built on the CPU and
// held in the paper's three pools, laid out exactly as the GPU reads them
// (shaders/line_space/layout.glsl). GL-free, so the CPU tests check it directly.
//
//   * The root is the scene's bounding box (padded, see NTree::margin). A node of level l < d that
//     holds geometry is subdivided into N × N × N equal children; level d holds only leaves, which
//     are never stored: the line space of their parent (level d - 1) summarises them.
//   * A child holds geometry when a triangle touches it (exact triangle–box test, on the child's
//     box widened by `margin`).
//   * Line space of a node: one bit per pair of sub-faces on two different faces, set when the shaft
//     between them touches a non-empty child (exact shaft–box test against the widened child box).
//     Set bits are therefore conservative: a segment between the two sub-faces that touches geometry
//     inside the node always finds its bit set (see Geometry.h).
#include "algorithms/line_space/Geometry.h"
#include "framework/scene/Scene.h"
#include "shaders/line_space/layout.glsl"

#include <cstddef>
#include <cstdint>
#include <cstddef>
#include <algorithm>
#include <utility>
#include <vector>

namespace shadowlab::ls {

/// Node pool entry, std430 (LsNode in shaders/line_space/trace.comp).
struct NodeGpu {
    float lo[3];
    uint32_t children; ///< offset of its children group in the tree pool, or LS_NO_CHILDREN
    float size[3];     ///< world units per axis
    uint32_t level;    ///< 0 = root
};
static_assert(sizeof(NodeGpu) == LS_NODE_BYTES, "LsNode is 32 bytes in std430");

constexpr int kMaxN = 8;     ///< N² sub-faces per face must fit one 64-bit mask in the build
constexpr int kMaxDepth = 5; ///< d: N^d leaf cells per axis

constexpr size_t wordsPerNode(int n) { return size_t(LS_WORDS_PER_NODE(n)); }
static_assert(wordsPerNode(4) == 120 && wordsPerNode(8) == 1920, "15 N^4 bits, packed in 32-bit words");
constexpr size_t occupancyWords(int n) { return size_t(LS_OCC_WORDS_PER_NODE(n)); }

/// Bit of the shaft between sub-face `subA` of face `fa` and `subB` of face `fb` (fa != fb, any order).
inline uint32_t shaftBit(int n, int fa, int subA, int fb, int subB) {
    if (fa > fb) std::swap(fa, fb), std::swap(subA, subB);
    const uint32_t n2 = uint32_t(n * n);
    return uint32_t(LS_PAIR_INDEX(fa, fb)) * n2 * n2 + uint32_t(subA) * n2 + uint32_t(subB);
}

struct NTree {
    int n = 0, d = 0;
    float margin = 0;             ///< world units: boxes are widened by this in every overlap test
    std::vector<NodeGpu> nodes;   ///< node pool, breadth first (node 0 is the root, if any geometry)
    std::vector<uint32_t> tree;   ///< tree pool: N³ entries per children group: node index or LS_EMPTY
    std::vector<uint32_t> bits;   ///< line-space pool: wordsPerNode(n) words per node
    /// Occupancy pool: occupancyWords(n) words per node, bit (z × N + y) × N + x set when a triangle
    /// touches that child (the widened box, as for the tree pool). The walk of the start region's
    /// last node reads the leaves' bits; the tree pool says the same above the last level.
    std::vector<uint32_t> occupancy;
    std::vector<uint64_t> nodesPerLevel; ///< subdivided nodes per level 0 .. d-1
    double buildMs = 0;           ///< CPU time of the build (kept when loaded from the disk cache)

    bool bit(size_t node, uint32_t b) const { return (bits[node * wordsPerNode(n) + (b >> 5)] >> (b & 31)) & 1u; }
    size_t poolBytes() const {
        return nodes.size() * sizeof(NodeGpu) + (tree.size() + bits.size() + occupancy.size()) * sizeof(uint32_t);
    }
};

/// Builds the N-tree of `scene` with branching factor n (2..kMaxN) and depth d (1..kMaxDepth), on
/// `threads` threads (0 = all). Deterministic: the pools do not depend on the thread count.
/// Throws SceneRefusal as soon as the node or tree pool would exceed `maxBlockBytes` (the GPU's
/// SSBO limit) or the line-space pool LS_BIT_CHUNKS blocks of that size: a level's node count is
/// known before its line spaces are computed, so an impossible parameter set fails in seconds
/// instead of after the whole build. `shapeOnly`: nodes, tree and occupancy without the line
/// spaces (bits left empty), the same checks at a fraction of the cost (`validate`).
NTree buildNTree(const Scene& scene, int n, int d, int threads = 0, size_t maxBlockBytes = SIZE_MAX, bool shapeOnly = false);

/// Triangles of the leaves of the last subdivided level, for start_region = exact (the start region
/// tested against the triangles themselves). Occupied leaves are numbered in node order, then child
/// order; leaf c of node i (its occupancy bit set) is number wordRank[i × occupancyWords + c / 32]
/// + (occupied leaves of word c / 32 below bit c % 32), so the shader finds it with one load and one
/// bitCount; its triangles are tris[prefix[g] .. prefix[g + 1]) (scene triangle indices).
struct LeafLists {
    std::vector<uint32_t> wordRank; ///< per node and occupancy word (0 above the last level)
    std::vector<uint32_t> prefix;   ///< per occupied leaf, plus one
    std::vector<uint32_t> tris;
    /// With a leaf split S > 1: per occupied leaf, the occupancy of its S³ sub-cells (bit
    /// (z × S + y) × S + x, two words: bits 0..31, 32..63), by the same triangle–box test on the
    /// sub-cells widened by the tree's margin.
    std::vector<uint32_t> sub;
    size_t bytes() const { return (wordRank.size() + prefix.size() + tris.size() + sub.size()) * sizeof(uint32_t); }
};

/// The leaf lists of `tree` (built from `scene`): the build's descent replayed with the same
/// triangle–box tests on the same boxes, so a leaf has triangles exactly where its occupancy bit is set.
/// `split` (1, 2 or 4): sub-cells per axis of a leaf for LeafLists::sub (1: none).
LeafLists buildLeafLists(const Scene& scene, const NTree& tree, int threads = 0, int split = 1);

/// Per scene triangle its plane: unit normal (x, y, z) and offset w, so a point p lies at signed
/// distance dot(n, p) + w; (0, 0, 0, 0) for a degenerate triangle (every point "on" it, never culled).
std::vector<glm::vec4> trianglePlanes(const Scene& scene);

/// Nodes per line-space pool chunk for SSBOs of at most `maxBlockBytes`.
inline size_t nodesPerChunk(int n, size_t maxBlockBytes) {
    return std::max<size_t>(1, maxBlockBytes / (wordsPerNode(n) * sizeof(uint32_t)));
}

/// The root box the build uses for `scene` (bounds padded so no axis is flat and geometry on the
/// bounds lies strictly inside), and the overlap margin; exposed for the tests.
void rootBox(const Scene& scene, glm::vec3& lo, glm::vec3& size, float& margin);

/// The sub-face box (flat along the face's axis) of face f, sub-face (i, j), of node box lo + [0, size].
DBox subFaceBox(glm::dvec3 lo, glm::dvec3 size, int n, int f, int i, int j);

} // namespace shadowlab::ls
