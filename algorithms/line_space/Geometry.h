#pragma once
// Exact, conservative geometric tests of the line-space build (double precision, GL-free):
//   * triangle–box overlap (Akenine-Möller 2001: separating axis theorem, 13 axes), which decides
//     which N-tree children a triangle occupies;
//   * shaft–box overlap: does any segment between two sub-faces of a node pass through a box?
#include <glm/glm.hpp>

#include <algorithm>

namespace shadowlab::ls {

struct DBox {
    glm::dvec3 lo, hi;
};

/// Whether triangle (a, b, c) and the closed box touch (shared boundary points count).
bool triangleOverlapsBox(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, const DBox& box);

/// Whether the shaft between A and B, the union of all segments from a point of A to a point of B
/// (= their convex hull, A and B being convex), touches the closed box C. A and B are axis-aligned
/// boxes (sub-faces are flat ones). Exact: for a fixed s, the points (1 - s) a + s b form the box
/// (1 - s) A ⊕ s B, so the hull meets C iff some s in [0, 1] satisfies six linear inequalities,
/// two per axis. This is what a full separating-axis test of the hull's 8 corners against C
/// decides, at the cost of one interval intersection.
inline bool shaftOverlapsBox(const DBox& A, const DBox& B, const DBox& C) {
    double s0 = 0.0, s1 = 1.0;
    // a + b s <= 0 on [s0, s1]
    auto clip = [&](double a, double b) {
        if (b > 0.0) s1 = std::min(s1, -a / b);
        else if (b < 0.0) s0 = std::max(s0, -a / b);
        else if (a > 0.0) s1 = -1.0;
    };
    for (int j = 0; j < 3; ++j) {
        clip(A.lo[j] - C.hi[j], B.lo[j] - A.lo[j]); // (1 - s) A.lo + s B.lo <= C.hi
        clip(C.lo[j] - A.hi[j], A.hi[j] - B.hi[j]); // (1 - s) A.hi + s B.hi >= C.lo
        if (s0 > s1) return false;
    }
    return true;
}

} // namespace shadowlab::ls
