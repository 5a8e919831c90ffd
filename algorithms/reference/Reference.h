#pragma once
// `reference`: exact shadows ray-traced on the CPU with Embree 3 (EmbreeTracer), the ground truth
// every other algorithm is measured against. See EmbreeTracer.h for the visibility convention.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo referenceInfo();

} // namespace shadowlab
