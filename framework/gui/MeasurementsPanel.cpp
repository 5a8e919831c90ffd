// Measurements (rolling graphs of the active algorithm's stages), the view selector and its legend.
#include "framework/gui/GuiState.h"
#include "framework/metrics/Images.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>

namespace shadowlab {

namespace {

std::string formatBytes(size_t bytes) {
    char s[32];
    if (bytes >= (size_t(1) << 20)) std::snprintf(s, sizeof s, "%.2f MiB", double(bytes) / double(1 << 20));
    else std::snprintf(s, sizeof s, "%.1f KiB", double(bytes) / 1024.0);
    return s;
}

void plot(const char* id, const RollingSeries& series, const char* what) {
    char overlay[96];
    std::snprintf(overlay, sizeof overlay, "%s %.2f ms  (mean %.2f, max %.2f)", what, series.last(), series.mean(), series.max());
    const auto& v = series.values();
    ImGui::PlotLines(id, v.data(), int(v.size()), 0, overlay, 0.0f, std::max(series.max() * 1.1f, 1e-3f),
                     ImVec2(ImGui::GetContentRegionAvail().x, 40));
}

ImVec4 colour(const std::array<unsigned char, 4>& c) { return ImVec4(c[0] / 255.f, c[1] / 255.f, c[2] / 255.f, 1.0f); }

void legendRows(const std::vector<LegendEntry>& rows) {
    for (const LegendEntry& e : rows) {
        ImGui::ColorButton(e.label.c_str(), colour(e.rgba), ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoPicker,
                           ImVec2(14, 14));
        ImGui::SameLine();
        ImGui::TextUnformatted(e.label.c_str());
    }
}

std::vector<LegendEntry> visibilityLegend() {
    // Coloured by visibilityImage() itself, one pixel per case.
    auto rgba = visibilityImage({0.0f, 0.5f, 1.0f, 0.0f}, {1, 1, 1, 0});
    const char* labels[] = {"shadowed (0)", "half (0.5)", "lit (1)", "no geometry"};
    std::vector<LegendEntry> out;
    for (size_t i = 0; i < 4; ++i) out.push_back({labels[i], {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2], 255}});
    return out;
}

} // namespace

void drawMeasurementsPanel(GuiState& s) {
    const Measurements& m = s.measurements;
    const Viewer& v = *s.viewer;
    ImGui::Text("%d x %d px, %s", v.resolution().x, v.resolution().y, v.active().label.c_str());
    // The GUI runs instrumented so that counters and heat maps stay live; an experiment's tables
    // time the same frames with statistics compiled out, so these times are higher.
    ImGui::TextDisabled("times include statistics (counters, heat maps);");
    ImGui::TextDisabled("shadowlab run times them compiled out");
    plot("##frame", m.frameMs(), "frame");
    const bool wall = v.wallClockStages();
    if (!wall) plot("##gpu", m.algorithmGpuMs(), "GPU");
    plot("##wall", m.algorithmWallMs(), "wall");
    for (const StageSeries& st : m.stages()) {
        ImGui::PushID(st.name.c_str());
        // CPU-only stages (the reference) have no GPU time: plot their CPU time instead. On a CPU
        // rasteriser every stage is timed by its wall clock (Viewer::wallClockStages()).
        bool cpuOnly = st.gpuMs.max() <= 0.0f && st.cpuMs.max() > 0.0f;
        const char* label = wall ? " wall" : cpuOnly ? " cpu" : " gpu";
        plot("##stage", wall || cpuOnly ? st.cpuMs : st.gpuMs, (st.name + label).c_str());
        ImGui::PopID();
    }
    // Read only while this panel is open (see Measurements::record()).
    const ShadowAlgorithm* algorithm = v.algorithm();
    if (!algorithm) return;
    const std::vector<Counter> counters = algorithm->counters();
    if (!counters.empty() && ImGui::BeginTable("counters", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp)) {
        for (const Counter& c : counters) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(c.name.c_str());
            ImGui::TableNextColumn();
            ImGui::Text("%.4g", c.value);
        }
        ImGui::EndTable();
    }
    ImGui::Text("memory %s", formatBytes(algorithm->memoryBytes()).c_str());
    if (const uint64_t overflow = algorithm->overflowCount(); overflow > 0) {
        ImGui::SameLine();
        ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "overflow %llu: image not trustworthy", (unsigned long long)overflow);
    }
}

void drawViewPanel(GuiState& s) {
    ViewImages& views = s.views;
    int mode = int(views.mode);
    ImGui::RadioButton("shaded (1)", &mode, int(ViewMode::Shaded));
    ImGui::SameLine();
    ImGui::RadioButton("visibility (2)", &mode, int(ViewMode::Visibility));
    ImGui::RadioButton("heat map (3)", &mode, int(ViewMode::Heat));
    ImGui::SameLine();
    ImGui::RadioButton("difference (4)", &mode, int(ViewMode::Difference));
    views.mode = ViewMode(mode);

    if (views.mode == ViewMode::Heat && s.viewer->algorithm()) {
        auto debug = s.viewer->algorithm()->debugViews();
        for (int i = 0; i < int(debug.size()); ++i) {
            if (ImGui::RadioButton(debug[size_t(i)].name.c_str(), views.heatIndex == i)) views.heatIndex = i;
            ImGui::SameLine();
        }
        ImGui::NewLine();
    }
    if (views.mode == ViewMode::Difference) {
        if (ImGui::Button("Compute reference (R)")) views.requestReference();
        ImGui::SameLine();
        ImGui::Checkbox("on every change", &views.autoReference);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("re-trace whenever the view changes (CPU: slow)");
        if (views.hasReference() && !views.referenceStale(*s.viewer)) {
            const Accuracy& a = views.accuracy();
            ImGui::Text("mismatch %.3f%% of lit pixels", 100 * a.mismatchRatio);
            ImGui::Text("false lit %.3f%%, false shadowed %.3f%%", 100 * a.falseLit, 100 * a.falseShadowed);
            ImGui::TextWrapped("rmse %.4f over %zu lit px; traced in %.0f ms", a.rmse, a.litPixels, views.referenceMs());
        }
    }
    if (!views.note().empty()) ImGui::TextColored(ImVec4(1, 0.7f, 0.3f, 1), "%s", views.note().c_str());
    ImGui::SliderFloat("render scale", &s.renderScale, kRenderScaleMin, kRenderScaleMax, "%.3f");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("render resolution relative to the viewport's pixels");
    if (ImGui::Button("Screenshot (F12)")) s.screenshotRequest = screenshotFileName();
}

void drawViewLegend(GuiState& s, glm::vec2 viewportMin, glm::vec2 viewportMax) {
    ViewImages& views = s.views;
    if (views.mode == ViewMode::Shaded || !views.note().empty()) return;
    ImGui::SetNextWindowPos(ImVec2(viewportMin.x + 8, viewportMax.y - 8), ImGuiCond_Always, ImVec2(0, 1));
    ImGui::SetNextWindowBgAlpha(0.75f);
    ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                             ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove |
                             ImGuiWindowFlags_NoSavedSettings;
    if (ImGui::Begin("legend", nullptr, flags)) {
        if (views.mode == ViewMode::Visibility) legendRows(visibilityLegend());
        if (views.mode == ViewMode::Difference) legendRows(ViewImages::differenceLegend());
        if (views.mode == ViewMode::Heat) {
            ImGui::Image(ImTextureID(intptr_t(views.heatRamp())), ImVec2(220, 12));
            ImGui::Text("0");
            ImGui::SameLine(180);
            ImGui::Text("%.3g %s", views.heatMax(), views.heatUnit().c_str());
        }
    }
    ImGui::End();
}

} // namespace shadowlab
