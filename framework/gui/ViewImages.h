#pragma once
// What the viewport shows: the shaded image, the visibility, one of the algorithm's heat maps, or
// the difference against the CPU reference. Colour maps are framework/metrics/Images.h's (the same
// as in experiment outputs); the RGBA they produce is uploaded to a texture for display.
#include "framework/metrics/Accuracy.h"
#include "framework/gui/Viewer.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace shadowlab {

enum class ViewMode { Shaded, Visibility, Heat, Difference };

/// One entry of the difference legend, coloured by differenceImage() itself.
struct LegendEntry {
    std::string label;
    std::array<unsigned char, 4> rgba;
};

class ViewImages {
public:
    ViewMode mode = ViewMode::Shaded;
    int heatIndex = 0;          ///< which of the algorithm's debugViews()
    bool autoReference = false; ///< re-trace the reference whenever the view changes (slow: CPU)

    /// Call after Viewer::renderFrame(): prepares the image of `mode`; returns the texture to show.
    GLuint update(Viewer& viewer);

    /// Asks for the reference to be ray-traced (CPU, blocking) by the next update(), so it is traced
    /// for the frame just rendered even when the request comes before the camera moves this frame.
    void requestReference() { referenceRequested_ = true; }
    /// Ray-traces the reference for the frame last rendered.
    void computeReference(Viewer& viewer);
    bool hasReference() const { return !refValues_.empty(); }
    /// The camera, light or resolution changed since the reference was traced.
    bool referenceStale(const Viewer& viewer) const;
    const Accuracy& accuracy() const { return accuracy_; }
    double referenceMs() const { return referenceMs_; }

    /// The heat map's range and unit, for its legend (valid after update() in Heat mode).
    float heatMax() const { return heatMax_; }
    const std::string& heatUnit() const { return heatUnit_; }
    /// A 256×1 texture of the heat ramp over [0, 1].
    GLuint heatRamp();
    /// Colours of the difference image, from differenceImage() on one pixel per case.
    static std::vector<LegendEntry> differenceLegend();
    /// Why the current mode shows the shaded image instead ("" when it shows what was asked).
    const std::string& note() const { return note_; }

private:
    /// What the reference was traced for: any field of the camera or light, or the resolution.
    struct FrameKey {
        Camera camera;
        Light light;
        glm::ivec2 resolution{0, 0};
        bool operator==(const FrameKey&) const = default;
    };
    static FrameKey keyOf(const Viewer& viewer);
    void upload(const std::vector<unsigned char>& rgba, glm::ivec2 size);

    GlTexture display_;
    glm::ivec2 displaySize_{0, 0};
    GlTexture ramp_;

    std::unique_ptr<AlgorithmHost> reference_;
    StageTimer referenceTimer_;
    std::vector<float> refValues_;
    std::vector<uint8_t> lit_;
    FrameKey refKey_{};
    Accuracy accuracy_;
    double referenceMs_ = 0;
    bool referenceRequested_ = false;

    float heatMax_ = 0;
    std::string heatUnit_;
    std::string note_;
};

} // namespace shadowlab
