// Fly-through: playback of the config's camera and light paths, and recording of a new camera path.
#include "framework/gui/GuiState.h"
#include "framework/gui/RecordedConfig.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <ctime>

namespace shadowlab {

bool saveRecording(GuiState& s, const std::string& file) {
    try {
        saveRecordedConfig(*s.viewer, s.recorder.path(), s.saveName, file);
        s.message = "saved " + file + " (" + std::to_string(s.recorder.keyframes().size()) + " keyframes)";
        return true;
    } catch (const std::exception& e) {
        s.message = std::string("not saved: ") + e.what();
        return false;
    }
}

void useRecording(GuiState& s) {
    if (s.recorder.keyframes().empty()) return;
    s.viewer->setCameraPath(s.recorder.path());
    s.viewer->playback.followCamera = true;
}

std::string screenshotFileName() {
    static int count = 0; // several screenshots within one second must not overwrite each other
    char name[64];
    std::time_t t = std::time(nullptr);
    std::strftime(name, sizeof name, "shadowlab-%Y%m%d-%H%M%S", std::localtime(&t));
    return std::string(name) + "-" + std::to_string(++count) + ".png";
}

void drawFlyThroughPanel(GuiState& s) {
    Viewer& v = *s.viewer;
    Playback& p = v.playback;
    const ExperimentConfig& cfg = v.config();
    bool hasPath = !cfg.cameraPath.empty() || !cfg.lightPath.empty();
    if (!hasPath) ImGui::TextDisabled("the config has no camera or light path");

    if (ImGui::Button(p.playing ? "Pause" : "Play")) p.playing = !p.playing;
    ImGui::SameLine();
    if (ImGui::Button("|<")) p.frame = 0;
    ImGui::SameLine();
    ImGui::Checkbox("loop", &p.loop);
    ImGui::SetNextItemWidth(-1);
    // Frame i of the experiment's `frames`: the same sampling of the paths as `shadowlab run`.
    ImGui::SliderInt("##frame", &p.frame, 0, cfg.frames - 1, "frame %d");
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("frame of the experiment's %d; paths are sampled uniformly in time", cfg.frames);
    ImGui::Checkbox("follow the camera path", &p.followCamera);

    ImGui::Separator();
    ImGui::TextUnformatted("Record a camera path");
    if (ImGui::Button("Add keyframe")) s.recorder.addKeyframe(v.camera);
    ImGui::SameLine();
    if (ImGui::Button("Undo")) s.recorder.removeLast();
    ImGui::SameLine();
    if (ImGui::Button("Clear")) s.recorder.clear();
    ImGui::SameLine();
    ImGui::Text("%zu keys", s.recorder.keyframes().size());
    ImGui::SetNextItemWidth(120);
    ImGui::SliderFloat("step (s)", &s.recorder.step, 0.05f, 10.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("path time between keyframes added with the button");
    ImGui::Checkbox("record continuously", &s.recorder.continuous);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("sample the camera while flying, timed by the real clock");
    if (s.recorder.continuous) {
        ImGui::SameLine();
        ImGui::SetNextItemWidth(100);
        ImGui::SliderFloat("every (s)", &s.recorder.interval, 0.05f, 2.0f, "%.2f");
    }
    if (ImGui::Button("Play the recording") && !s.recorder.keyframes().empty()) {
        useRecording(s);
        p.playing = true;
    }
    ImGui::SetNextItemWidth(-80);
    ImGui::InputText("name", &s.saveName);
    ImGui::SetNextItemWidth(-80);
    ImGui::InputText("file", &s.savePath);
    if (ImGui::Button("Save as experiment config")) saveRecording(s, s.savePath);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("scene, recorded camera path, light and the current algorithm's settings;\n"
                          "checked with the runner's parser, then `shadowlab run FILE` runs it");
}

} // namespace shadowlab
