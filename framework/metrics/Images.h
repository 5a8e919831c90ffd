#pragma once
// PNG output of the images an experiment writes: shaded frames, visibility, difference against the
// reference (false-lit / false-shadowed colour-coded) and heat maps.
#include <array>
#include <cstddef>
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

/// The values a heat map's ramp spans, [min, max], and how max was chosen. Values above max are
/// drawn in the ramp's top colour (clipped).
struct HeatScale {
    enum class Kind { Fixed, P99 };
    Kind kind = Kind::P99;  ///< Fixed: the view's own maxValue; P99: 99th percentile of the non-zero pixels
    float min = 0, max = 1;
    float dataMax = 0;      ///< the largest value in the image
    size_t nonZero = 0;     ///< pixels with a value > 0 (those the percentile is taken over)
    size_t clipped = 0;     ///< pixels above max
};
const char* heatScaleName(HeatScale::Kind kind);  // "fixed" | "p99"

/// The scale of a heat map: [0, fixedMax] where fixedMax > 0, else [0, p99 of the non-zero values]
/// (1 when none is), so that a few hot pixels do not darken the rest of the image.
HeatScale heatMapScale(const std::vector<float>& values, float fixedMax);
/// A heat map (perceptual "inferno"-like ramp, heatRampStops()) over the scale's [min, max].
std::vector<unsigned char> heatMapImage(const std::vector<float>& values, const HeatScale& scale);
/// The same over heatMapScale(values, maxValue); usedMax receives the scale's max.
std::vector<unsigned char> heatMapImage(const std::vector<float>& values, float maxValue, float* usedMax = nullptr);
/// The ramp's colours (RGB in [0, 1]) at 0, 1/4, …, 1 of the scale, linearly interpolated between:
/// written beside each heat map so that a colour bar drawn elsewhere matches the image exactly.
const std::array<std::array<float, 3>, 5>& heatRampStops();

} // namespace shadowlab
