// Headless context through EGL with no surface: how GPU servers without a display are reached.
// Prefers a device-enumerated display (one per GPU) and falls back to the default display.
#include "framework/core/Error.h"
#include "framework/gl/GlLoader.h"
#include "framework/gl/GlContext.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

namespace shadowlab {
namespace {

EGLDisplay openDisplay() {
    auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto platformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (queryDevices && platformDisplay) {
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (queryDevices(16, devices, &count) && count > 0) {
            for (EGLint i = 0; i < count; ++i) {
                EGLDisplay d = platformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                EGLint major, minor;
                if (d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor)) return d;
            }
        }
    }
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    EGLint major, minor;
    if (d == EGL_NO_DISPLAY || !eglInitialize(d, &major, &minor)) throw RuntimeError("EGL: no display could be initialised");
    return d;
}

class EglContext : public GlContext {
public:
    explicit EglContext(bool debug) {
        display_ = openDisplay();
        if (!eglBindAPI(EGL_OPENGL_API)) throw RuntimeError("EGL: OpenGL API not available");
        const EGLint configAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config;
        EGLint n = 0;
        if (!eglChooseConfig(display_, configAttribs, &config, 1, &n) || n == 0) throw RuntimeError("EGL: no usable config");
        const EGLint ctxAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                     EGL_CONTEXT_OPENGL_DEBUG, debug ? EGL_TRUE : EGL_FALSE, EGL_NONE};
        context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, ctxAttribs);
        if (context_ == EGL_NO_CONTEXT) throw RuntimeError("EGL: cannot create an OpenGL 4.5 core context");
        // All rendering goes to FBOs, so no surface is needed (EGL_KHR_surfaceless_context).
        if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
            throw RuntimeError("EGL: cannot make the context current without a surface");
        loadGlFunctions([](const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); });
    }
    ~EglContext() override {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
        eglTerminate(display_);
    }
    std::string backend() const override { return "EGL"; }

private:
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
};

} // namespace

std::unique_ptr<GlContext> createHeadlessContext(bool debug) { return std::make_unique<EglContext>(debug); }

} // namespace shadowlab
