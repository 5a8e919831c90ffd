#pragma once
// The edges of a triangle soup and the triangles around each, built once per scene for the
// silhouette pass of `shadow_volumes`. Corners are welded by exact position within one rigid part
// (a moving part, or the static rest), so welded corners stay welded under the parts' motion. An
// edge may have any number of triangles around it (open meshes: one; non-manifold: three or more),
// each with the direction it walks the edge in, which is what the per-edge silhouette multiplicity
// is summed from (docs/algorithms/shadow_volumes.md, "Volumes").
#include "framework/scene/Scene.h"

#include <cstdint>
#include <vector>

namespace shadowlab {

/// One triangle's side of an edge, packed in a word: triangle << 3 | corner << 1 | reversed.
/// The edge runs from the triangle's corner `corner` to corner (corner + 1) % 3; `reversed` says
/// that the triangle walks it against the edge's direction (the first triangle's walk).
struct EdgeSide {
    uint32_t triangle, corner;
    bool reversed;
};
inline uint32_t packEdgeSide(const EdgeSide& s) { return s.triangle << 3 | s.corner << 1 | (s.reversed ? 1u : 0u); }
inline EdgeSide unpackEdgeSide(uint32_t w) { return {w >> 3, (w >> 1) & 3u, (w & 1u) != 0}; }
/// Triangles a packed side can name (29 bits).
inline constexpr uint64_t kMaxEdgeSideTriangles = uint64_t(1) << 29;

struct EdgeAdjacency {
    /// Edge e's sides are sides[first[e], first[e + 1]); the first of them gives the edge's two
    /// vertices and direction (never reversed). first has edgeCount() + 1 entries.
    std::vector<uint32_t> first;
    std::vector<uint32_t> sides; ///< packEdgeSide words, grouped by edge: 3 per triangle
    size_t edgeCount() const { return first.empty() ? 0 : first.size() - 1; }
    size_t maxSides = 0;      ///< the most triangles around one edge
    size_t openEdges = 0;     ///< edges with one triangle (mesh borders)
    size_t nonManifold = 0;   ///< edges with three or more
};

/// The welded edges of `scene`'s triangles. Throws InputError when the scene has more triangles
/// than a packed side can name.
EdgeAdjacency buildEdgeAdjacency(const Scene& scene);

} // namespace shadowlab
