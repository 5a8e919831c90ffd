#pragma once
// `psv`: Partitioned Shadow Volumes (Gerhards, Mora, Aveneau, Ghazanfarpour, EG 2015). Every frame
// a compute shader merges each triangle's shadow frustum into a Ternary Object Partitioning tree
// (stage `build`); a second one locates each G-buffer point in it (stage `traverse`). Exact hard
// shadows for point, spot and directional lights, with the paper's wedge optimisation, random
// insertion order, front-face culling, x-ray transparency, and the depth skip and the stackless and
// hybrid traversals of Mora et al. 2016 (Deep PSV).
// Design, parameters and measurements: docs/algorithms/psv.md.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo psvInfo();

} // namespace shadowlab
