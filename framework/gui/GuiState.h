#pragma once
// Everything the panels read and edit, owned by GuiApp. Panels are free functions over it, one
// file per group, so each stays small and none owns state another needs.
#include "framework/gui/CameraController.h"
#include "framework/gui/GuiOptions.h"
#include "framework/gui/Measurements.h"
#include "framework/gui/ParamWidgets.h"
#include "framework/gui/PathRecorder.h"
#include "framework/gui/ViewImages.h"
#include "framework/gui/Viewer.h"

#include <memory>
#include <string>

namespace shadowlab {

struct GuiState {
    std::unique_ptr<Viewer> viewer;
    ViewImages views;
    Measurements measurements;
    PathRecorder recorder;
    CameraController controller;
    ParamWidgets paramWidgets;

    float panelWidth = 380.0f;  ///< screen units; the viewport is the rest of the window
    float renderScale = 0.5f;   ///< render resolution / viewport pixels (llvmpipe is slow: keep it low)
    bool showHelp = false;
    bool quit = false;
    std::string screenshotRequest; ///< file to write after the next frame is drawn ("" = none)
    std::string savePath = "recorded.json";
    std::string saveName = "recorded";
    std::string message;           ///< last status line (saved files, errors)
    double lastFrameMs = 0;
};

// Panels (each in its own file), drawn inside the side panel window.
void drawAlgorithmPanel(GuiState& s);
void drawCameraPanel(GuiState& s);
void drawLightPanel(GuiState& s);
void drawFlyThroughPanel(GuiState& s);
void drawMeasurementsPanel(GuiState& s);
void drawViewPanel(GuiState& s);
/// Draws the legend of the current view over the viewport's lower-left corner.
void drawViewLegend(GuiState& s, glm::vec2 viewportMin, glm::vec2 viewportMax);

/// Keyboard shortcuts (also listed in the help window and docs/gui.md) for the keys pressed this frame.
void handleShortcuts(GuiState& s, const std::vector<int>& keyPresses);
void drawHelpWindow(GuiState& s);

/// Saves the recorder's path as a config (status in s.message); true on success.
bool saveRecording(GuiState& s, const std::string& file);
/// Makes the recorded path the one the playback follows.
void useRecording(GuiState& s);
/// The default file name of a screenshot taken now.
std::string screenshotFileName();

} // namespace shadowlab
