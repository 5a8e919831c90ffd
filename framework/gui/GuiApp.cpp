#include "framework/gui/GuiApp.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/JsonNode.h"
#include "framework/core/Text.h"
#include "framework/experiment/MemoryPlan.h"
#include "framework/experiment/OutputPlace.h"
#include "framework/scene/SceneConfig.h"
#include "framework/gl/Gl.h"
#include "framework/gui/Automation.h"
#include "framework/gui/DefaultScene.h"
#include "framework/gui/GlfwContext.h"
#include "framework/gui/GuiState.h"

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb_image_write.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace shadowlab {

namespace {

/// Dear ImGui bound to the window for the lifetime of the object.
class ImGuiSession {
public:
    explicit ImGuiSession(GlfwContext& context) {
        IMGUI_CHECKVERSION();
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr; // no imgui.ini dropped in whatever folder the app runs from
        ImGui::StyleColorsDark();
        loadFont();
        ImGui_ImplGlfw_InitForOpenGL(context.window(), true);
        ImGui_ImplOpenGL3_Init("#version 450");
    }
    ~ImGuiSession() {
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }
    ImGuiSession(const ImGuiSession&) = delete;
    static void loadFont() {
        // Units and docs use ×, θ, ², — and ≥, which ImGui's built-in font lacks. DejaVu Sans
        // (Debian's fonts-dejavu-core) has them; without it the built-in font shows '?' instead.
        static const ImWchar ranges[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0x2000, 0x206F, 0x2190, 0x21FF, 0x2200, 0x22FF, 0};
        const char* file = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
        if (std::FILE* f = std::fopen(file, "rb")) {
            std::fclose(f);
            ImGui::GetIO().Fonts->AddFontFromFileTTF(file, 14.0f, nullptr, ranges);
        }
    }
    ImGuiSession& operator=(const ImGuiSession&) = delete;
};

/// The default framebuffer (the whole window, panel included) as a PNG. Encoded in memory and
/// written with writeFileAtomic: a symbolic link, a device or a directory at `file` is refused
/// rather than replaced, and a failed write leaves neither a half PNG nor a temporary.
void writeScreenshot(const std::string& file, glm::ivec2 size) {
    std::vector<unsigned char> rgba(size_t(size.x) * size_t(size.y) * 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, size.x, size.y, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    for (size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255; // the window is opaque, whatever alpha ImGui left
    // GL rows are bottom-up; a PNG's top-down.
    const size_t row = size_t(size.x) * 4;
    std::vector<unsigned char> flipped(rgba.size());
    for (int y = 0; y < size.y; ++y) std::copy_n(rgba.data() + size_t(size.y - 1 - y) * row, row, flipped.data() + size_t(y) * row);
    std::string png;
    const bool ok = stbi_write_png_to_func(
        [](void* context, void* data, int n) { static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(n)); },
        &png, size.x, size.y, 4, flipped.data(), int(row));
    if (!ok) throw RuntimeError("cannot encode the screenshot " + file);
    writeFileAtomic(file, png);
}

void drawSidePanel(GuiState& s) {
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(s.panelWidth, display.y), ImGuiCond_Always);
    ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                             ImGuiWindowFlags_NoBringToFrontOnFocus;
    if (ImGui::Begin("shadowlab", nullptr, flags)) {
        ImGui::PushItemWidth(ImGui::GetContentRegionAvail().x * 0.6f);
        const ImGuiTreeNodeFlags open = ImGuiTreeNodeFlags_DefaultOpen;
        if (ImGui::CollapsingHeader("Algorithm", open)) drawAlgorithmPanel(s);
        if (ImGui::CollapsingHeader("Measurements", open)) drawMeasurementsPanel(s);
        if (ImGui::CollapsingHeader("View", open)) drawViewPanel(s);
        if (ImGui::CollapsingHeader("Fly-through", open)) drawFlyThroughPanel(s);
        if (ImGui::CollapsingHeader("Camera")) drawCameraPanel(s);
        if (ImGui::CollapsingHeader("Light")) drawLightPanel(s);
        ImGui::PopItemWidth();
        if (!s.message.empty()) ImGui::TextWrapped("%s", s.message.c_str());
        ImGui::TextDisabled("F1: keys and mouse");
    }
    ImGui::End();
}

} // namespace

/// An output file of the session (--screenshot, --report, --save-config) must not be one of its
/// inputs (twentieth probe: `--screenshot c.json` replaced the config being read, where
/// `run --force` refuses the same).
static void refuseOutputsOverInputs(const GuiOptions& opts, const Json& source) {
    // The built-in scene has no config file: its scene's files only, relative to this folder.
    std::vector<std::string> inputs = configInputFiles(source, opts.config.empty() ? std::string("built-in") : opts.config);
    if (opts.config.empty()) inputs.erase(inputs.begin());
    const std::pair<const char*, const std::string*> outputs[] = {
        {"--screenshot", &opts.screenshot}, {"--report", &opts.report}, {"--save-config", &opts.saveConfig}};
    for (size_t k = 0; k < std::size(outputs); ++k) {
        const auto& [option, file] = outputs[k];
        if (file->empty()) continue;
        std::error_code ec;
        for (const std::string& input : inputs)
            if (std::filesystem::equivalent(*file, input, ec))
                throw InputError(shortPath(*file), "", std::string(option) + ": the file is an input of this session (" +
                                                           shortPath(input) + "); write it elsewhere");
        // Twenty-fourth probe: --report R/summary.json turned a run's summary into a frame log, and
        // two options naming one file kept only the last one written.
        try {
            OutputPlace::checkFileOutsideOutputs(*file);
        } catch (const InputError& e) {
            throw InputError(shortPath(*file), "", std::string(option) + ": " + e.cause());
        }
        for (size_t j = 0; j < k; ++j)
            if (!outputs[j].second->empty() && std::filesystem::absolute(*outputs[j].second, ec).lexically_normal() ==
                                                   std::filesystem::absolute(*file, ec).lexically_normal())
                throw InputError(shortPath(*file), "", std::string(option) + " and " + outputs[j].first + " name the same file");
    }
}

int runGui(const GuiOptions& opts) {
    // Everything that can be bad input is checked before a window opens (exit 2 even without a display).
    Json source = opts.config.empty() ? defaultGuiConfig() : JsonNode::parseFile(opts.config);
    const std::string name = opts.config.empty() ? "<built-in scene>" : opts.config;
    refuseOutputsOverInputs(opts, source);
    // As run and validate (twentieth probe: the GUI built an 8 M-triangle scene that the plan
    // refuses, and died in Mesa; it drew opaque shadows under translucent casters that validate
    // refuses, and saved that config): the memory plan of the predicted scene before it is made,
    // then the scene. The device's own limits and each algorithm's fit on the scene (which asks
    // the device) are checked once its context exists, before the first frame.
    const ScenePrediction predicted = predictConfigScene(source, name);
    checkMemoryPlan(parseConfig(source, name, false), predicted, DeviceLimits{});
    ExperimentConfig config = parseConfig(source, name);
    AutomationPlan plan = planAutomation(opts, config);

    GlfwContext context(opts.windowSize, "shadowlab — " + config.name, opts.frames == 0);
    {
        GLint viewport[2] = {0, 0}, texture = 0;
        glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &texture);
        checkWindowSize("--size", opts.windowSize, std::min(viewport[0], viewport[1]), texture);
        if (opts.resizeTo.x > 0) checkWindowSize("--resize", opts.resizeTo, std::min(viewport[0], viewport[1]), texture);
    }
    {
        // As run and validate check it, with the chosen algorithm and its --set values (twenty-third
        // probe: a refused line_space pool failed in the build, exit 1).
        const ExperimentConfig started = configAsStarted(config, plan);
        checkMemoryPlan(started, predicted, currentDeviceLimits(predicted.triangles));
        checkAlgorithmsTakeScene(started);
    }
    installGlDebugCallback(true);
    ImGuiSession imgui(context);

    GuiState s;
    s.viewer = std::make_unique<Viewer>(std::move(config), std::move(source));
    if (opts.renderScale > 0) s.renderScale = opts.renderScale;
    FrameReport report;
    applyAutomation(s, opts, plan);
    if (opts.reference) s.views.requestReference();

    using Clock = std::chrono::steady_clock;
    auto last = Clock::now();
    int rendered = 0;
    while (!context.shouldClose() && !s.quit) {
        context.pollEvents();
        glm::ivec2 fb = context.framebufferSize();
        if (fb.x <= 0 || fb.y <= 0) { // minimised: nothing to draw into
            context.waitEvents();
            continue;
        }

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        ImGuiIO& io = ImGui::GetIO();
        const glm::vec2 viewportMin(s.panelWidth, 0.0f), viewportMax(io.DisplaySize.x, io.DisplaySize.y);

        Viewer& v = *s.viewer;
        handleShortcuts(s, context.takeKeyPresses());
        float radius = std::max(v.sceneGpu().bounds().radius(), 1e-3f);
        if (s.controller.updateCamera(v.camera, radius, io.DeltaTime)) v.playback.followCamera = false;
        if (s.controller.updateLight(v.light, v.camera, viewportMax.y - viewportMin.y)) v.playback.followLight = false;
        s.recorder.update(v.camera, io.DeltaTime);
        drawSidePanel(s);
        drawHelpWindow(s);

        // Resolution follows the viewport (window resize reallocates G-buffer, shading, visibility, algorithm).
        glm::vec2 pixels = (viewportMax - viewportMin) * glm::vec2(io.DisplayFramebufferScale.x, io.DisplayFramebufferScale.y);
        v.setResolution(glm::max(glm::ivec2(glm::round(pixels * s.renderScale)), glm::ivec2(8)));
        v.applyPlayback();
        v.renderFrame();
        auto now = Clock::now();
        s.lastFrameMs = std::chrono::duration<double, std::milli>(now - last).count();
        last = now;
        s.measurements.record(v.lastStages(), v.lastAlgorithmWallMs(), s.lastFrameMs);
        GLuint image = s.views.update(v);
        // GL textures are bottom-up: flip v so the image is upright.
        ImGui::GetBackgroundDrawList()->AddImage(ImTextureID(intptr_t(image)), ImVec2(viewportMin.x, viewportMin.y),
                                                 ImVec2(viewportMax.x, viewportMax.y), ImVec2(0, 1), ImVec2(1, 0));
        drawViewLegend(s, viewportMin, viewportMax);
        if (!opts.report.empty()) report.add(v); // frames are kept only to be written
        v.stepPlayback();

        ImGui::Render();
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, fb.x, fb.y);
        glClearColor(0.1f, 0.1f, 0.1f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        ++rendered;
        bool lastFrame = opts.frames > 0 && rendered >= opts.frames;
        if (lastFrame && !opts.screenshot.empty()) s.screenshotRequest = opts.screenshot;
        if (!s.screenshotRequest.empty()) {
            try {
                writeScreenshot(s.screenshotRequest, fb);
                s.message = "wrote " + s.screenshotRequest;
            } catch (const std::exception& e) {
                if (lastFrame) throw; // automation: a missing screenshot is a failure
                s.message = e.what(); // F12 onto a link or a folder: say so, keep the session
            }
            s.screenshotRequest.clear();
        }
        context.swapBuffers();
        if (rendered == 1 && opts.resizeTo.x > 0) context.resize(opts.resizeTo);
        if (lastFrame) break;
    }
    if (!opts.report.empty()) report.write(opts.report, s);
    if (glErrorCount() > 0) {
        std::fprintf(stderr, "shadowlab-gui: %d OpenGL errors were reported\n", glErrorCount());
        return 1;
    }
    return 0;
}

} // namespace shadowlab
