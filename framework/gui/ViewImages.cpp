#include "framework/gui/ViewImages.h"

#include "framework/metrics/Images.h"

#include <algorithm>
#include <chrono>

namespace shadowlab {

ViewImages::FrameKey ViewImages::keyOf(const Viewer& v) {
    return {v.camera, v.light, v.resolution()};
}

bool ViewImages::referenceStale(const Viewer& viewer) const { return !hasReference() || !(refKey_ == keyOf(viewer)); }

void ViewImages::upload(const std::vector<unsigned char>& rgba, glm::ivec2 size) {
    if (!display_ || size != displaySize_) {
        // Linear filtering: the viewport may show the image larger than it was rendered.
        display_ = makeTexture2D(GL_RGBA8, size.x, size.y, GL_LINEAR);
        displaySize_ = size;
    }
    glTextureSubImage2D(display_.id(), 0, 0, 0, size.x, size.y, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
}

GLuint ViewImages::heatRamp() {
    if (!ramp_) {
        std::vector<float> ramp(256);
        for (size_t i = 0; i < ramp.size(); ++i) ramp[i] = float(i) / float(ramp.size() - 1);
        ramp_ = makeTexture2D(GL_RGBA8, int(ramp.size()), 1, GL_LINEAR);
        auto rgba = heatMapImage(ramp, 1.0f);
        glTextureSubImage2D(ramp_.id(), 0, 0, 0, int(ramp.size()), 1, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    }
    return ramp_.id();
}

std::vector<LegendEntry> ViewImages::differenceLegend() {
    // One pixel per case, so the legend can never disagree with the image's colours.
    const std::vector<float> vis = {1, 0, 1, 0, 0}, ref = {0, 1, 1, 0, 0};
    const std::vector<uint8_t> lit = {1, 1, 1, 1, 0};
    auto rgba = differenceImage(vis, ref, lit);
    const char* labels[] = {"false lit (algorithm lit, reference shadowed)", "false shadowed (algorithm shadowed, reference lit)",
                            "agree, lit", "agree, shadowed", "not lit by the light (excluded)"};
    std::vector<LegendEntry> out;
    for (size_t i = 0; i < vis.size(); ++i)
        out.push_back({labels[i], {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2], rgba[4 * i + 3]}});
    return out;
}

void ViewImages::computeReference(Viewer& viewer) {
    const glm::ivec2 res = viewer.resolution();
    if (res.x <= 0) return;
    auto t = std::chrono::steady_clock::now();
    const AlgorithmEntry& entry = viewer.config().referenceEntry;
    if (!reference_) {
        // Built once (Embree BVH) and kept: only the frame changes between requests.
        reference_ = std::make_unique<AlgorithmHost>(*entry.info, entry.params);
        reference_->setScene(viewer.sceneGpu());
    }
    viewer.runOn(*reference_, referenceTimer_);  // resizes to the frame's resolution
    refValues_ = reference_->readVisibility();
    lit_ = litMask(viewer.cpuGBuffer(), viewer.light);
    refKey_ = keyOf(viewer);
    referenceMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

GLuint ViewImages::update(Viewer& viewer) {
    note_.clear();
    if (referenceRequested_) {
        referenceRequested_ = false;
        computeReference(viewer);
    }
    const glm::ivec2 res = viewer.resolution();
    if (mode == ViewMode::Shaded || res.x <= 0) return viewer.shadedTexture();
    if (mode == ViewMode::Visibility) {
        upload(visibilityImage(readTextureR32F(viewer.visibilityTexture(), res.x, res.y), coveredMask(viewer.cpuGBuffer())),
               res);
        return display_.id();
    }
    if (mode == ViewMode::Heat) {
        std::vector<DebugView> views = viewer.algorithm() ? viewer.algorithm()->debugViews() : std::vector<DebugView>{};
        if (views.empty()) {
            note_ = viewer.active().info->name + " has no heat maps";
            return viewer.shadedTexture();
        }
        heatIndex = std::clamp(heatIndex, 0, int(views.size()) - 1);
        const DebugView& view = views[size_t(heatIndex)];
        upload(heatMapImage(readTextureR32F(view.texture, res.x, res.y), view.maxValue, &heatMax_), res);
        heatUnit_ = view.unit;
        return display_.id();
    }
    // Difference: only against a reference traced for this very camera, light and resolution.
    if (referenceStale(viewer) && autoReference) computeReference(viewer);
    if (referenceStale(viewer)) {
        note_ = hasReference() ? "the view changed since the reference was traced: compute it again"
                               : "no reference yet: compute it (CPU ray tracing)";
        return viewer.shadedTexture();
    }
    const std::vector<float> vis = readTextureR32F(viewer.visibilityTexture(), res.x, res.y);
    accuracy_ = compareVisibility(vis, refValues_, lit_);
    upload(differenceImage(vis, refValues_, lit_), res);
    return display_.id();
}

} // namespace shadowlab
