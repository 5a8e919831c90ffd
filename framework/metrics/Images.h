#pragma once
// PNG output of the images an experiment writes: shaded frames, visibility, difference against the
// reference (false-lit / false-shadowed colour-coded) and heat maps.
#include <cstdint>
#include <string>
#include <vector>

namespace shadowlab {

/// Writes RGBA8 pixels (bottom row first, as GL reads them) as a PNG with the top row first.
void writePngRGBA(const std::string& path, int width, int height, const std::vector<unsigned char>& rgbaBottomUp);
/// Visibility in [0, 1] as grey (background pixels shown dark blue).
std::vector<unsigned char> visibilityImage(const std::vector<float>& vis, const std::vector<uint8_t>& covered);
/// Difference against the reference on lit pixels: red = false lit, blue = false shadowed,
/// grey = agrees (brightness = visibility), black = not lit by the light at all.
std::vector<unsigned char> differenceImage(const std::vector<float>& vis, const std::vector<float>& ref,
                                           const std::vector<uint8_t>& lit);
/// A heat map (perceptual "inferno"-like ramp) over [0, maxValue]; maxValue ≤ 0 uses the data's maximum.
std::vector<unsigned char> heatMapImage(const std::vector<float>& values, float maxValue, float* usedMax = nullptr);

} // namespace shadowlab
