#include "framework/experiment/FrameImages.h"

#include "framework/core/FileIO.h"
#include "framework/gl/GlObjects.h"
#include "framework/metrics/Images.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>

namespace shadowlab {

std::string frameImagePrefix(const std::string& id, int frame) {
    char tag[32];
    std::snprintf(tag, sizeof tag, "_f%04d_", frame);
    return id + tag;
}

void writeFrameImages(const std::string& dir, const std::string& id, int frame, glm::ivec2 res, ShadingPass& shading,
                      const std::vector<float>& vis, const std::vector<float>* ref, const std::vector<uint8_t>& lit,
                      const std::vector<uint8_t>& covered) {
    const std::string base = dir + "/images/" + frameImagePrefix(id, frame);
    const auto& [shaded, visibility, diff] = kFrameImageKinds;
    writePngRGBA(base + shaded + ".png", res.x, res.y, readTextureRGBA8(shading.output(), res.x, res.y));
    writePngRGBA(base + visibility + ".png", res.x, res.y, visibilityImage(vis, covered));
    if (ref) writePngRGBA(base + diff + ".png", res.x, res.y, differenceImage(vis, *ref, lit));
}

namespace {

/// What one heat map's colours mean: the JSON written beside its PNG (less id and frame).
nlohmann::json heatMapLegend(const DebugView& view, const HeatScale& scale, const std::string& image, glm::ivec2 res) {
    nlohmann::json ramp = nlohmann::json::array();
    // As the decimals they were written with (a float's 0.02 would print as 0.0199999995…).
    auto decimal = [](float v) { return std::round(double(v) * 1e4) / 1e4; };
    for (const auto& c : heatRampStops()) ramp.push_back({decimal(c[0]), decimal(c[1]), decimal(c[2])});
    return {{"name", view.name},
            {"unit", view.unit},
            {"image", image},
            {"width", res.x},
            {"height", res.y},
            {"scale", heatScaleName(scale.kind)},
            {"min", scale.min},
            {"max", scale.max},
            {"data_max", scale.dataMax},
            {"nonzero_pixels", scale.nonZero},
            {"clipped_pixels", scale.clipped},
            {"ramp", ramp}};
}

} // namespace

void writeHeatMaps(const std::string& dir, const std::string& id, int frame, glm::ivec2 res, const std::vector<DebugView>& views) {
    const std::string prefix = frameImagePrefix(id, frame);
    for (size_t k = 0; k < views.size(); ++k) {
        const DebugView& view = views[k];
        auto values = readTextureR32F(view.texture, res.x, res.y);
        const HeatScale scale = heatMapScale(values, view.maxValue);
        const std::string image = prefix + kHeatMapPrefix + view.name + ".png";
        writePngRGBA(dir + "/images/" + image, res.x, res.y, heatMapImage(values, scale));
        // The PNG holds colours only: its legend (what the colours mean) is this file beside it.
        nlohmann::json legend = heatMapLegend(view, scale, image, res);
        legend["id"] = id;
        legend["frame"] = frame;
        legend["view_index"] = k; // the algorithm's order of its views, which readers keep
        const std::string path = dir + "/images/" + prefix + kHeatMapPrefix + view.name + ".json";
        writeFileAtomic(path, legend.dump(2) + "\n");
    }
}

} // namespace shadowlab
