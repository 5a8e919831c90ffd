#pragma once
// `shadow_map`: the baseline. A 2D map for spot and directional lights, a cube map for point
// lights, each storing linear distance to the light; constant + slope-scaled bias; PCF filtering.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo shadowMapInfo();

} // namespace shadowlab
