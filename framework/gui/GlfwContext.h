#pragma once
// A window with an OpenGL 4.5 core context through GLFW: the interactive back end (the headless
// ones are OSMesa and EGL). Only this file and the input code see GLFW; no GL header is included.
#include "framework/gl/GlContext.h"

#include <glm/glm.hpp>

#include <memory>
#include <string>
#include <vector>

struct GLFWwindow;

namespace shadowlab {

class GlfwContext : public GlContext {
public:
    /// Opens a `size` window (screen coordinates) titled `title`, makes its context current and
    /// loads the GL functions; throws RuntimeError when there is no display or no GL 4.5 core.
    GlfwContext(glm::ivec2 size, const std::string& title, bool vsync);
    ~GlfwContext() override;
    GlfwContext(const GlfwContext&) = delete;
    GlfwContext& operator=(const GlfwContext&) = delete;

    std::string backend() const override { return "GLFW"; }
    GLFWwindow* window() const { return window_; }
    glm::ivec2 framebufferSize() const; ///< pixels (differs from the window size on HiDPI screens)
    bool shouldClose() const;
    void pollEvents();
    /// Keys pressed since the last call (GLFW key codes, in order). Dear ImGui 1.86 only sees whether
    /// a key is down at each frame, so a tap shorter than a frame (frames take 100+ ms on llvmpipe)
    /// would be lost to it; shortcuts read this queue instead.
    std::vector<int> takeKeyPresses();
    /// Asks for a new window size (screen units); the framebuffer follows once events are processed.
    void resize(glm::ivec2 size);
    /// Blocks until an event arrives (while minimised, instead of spinning).
    void waitEvents();
    void swapBuffers();

private:
    static void onKey(GLFWwindow* window, int key, int scancode, int action, int mods);
    GLFWwindow* window_ = nullptr;
    std::vector<int> keyPresses_;
};

} // namespace shadowlab
