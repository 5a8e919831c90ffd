#pragma once
// `template`: the example plugin to copy when adding an algorithm (algorithms/template/README.md).
// Exact hard shadows by brute force: every pixel casts its shadow ray(s) against every triangle,
// biggest triangles first. Built into the tests and registered only there (tests/ConformanceGLTest),
// so it is tested from its first line exactly as a new algorithm would be.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo templateInfo();

} // namespace shadowlab
