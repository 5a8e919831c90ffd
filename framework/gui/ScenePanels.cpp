// The algorithm, camera and light panels.
#include "framework/gui/GuiState.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace shadowlab {

namespace {

constexpr LightType kLightTypes[] = {LightType::Point, LightType::Spot, LightType::Directional, LightType::Area};

// The parser's limits (Config.h), so anything set here can be saved as a config;
// saveRecordedConfig() re-validates with parseConfig before writing anyway.
constexpr float kFovMin = configlimits::kFovMinDeg, kFovMax = configlimits::kFovMaxDeg;
constexpr float kConeMin = configlimits::kConeMinDeg, kConeMax = configlimits::kConeMaxDeg;
constexpr int kSamplesMin = configlimits::kAreaSamplesMin, kSamplesMax = configlimits::kAreaSamplesMax;

std::string choiceLabel(const AlgorithmChoice& c) {
    return c.label + (c.fromConfig ? "  (config)" : "  (defaults)");
}

} // namespace

void drawAlgorithmPanel(GuiState& s) {
    Viewer& v = *s.viewer;
    ImGui::SetNextItemWidth(-1);
    if (ImGui::BeginCombo("##algorithm", choiceLabel(v.active()).c_str())) {
        for (size_t i = 0; i < v.choices().size(); ++i) {
            const AlgorithmChoice& c = v.choices()[i];
            if (i > 0 && c.fromConfig != v.choices()[i - 1].fromConfig) ImGui::Separator();
            if (ImGui::Selectable(choiceLabel(c).c_str(), int(i) == v.activeIndex())) {
                v.selectAlgorithm(int(i));
                s.measurements.clear();
            }
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", c.info->summary.c_str());
        }
        ImGui::EndCombo();
    }
    ImGui::TextWrapped("%s", v.active().info->summary.c_str());
    std::string why = v.unsupportedReason();
    if (!why.empty()) ImGui::TextColored(ImVec4(1, 0.5f, 0.2f, 1), "%s: shown unshadowed", why.c_str());
    s.paramWidgets.draw(v);
}

void drawCameraPanel(GuiState& s) {
    Viewer& v = *s.viewer;
    Camera& c = v.camera;
    bool moved = false;
    float radius = std::max(v.sceneGpu().bounds().radius(), 1e-3f);
    moved |= ImGui::DragFloat3("position", &c.position.x, 0.01f * radius, 0, 0, "%.3f");
    moved |= ImGui::DragFloat3("target", &c.target.x, 0.01f * radius, 0, 0, "%.3f");
    if (moved) v.playback.followCamera = false;
    ImGui::SliderFloat("fov y", &c.fovYDeg, kFovMin, kFovMax, "%.1f deg", ImGuiSliderFlags_AlwaysClamp);
    // Near and far on log sliders, each bounded by the other so the projection stays valid.
    ImGui::SliderFloat("near", &c.nearPlane, 1e-4f * radius, c.farPlane * 0.5f, "%.4g", ImGuiSliderFlags_Logarithmic);
    ImGui::SliderFloat("far", &c.farPlane, c.nearPlane * 2.0f, 1e3f * radius, "%.4g", ImGuiSliderFlags_Logarithmic);
    c.nearPlane = std::max(c.nearPlane, 1e-6f);
    c.farPlane = std::max(c.farPlane, c.nearPlane * 1.001f);
    ImGui::SliderFloat("move speed", &s.controller.speed, 0.05f, 5.0f, "%.2f radii/s", ImGuiSliderFlags_Logarithmic);
    ImGui::TextDisabled("right-drag: look, WASD: move, Q/E: down/up, Shift: fast");
}

void drawLightPanel(GuiState& s) {
    Viewer& v = *s.viewer;
    Light& l = v.light;
    float radius = std::max(v.sceneGpu().bounds().radius(), 1e-3f);
    if (ImGui::BeginCombo("type", toString(l.type))) {
        for (LightType t : kLightTypes)
            if (ImGui::Selectable(toString(t), t == l.type)) l.type = t;
        ImGui::EndCombo();
    }
    bool moved = ImGui::DragFloat3("position", &l.position.x, 0.01f * radius, 0, 0, "%.3f");
    if (l.type != LightType::Point) {
        // Spot, area and directional lights aim at the target: it sets their direction.
        moved |= ImGui::DragFloat3("target", &l.target.x, 0.01f * radius, 0, 0, "%.3f");
        glm::vec3 d = l.target - l.position;
        if (glm::length(d) > 0) {
            d = glm::normalize(d);
            ImGui::TextDisabled("direction (%.2f, %.2f, %.2f)", d.x, d.y, d.z);
        } else {
            ImGui::TextColored(ImVec4(1, 0.5f, 0.2f, 1), "target must differ from position");
        }
    }
    if (moved) v.playback.followLight = false;
    if (l.type == LightType::Spot)
        ImGui::SliderFloat("cone", &l.coneDeg, kConeMin, kConeMax, "%.1f deg", ImGuiSliderFlags_AlwaysClamp);
    if (l.type == LightType::Area) {
        ImGui::DragFloat2("size", &l.size.x, 0.01f * radius, 1e-3f * radius, 10.0f * radius, "%.3f");
        l.size = glm::max(l.size, glm::vec2(1e-6f)); // configs require positive sides
        ImGui::SliderInt("samples", &l.samples, kSamplesMin, kSamplesMax, "%d",
                         ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
    }
    ImGui::Checkbox("follow the light path", &v.playback.followLight);
    if (v.config().lightPath.empty()) {
        ImGui::SameLine();
        ImGui::TextDisabled("(the config has none)");
    }
    ImGui::TextDisabled("Ctrl + left-drag in the view moves the light");
}

} // namespace shadowlab
