#pragma once
// `metric_tree`: scalable hard shadows with triangle clusters and a ternary metric tree (Deves,
// Mora, Aveneau, Ghazanfarpour, EGSR 2018). Preprocessing (`preprocess`, cached on disk) groups the
// triangles into clusters bounded by spheres or capsules; every frame a compute shader culls the
// clusters by their normal cones and inserts their cones / capsule-cones into a ternary metric tree
// with atomics (stage `build`); a second one walks it per G-buffer point and tests the triangles of
// the clusters whose cone holds the point (stage `traverse`). Exact hard shadows for point and
// directional lights. Design, parameters and measurements: docs/algorithms/metric_tree.md.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo metricTreeInfo();

/// `tile: auto`: pixels per tile of the tile query on subgroups of `subgroupWidth` lanes (0 =
/// unknown). The tile walks are made by invocations 0 .. 64 / pixels - 1 of a 64-invocation group
/// while the others wait at a barrier, so the walkers should fill one subgroup: 64 / width pixels,
/// at least 8 (a smaller tile shares its walk among too few pixels) and at most 64. Hence 8 (4 × 2)
/// on 8 lanes or more (llvmpipe, NVIDIA, AMD: 8 walkers, of 32 or 64 lanes on a GPU, instead of
/// the 1 or 2 a subgroup-sized tile gave), 16 (8 × 2) on 4 lanes. docs/algorithms/metric_tree.md.
int autoTilePixels(int subgroupWidth);

} // namespace shadowlab
