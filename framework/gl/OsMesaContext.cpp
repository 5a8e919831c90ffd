// Headless context through Mesa's OSMesa (llvmpipe on the CPU): the default for experiments and tests.
#include "framework/core/Error.h"
#include "framework/gl/GlLoader.h"
#include "framework/gl/GlContext.h"

#include <GL/osmesa.h>

#include <vector>

namespace shadowlab {
namespace {

class OsMesaContext : public GlContext {
public:
    explicit OsMesaContext(bool debug) {
        const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                               OSMESA_CONTEXT_MAJOR_VERSION, 4, OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
        (void)debug; // OSMesa has no debug flag; KHR_debug output works on any Mesa context.
        ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
        if (!ctx_) throw RuntimeError("OSMesa: cannot create an OpenGL 4.5 core context");
        // All rendering goes to FBOs; the default framebuffer only needs to exist.
        buffer_.resize(4 * 4 * 4);
        if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, 4, 4))
            throw RuntimeError("OSMesa: cannot make the context current");
        loadGlFunctions([](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); });
    }
    ~OsMesaContext() override { OSMesaDestroyContext(ctx_); }
    std::string backend() const override { return "OSMesa"; }

private:
    OSMesaContext ctx_ = nullptr;
    std::vector<unsigned char> buffer_;
};

} // namespace

std::unique_ptr<GlContext> createHeadlessContext(bool debug) { return std::make_unique<OsMesaContext>(debug); }

} // namespace shadowlab
