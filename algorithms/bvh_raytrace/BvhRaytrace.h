#pragma once
// `bvh_raytrace`: the same-device baseline of line_space. The reference's shadow rays, traced in
// GLSL through a binned-SAH BVH built once on the CPU (setScene) and flattened into SSBOs; a fixed
// traversal stack whose overflow is reported, any-hit early exit. Hard shadows (point, spot,
// directional) and soft shadows (area light: the fraction of Light::samplePoints() unblocked).
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo bvhRaytraceInfo();

} // namespace shadowlab
