#pragma once
// The line space of one N-tree node: for every pair of sub-faces on two different faces, whether
// the shaft between them touches a non-empty child (Geometry.h's exact shaft–box test).
//
// Testing all 15 N⁴ shafts against every non-empty child costs minutes per parameter set on a big
// scene, so the fill works per start sub-face A and end face F, with a 64-bit mask of F's N² ≤ 64
// sub-faces:
//   * the children are grouped in a hierarchy of 2×2×2 blocks; a block whose footprint on F (the
//     sub-faces a shaft from A can reach through the block's box) adds nothing to the mask known so
//     far is skipped whole;
//   * a child (or a block whose children are all non-empty, whose box is then exactly their union)
//     marks at once the sub-faces reached at a few fixed shaft parameters s, which are certainly
//     hit, and tests only the remaining candidates exactly.
// The result is the set of shafts the exact test accepts (up to rounding at 1e-9 of a cell, on the
// conservative side), only faster.
#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace shadowlab::ls {

/// Writes the 15 N⁴ line-space bits of the node lo + [0, size] into `words` (wordsPerNode(n),
/// zeroed by the caller). `occupied` has N³ entries in child order (z × N + y) × N + x; child boxes
/// are the cells lo + k × (size / N), widened by `margin` (the shader's float arithmetic).
void fillLineSpace(int n, glm::vec3 lo, glm::vec3 size, const std::vector<uint8_t>& occupied, double margin,
                   uint32_t* words);

} // namespace shadowlab::ls
