#include "framework/gui/GlfwContext.h"

#include "framework/core/Error.h"
#include "framework/gl/GlLoader.h"

// GLFW must not pull in GL/gl.h: the loader's gl* macros (framework/gl/Gl.h) would clash with it.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstdio>
#include <utility>

namespace shadowlab {

namespace {

// GLFW reports failures through a callback; keep the last message for the exception we throw.
// Failures while opening are reported once, by the exception; later ones are printed.
std::string g_lastGlfwError;
bool g_windowOpen = false;

void onGlfwError(int code, const char* description) {
    g_lastGlfwError = description ? description : "unknown";
    if (g_windowOpen) std::fprintf(stderr, "GLFW error %d: %s\n", code, g_lastGlfwError.c_str());
}

} // namespace

GlfwContext::GlfwContext(glm::ivec2 size, const std::string& title, bool vsync) {
    glfwSetErrorCallback(onGlfwError);
    if (!glfwInit()) throw RuntimeError("GLFW: cannot initialise (no display?): " + g_lastGlfwError);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_FALSE); // the shading pass already writes display-space RGBA8
    window_ = glfwCreateWindow(size.x, size.y, title.c_str(), nullptr, nullptr);
    if (!window_) {
        glfwTerminate();
        throw RuntimeError("GLFW: cannot create a window with an OpenGL 4.5 core context: " + g_lastGlfwError);
    }
    g_windowOpen = true;
    // Installed before Dear ImGui's back end, which chains to it.
    glfwSetWindowUserPointer(window_, this);
    glfwSetKeyCallback(window_, onKey);
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(vsync ? 1 : 0);
    loadGlFunctions(reinterpret_cast<void* (*)(const char*)>(glfwGetProcAddress));
}

GlfwContext::~GlfwContext() {
    g_windowOpen = false;
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
}

glm::ivec2 GlfwContext::framebufferSize() const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return {w, h};
}

bool GlfwContext::shouldClose() const { return glfwWindowShouldClose(window_); }

void GlfwContext::pollEvents() { glfwPollEvents(); }

void GlfwContext::onKey(GLFWwindow* window, int key, int, int action, int) {
    auto* self = static_cast<GlfwContext*>(glfwGetWindowUserPointer(window));
    if (self && action == GLFW_PRESS) self->keyPresses_.push_back(key);
}

std::vector<int> GlfwContext::takeKeyPresses() { return std::exchange(keyPresses_, {}); }

void GlfwContext::resize(glm::ivec2 size) { glfwSetWindowSize(window_, size.x, size.y); }

void GlfwContext::waitEvents() { glfwWaitEvents(); }

void GlfwContext::swapBuffers() { glfwSwapBuffers(window_); }

} // namespace shadowlab
