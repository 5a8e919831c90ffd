#include "framework/metrics/Images.h"

#include "framework/core/FileIO.h"

#include "framework/core/Error.h"

#include <algorithm>
#include <cmath>

#include <stb_image_write.h>

namespace shadowlab {

void writePngRGBA(const std::string& path, int width, int height, const std::vector<unsigned char>& rgba) {
    std::vector<unsigned char> flipped(rgba.size());
    size_t row = size_t(width) * 4;
    for (int y = 0; y < height; ++y)
        std::copy_n(rgba.data() + size_t(height - 1 - y) * row, row, flipped.data() + size_t(y) * row);
    // Encoded in memory, then written like every other output file (writeFileAtomic): a full disk
    // or a link at the target never leaves a truncated PNG under the real name.
    std::string png;
    auto append = [](void* context, void* data, int size) { static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size)); };
    if (!stbi_write_png_to_func(append, &png, width, height, 4, flipped.data(), int(row)))
        throw RuntimeError("cannot encode " + path);
    writeFileAtomic(path, png);
}

static void put(std::vector<unsigned char>& out, size_t i, float r, float g, float b) {
    out[4 * i + 0] = (unsigned char)std::lround(std::clamp(r, 0.0f, 1.0f) * 255.0f);
    out[4 * i + 1] = (unsigned char)std::lround(std::clamp(g, 0.0f, 1.0f) * 255.0f);
    out[4 * i + 2] = (unsigned char)std::lround(std::clamp(b, 0.0f, 1.0f) * 255.0f);
    out[4 * i + 3] = 255;
}

std::vector<unsigned char> visibilityImage(const std::vector<float>& vis, const std::vector<uint8_t>& covered) {
    std::vector<unsigned char> out(vis.size() * 4);
    for (size_t i = 0; i < vis.size(); ++i) {
        if (covered[i]) put(out, i, vis[i], vis[i], vis[i]);
        else put(out, i, 0.05f, 0.05f, 0.2f);
    }
    return out;
}

std::vector<unsigned char> differenceImage(const std::vector<float>& vis, const std::vector<float>& ref,
                                           const std::vector<uint8_t>& lit) {
    std::vector<unsigned char> out(vis.size() * 4);
    for (size_t i = 0; i < vis.size(); ++i) {
        if (!lit[i]) { put(out, i, 0, 0, 0); continue; }
        bool v = vis[i] >= 0.5f, r = ref[i] >= 0.5f;
        if (v && !r) put(out, i, 1.0f, 0.1f, 0.1f);      // false lit
        else if (!v && r) put(out, i, 0.1f, 0.3f, 1.0f); // false shadowed
        else { float g = 0.25f + 0.5f * ref[i]; put(out, i, g, g, g); }
    }
    return out;
}

const char* heatScaleName(HeatScale::Kind kind) { return kind == HeatScale::Kind::Fixed ? "fixed" : "p99"; }

HeatScale heatMapScale(const std::vector<float>& values, float fixedMax) {
    HeatScale s;
    std::vector<float> nonZero;
    for (float v : values) {
        s.dataMax = std::max(s.dataMax, v);
        if (v > 0) nonZero.push_back(v);
    }
    s.nonZero = nonZero.size();
    if (fixedMax > 0) {
        s.kind = HeatScale::Kind::Fixed;
        s.max = fixedMax;
    } else if (!nonZero.empty()) {
        // Nearest rank: the smallest value that at least 99 % of the non-zero pixels do not exceed.
        size_t rank = size_t(std::ceil(0.99 * double(nonZero.size()))) - 1;
        std::nth_element(nonZero.begin(), nonZero.begin() + std::ptrdiff_t(rank), nonZero.end());
        s.max = nonZero[rank];
    }
    for (float v : values) s.clipped += v > s.max;
    return s;
}

const std::array<std::array<float, 3>, 5>& heatRampStops() {
    // Piecewise-linear approximation of a black → purple → orange → yellow ramp.
    static const std::array<std::array<float, 3>, 5> stops{
        {{0, 0, 0.02f}, {0.34f, 0.06f, 0.43f}, {0.73f, 0.21f, 0.33f}, {0.98f, 0.55f, 0.04f}, {0.99f, 1.0f, 0.64f}}};
    return stops;
}

std::vector<unsigned char> heatMapImage(const std::vector<float>& values, const HeatScale& scale) {
    const auto& stops = heatRampStops();
    const float range = scale.max > scale.min ? scale.max - scale.min : 1.0f;
    std::vector<unsigned char> out(values.size() * 4);
    for (size_t i = 0; i < values.size(); ++i) {
        float t = std::clamp((values[i] - scale.min) / range, 0.0f, 1.0f) * 4.0f;
        int k = std::min(int(t), 3);
        float u = t - float(k);
        put(out, i, stops[k][0] + u * (stops[k + 1][0] - stops[k][0]), stops[k][1] + u * (stops[k + 1][1] - stops[k][1]),
            stops[k][2] + u * (stops[k + 1][2] - stops[k][2]));
    }
    return out;
}

std::vector<unsigned char> heatMapImage(const std::vector<float>& values, float maxValue, float* usedMax) {
    HeatScale scale = heatMapScale(values, maxValue);
    if (usedMax) *usedMax = scale.max;
    return heatMapImage(values, scale);
}

} // namespace shadowlab
