#pragma once
// A current OpenGL 4.5 core context. Headless back ends (OSMesa, EGL) are chosen at link time:
// each executable links one implementation of createHeadlessContext().
#include <memory>
#include <string>

namespace shadowlab {

class GlContext {
public:
    virtual ~GlContext() = default;
    /// "OSMesa", "EGL" or "GLFW".
    virtual std::string backend() const = 0;
};

/// Creates and makes current a headless GL 4.5 core context; throws RuntimeError on failure.
/// `debug` requests a debug context (tests use it to fail on any GL error).
std::unique_ptr<GlContext> createHeadlessContext(bool debug);

/// The GL_RENDERER / GL_VERSION strings of the current context.
std::string glRendererString();
std::string glVersionString();

/// Installs a KHR_debug callback that records every GL error (and optionally warnings);
/// glErrorCount() returns how many were seen, glLastErrors() their messages.
void installGlDebugCallback(bool printToStderr);
int glErrorCount();
std::string glLastErrors();
void resetGlErrors();

/// Throws RuntimeError naming `what` when glGetError() reports an error.
void checkGl(const char* what);

} // namespace shadowlab
