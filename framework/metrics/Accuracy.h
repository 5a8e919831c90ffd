#pragma once
// Pixel-by-pixel comparison of an algorithm's visibility with the reference's.
#include "framework/render/GBuffer.h"
#include "framework/view/Light.h"

#include <cstdint>
#include <vector>

namespace shadowlab {

/// Pixels that receive direct light before occlusion: covered, facing the light (N·L > 0) and
/// inside the light's reach (spot cone, front of an area light). Metrics are over these pixels.
std::vector<uint8_t> litMask(const CpuGBuffer& g, const Light& light);
/// 1 where the G-buffer pixel holds geometry (the visibility image's "no geometry" is the rest).
std::vector<uint8_t> coveredMask(const CpuGBuffer& g);

struct Accuracy {
    size_t litPixels = 0;
    double mismatchRatio = 0; ///< share of lit pixels whose binary visibility (≥ 0.5) differs from the reference
    double falseLit = 0;      ///< share of lit pixels lit by the algorithm but shadowed in the reference
    double falseShadowed = 0; ///< share of lit pixels shadowed by the algorithm but lit in the reference
    double rmse = 0;          ///< root mean square difference of visibility over lit pixels
    size_t falseLitPixels = 0, falseShadowedPixels = 0;
    /// The first wrong pixel in memory order (row 0 at the image's bottom, as GL stores it); -1: none.
    int64_t firstWrongPixel = -1;
};

Accuracy compareVisibility(const std::vector<float>& visibility, const std::vector<float>& reference,
                           const std::vector<uint8_t>& lit);

} // namespace shadowlab
