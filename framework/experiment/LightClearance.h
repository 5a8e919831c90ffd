#pragma once
// A point or spot light kept clear of every surface by 1.25 × the ray offset, on every frame checked.
//
// The rule came from a difference of definition: the reference (and bvh_raytrace) ended each shadow
// ray the ray offset short of the light, while the volume algorithms (psv, ptsv, shadow_volumes)
// and the cluster tests count every triangle up to the light itself, and a surface within that
// distance of the light was seen by one and not the other (tenth probe: a light just behind a wall,
// whole regions apart; results/reference/exactness_campaign_llvmpipe.md). Rays to point and spot
// lights now run to the light itself (common/shadow_ray.glsl, reference/Watertight.h), with no
// division that a GPU could round otherwise, and they rely on this rule: nothing lies at the
// segment's end, where the rays and the volumes' apex meet, within a quarter of the offset more
// than rounding could decide.
#include "framework/experiment/Config.h"

namespace shadowlab {

/// InputError (the light's JSON path, the frame, the distance and the nearest point) when a point or
/// spot light lies within 1.25 × the largest ray offset of the reference and the exact algorithms
/// from any triangle, at any frame checked (every frame, or 10,000 spread over a longer run, as the
/// poses are). Directional lights have no end; area lights are sampled by the soft algorithms,
/// whose tolerance covers it.
void checkLightClearance(const ExperimentConfig& c);

} // namespace shadowlab
