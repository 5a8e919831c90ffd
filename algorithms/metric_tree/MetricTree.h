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

} // namespace shadowlab
