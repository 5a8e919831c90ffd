#pragma once
// The command line of shadowlab-gui. Besides the config to open, options drive the app without a
// person (tests, docs screenshots): they act through the same functions as the widgets.
#include <glm/glm.hpp>

#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

/// Render resolution relative to the viewport's pixels: below 1/8 images are too coarse to judge.
constexpr float kRenderScaleMin = 0.125f, kRenderScaleMax = 1.0f;
/// Window sides (--size, --resize), in screen units: X11 cannot make windows above 32767 (Xlib
/// aborts the process), and above 8192 no GL driver's viewport or texture is sure to follow; the
/// context's own GL_MAX_VIEWPORT_DIMS / GL_MAX_TEXTURE_SIZE are checked once it exists.
constexpr int kWindowSideMin = 64, kWindowSideMax = 8192;

struct GuiOptions {
    std::string config;                 ///< CONFIG.json; empty = the built-in default scene
    std::string algorithm;              ///< --algorithm: config entry id or registered name
    std::vector<std::pair<std::string, std::string>> sets; ///< --set KEY=VALUE, in order
    std::string view;                   ///< --view shaded|visibility|heat|difference
    bool reference = false;             ///< --reference: trace the reference after the first frame
    bool play = false;                  ///< --play
    int startFrame = 0;                 ///< --frame N
    int frames = 0;                     ///< --frames N: exit after N rendered frames (0 = run until closed)
    std::string screenshot;             ///< --screenshot FILE: after the last frame
    std::vector<std::pair<glm::vec3, glm::vec3>> recordKeyframes; ///< --record-keyframes "x,y,z,tx,ty,tz;..."
    float recordStep = 0;               ///< --record-step S (0 = the recorder's default)
    std::string saveConfig;             ///< --save-config FILE
    std::string report;                 ///< --report FILE: JSON log of every rendered frame
    glm::ivec2 windowSize{1280, 800};   ///< --size WxH, screen units
    glm::ivec2 resizeTo{0, 0};          ///< --resize WxH: resize the window after the first frame (tests the reallocation)
    float renderScale = 0;              ///< --render-scale S (0 = the GUI's default)
    bool help = false, version = false;
};

/// Parses argv[1..]; throws InputError (one line) on anything malformed, including an output file
/// (--screenshot, --report, --save-config) that names a directory, a symbolic link, a device or a
/// FIFO, or lies in a folder that does not exist: refused before a window opens or anything is
/// written. With --help (or --version) anywhere, nothing else is checked.
GuiOptions parseGuiOptions(const std::vector<std::string>& args);

/// The window size checked against the GL context's limits (InputError naming the option).
void checkWindowSize(const std::string& option, glm::ivec2 size, int maxViewport, int maxTexture);

extern const char* const kGuiUsage;

} // namespace shadowlab
