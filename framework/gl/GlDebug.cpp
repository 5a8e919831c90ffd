#include "framework/core/Error.h"
#include "framework/gl/Gl.h"
#include "framework/gl/GlContext.h"

#include <cstdio>
#include <mutex>
#include <string>

namespace shadowlab {
namespace {

std::mutex g_mutex;
int g_errors = 0;
std::string g_messages;
bool g_print = false;

void APIENTRY onDebugMessage(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                               const GLchar* message, const void*) {
    (void)source; (void)id; (void)length;
    if (type != GL_DEBUG_TYPE_ERROR && severity != GL_DEBUG_SEVERITY_HIGH) return;
    std::lock_guard<std::mutex> lock(g_mutex);
    ++g_errors;
    if (g_messages.size() < 4096) g_messages += std::string(message) + "\n";
    if (g_print) std::fprintf(stderr, "GL error: %s\n", message);
}

} // namespace

std::string glRendererString() {
    const GLubyte* s = glGetString(GL_RENDERER);
    return s ? reinterpret_cast<const char*>(s) : "unknown";
}

std::string glVersionString() {
    const GLubyte* s = glGetString(GL_VERSION);
    return s ? reinterpret_cast<const char*>(s) : "unknown";
}

void installGlDebugCallback(bool printToStderr) {
    g_print = printToStderr;
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(onDebugMessage, nullptr);
}

int glErrorCount() {
    std::lock_guard<std::mutex> lock(g_mutex);
    return g_errors;
}

std::string glLastErrors() {
    std::lock_guard<std::mutex> lock(g_mutex);
    return g_messages;
}

void resetGlErrors() {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_errors = 0;
    g_messages.clear();
}

void checkGl(const char* what) {
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "0x%04x", e);
        throw RuntimeError(std::string("OpenGL error ") + buf + " in " + what);
    }
}

} // namespace shadowlab
