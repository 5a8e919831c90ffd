#pragma once
// `line_space`: approximate shadows from precomputed line-space visibility (Keul, Klee & Müller
// 2017). An N-tree with a line space per subdivided node is built once per scene on the CPU
// (cached on disk), uploaded as the paper's three pools, and traversed per shadow ray on the GPU
// without ever testing a triangle (shaders/line_space/trace.comp). Soft shadows: the area light's
// own samples (the reference uses the same); hard shadows (the paper's Figure 7): a point, spot or
// directional light, one ray per pixel.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo lineSpaceInfo();

} // namespace shadowlab
