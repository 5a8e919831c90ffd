#pragma once
// `shadow_volumes`: Crow's shadow volumes counted on the stencil buffer, the baseline the
// per-triangle and partitioned shadow-volume papers measure themselves against. Silhouette edges
// (with their multiplicity, from an edge adjacency built per scene) are found on the GPU every
// frame and extruded to infinity; ZFAIL with caps (exact, the eye may be in shadow) or ZPASS (the
// papers' fast variant, wrong when the eye is in shadow); depth clamping instead of a far plane.
// docs/algorithms/shadow_volumes.md.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo shadowVolumesInfo();

} // namespace shadowlab
