// Keyboard shortcuts: one table drives both the handler and the help window (docs/gui.md lists the same).
#include "framework/gui/GuiState.h"

#define GLFW_INCLUDE_NONE // key codes only; GL headers would clash with framework/gl/Gl.h
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>

namespace shadowlab {

namespace {

struct Shortcut {
    int key;           ///< GLFW key code; 0 for mouse or held keys (help only)
    const char* name;
    const char* what;
    void (*run)(GuiState&);
};

void setView(GuiState& s, ViewMode m) { s.views.mode = m; }

const Shortcut kShortcuts[] = {
    {GLFW_KEY_F1, "F1", "show / hide this help", [](GuiState& s) { s.showHelp = !s.showHelp; }},
    {GLFW_KEY_SPACE, "Space", "play / pause the fly-through",
     [](GuiState& s) { s.viewer->playback.playing = !s.viewer->playback.playing; }},
    {GLFW_KEY_LEFT, "Left", "previous fly-through frame",
     [](GuiState& s) { auto& p = s.viewer->playback; p.frame = std::max(0, p.frame - 1); }},
    {GLFW_KEY_RIGHT, "Right", "next fly-through frame",
     [](GuiState& s) { auto& p = s.viewer->playback; p.frame = std::min(s.viewer->config().frames - 1, p.frame + 1); }},
    {GLFW_KEY_HOME, "Home", "first fly-through frame", [](GuiState& s) { s.viewer->playback.frame = 0; }},
    {GLFW_KEY_K, "K", "add a keyframe to the recorded path", [](GuiState& s) { s.recorder.addKeyframe(s.viewer->camera); }},
    {GLFW_KEY_1, "1", "view: shaded", [](GuiState& s) { setView(s, ViewMode::Shaded); }},
    {GLFW_KEY_2, "2", "view: visibility", [](GuiState& s) { setView(s, ViewMode::Visibility); }},
    {GLFW_KEY_3, "3", "view: the algorithm's heat maps", [](GuiState& s) { setView(s, ViewMode::Heat); }},
    {GLFW_KEY_4, "4", "view: difference against the reference", [](GuiState& s) { setView(s, ViewMode::Difference); }},
    {GLFW_KEY_R, "R", "trace the reference for this view (CPU) and show the difference",
     [](GuiState& s) { s.views.requestReference(); setView(s, ViewMode::Difference); }},
    {GLFW_KEY_F12, "F12", "screenshot of the whole window (PNG in the working folder)",
     [](GuiState& s) { s.screenshotRequest = screenshotFileName(); }},
    {GLFW_KEY_ESCAPE, "Esc", "quit", [](GuiState& s) { s.quit = true; }},
    {0, "right-drag", "look around", nullptr},
    {0, "W A S D", "move forward, left, back, right (Shift: faster)", nullptr},
    {0, "Q / E", "move down / up", nullptr},
    {0, "Ctrl + left-drag", "move the light in the image plane", nullptr},
};

} // namespace

void handleShortcuts(GuiState& s, const std::vector<int>& keyPresses) {
    // A text field being edited owns the keyboard.
    if (ImGui::GetIO().WantCaptureKeyboard) return;
    for (int key : keyPresses)
        for (const Shortcut& k : kShortcuts)
            if (k.key == key && k.run) k.run(s);
}

void drawHelpWindow(GuiState& s) {
    if (!s.showHelp) return;
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowPos(ImVec2(display.x * 0.5f, display.y * 0.5f), ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::Begin("Help: keyboard and mouse", &s.showHelp, ImGuiWindowFlags_AlwaysAutoResize)) {
        if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg)) {
            for (const Shortcut& k : kShortcuts) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(k.name);
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(k.what);
            }
            ImGui::EndTable();
        }
        ImGui::TextDisabled("Keys are ignored while a text field is being edited.");
    }
    ImGui::End();
}

} // namespace shadowlab
