#pragma once
// A point or spot light kept clear of every surface by 1.25 × the ray offset, on every frame checked.
//
// The reference (and bvh_raytrace) ends each shadow ray the ray offset short of the light; the
// volume algorithms (psv, ptsv, shadow_volumes) and the cluster tests count every triangle up to the
// light itself. A surface within that distance of the light is seen by one and not the other, and
// their images disagree on whole regions (tenth probe: a light just behind a wall; the count is in
// results/reference/exactness_campaign_llvmpipe.md). Which one is right is a matter of definition, not of precision, so such a scene is
// refused instead of compared, with a quarter of the offset more so that rounding at the ray's end
// cannot decide it either.
#include "framework/experiment/Config.h"

namespace shadowlab {

/// InputError (the light's JSON path, the frame, the distance and the nearest point) when a point or
/// spot light lies within 1.25 × the largest ray offset of the reference and the exact algorithms
/// from any triangle, at any frame checked (every frame, or 10,000 spread over a longer run, as the
/// poses are). Directional lights have no end; area lights are sampled by the soft algorithms,
/// whose tolerance covers it.
void checkLightClearance(const ExperimentConfig& c);

} // namespace shadowlab
