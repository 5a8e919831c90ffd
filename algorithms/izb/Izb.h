#pragma once
// `izb`: the irregular z-buffer with exact (frustum-traced) visibility, after Wyman, Hoetzlein and
// Lefohn, *Frustum-Traced Raster Shadows: Revisiting Irregular Z-Buffers* (I3D 2015), with one
// sample per pixel: the view samples are listed in the cells of a light-space grid, every triangle
// is rasterised conservatively onto the grid in a compute shader and tested exactly against each
// listed sample. The baseline of the metric-tree paper's Table 1. docs/algorithms/izb.md.
#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

AlgorithmInfo izbInfo();

} // namespace shadowlab
