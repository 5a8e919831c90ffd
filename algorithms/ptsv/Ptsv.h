#pragma once
// `ptsv`: Per-Triangle Shadow Volumes using a view-sample cluster hierarchy (Sintorn, Kämpe,
// Olsson, Assarsson, I3D 2014), the dual of `psv`: every frame, compute shaders build a 32-ary tree
// over the G-buffer's samples, clustered by 8×8 tile and exponential depth slice in Morton order
// (stage `hierarchy`), set up each triangle's shadow-volume planes (stage `setup`), walk each volume
// down the tree, 32 children at a time, marking the samples inside it (stage `traverse`, one or two
// passes), and finally shadow the samples of trivially accepted nodes (stage `resolve`). Exact hard
// shadows for point and directional lights. Design, parameters and measurements:
// docs/algorithms/ptsv.md.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo ptsvInfo();

} // namespace shadowlab
