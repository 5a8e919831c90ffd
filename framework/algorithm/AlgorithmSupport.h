#pragma once
// What several algorithm plugins share besides the interface: their registry entry, and the
// binding convention of per-pixel compute passes.
#include "framework/algorithm/ShadowAlgorithm.h"
#include "framework/gl/Shader.h"

#include <algorithm>
#include <initializer_list>
#include <type_traits>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

/// The registry entry of algorithm class T, built from its validated ParamValues (and the host's
/// AlgorithmOptions when T takes them: a plugin without statistics of its own need not).
template <class T>
AlgorithmInfo makeAlgorithmInfo(std::string name, std::string summary, std::vector<LightType> lights, bool exact,
                                const ParamSchema& (*schema)()) {
    AlgorithmInfo info;
    info.name = std::move(name);
    info.summary = std::move(summary);
    info.lights = std::move(lights);
    info.exact = exact;
    info.schema = schema;
    info.create = [](const ParamValues& p, const AlgorithmOptions& o) -> std::unique_ptr<ShadowAlgorithm> {
        if constexpr (std::is_constructible_v<T, const ParamValues&, const AlgorithmOptions&>)
            return std::make_unique<T>(p, o);
        else
            return (void)o, std::make_unique<T>(p);
    };
    return info;
}

/// The define every instrumented shader tests (`#if SHADOWLAB_STATISTICS`): 1 gathers the
/// statistics and debug images, 0 (the timed pass) compiles them out. Overflow detection is never
/// behind it.
inline std::pair<std::string, std::string> statisticsDefine(const AlgorithmOptions& o) {
    return {"SHADOWLAB_STATISTICS", o.statistics ? "1" : "0"};
}

/// The define of the SIMD probe (shaders/common/simd_probe.glsl): 1 in instrumented passes where a
/// ballot can be read (ARB_shader_ballot with ARB_gpu_shader_int64), else 0.
inline std::pair<std::string, std::string> simdProbeDefine(const AlgorithmOptions& o) {
    const bool ballot = o.statistics && hasExtension("GL_ARB_shader_ballot") && hasExtension("GL_ARB_gpu_shader_int64");
    return {"SHADOWLAB_SIMD_PROBE", ballot ? "1" : "0"};
}

/// The SIMD probe's counters, per section k named names[k]: `simd_<name>_slots_per_ray`, the lane
/// slots a ray pays there (its subgroup's passes × width, per ray: what the section costs, idle lanes
/// included), and `simd_<name>_utilisation`, the share of them doing work; plus `simd_width`. `wide(i)`
/// reads the kernel's 64-bit counter at word i; nothing is added without a probe (width 0).
template <class Wide>
void appendSimdProbeCounters(std::vector<Counter>& out, std::initializer_list<const char*> names, size_t base,
                             double width, double rays, Wide wide) {
    if (!(width > 0) || !(rays > 0)) return;
    out.push_back({"simd_width", width});
    size_t k = 0;
    for (const char* name : names) {
        const double passes = double(wide(base + 4 * k)), lanes = double(wide(base + 4 * k + 2));
        out.push_back({std::string("simd_") + name + "_slots_per_ray", passes * width / rays});
        out.push_back({std::string("simd_") + name + "_utilisation", passes > 0 ? lanes / (passes * width) : 0.0});
        ++k;
    }
}

/// Per-pixel passes read the G-buffer's world position (texture unit 0) and camera-facing normal
/// (unit 1) and write visibility to image unit 0 (R32F); units above are the algorithm's own.
inline void bindPixelPassInputs(const FrameInputs& f) {
    glBindTextureUnit(0, f.gbuffer.position());
    glBindTextureUnit(1, f.gbuffer.normal());
    glBindImageTexture(0, f.visibility, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
}

/// Binds an R32F debug image (heat map, overflow mask) a per-pixel pass writes.
inline void bindDebugImage(GLuint unit, const GlTexture& image) {
    glBindImageTexture(unit, image.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
}

/// After a per-pixel pass: its images are read by the shading pass and read back, its counters
/// downloaded.
inline void finishPixelPass() {
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                    GL_BUFFER_UPDATE_BARRIER_BIT);
}

/// Uploads the light's sample points (Light::samplePoints(), the reference's samples) as vec4s into
/// `buffer`, growing it when needed; returns how many there are.
inline int uploadLightSamples(GlBuffer& buffer, const Light& light) {
    std::vector<glm::vec4> samples;
    for (glm::vec3 s : light.samplePoints()) samples.emplace_back(s, 1.0f);
    const size_t bytes = samples.size() * sizeof(glm::vec4);
    if (bytes > buffer.size()) buffer = GlBuffer(bytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
    buffer.upload(samples.data(), bytes);
    return int(samples.size());
}

/// A light's samples traced by a per-pixel pass over several dispatches of at most `budget`
/// samples per pixel each, so that none runs into a GPU driver's watchdog (docs/architecture.md,
/// "GPU portability"). Between dispatches each pixel keeps its state in an accumulation image
/// (R32UI, RG32UI instrumented), allocated only when a frame takes more than one dispatch; the
/// shader reads the batch from uSampleFirst / uSampleEnd (bvh_raytrace, line_space, template).
class SampleBatches {
public:
    /// The frame's batches; (re)allocates the image when needed and binds it (or nothing, with a
    /// single dispatch) at image unit `unit`.
    void begin(int sampleCount, int budget, glm::ivec2 resolution, bool statistics, GLuint unit) {
        samples_ = sampleCount;
        budget_ = budget;
        dispatches_ = (sampleCount + budget - 1) / budget;
        const GLenum format = statistics ? GL_RG32UI : GL_R32UI;
        if (dispatches_ > 1 && resolution_ != resolution) {
            accum_ = makeTexture2D(format, resolution.x, resolution.y);
            resolution_ = resolution;
        }
        glBindImageTexture(unit, dispatches_ > 1 ? accum_.id() : 0, 0, GL_FALSE, 0, GL_READ_WRITE, format);
    }
    /// Runs `program` once per batch over `resolution` in groups of `group` (the program's local
    /// size); the next dispatch reads the state the last one wrote and adds to its counters.
    void dispatch(const ShaderProgram& program, glm::ivec2 resolution, glm::ivec2 group = {8, 8}) const {
        for (int first = 0; first < samples_; first += budget_) {
            program.set("uSampleFirst", first);
            program.set("uSampleEnd", std::min(samples_, first + budget_));
            program.dispatch2D(resolution.x, resolution.y, group.x, group.y);
            if (first + budget_ < samples_) glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
        }
    }
    /// Dispatches of the last frame (the counter sample_dispatches).
    int dispatches() const { return dispatches_; }

private:
    GlTexture accum_;
    glm::ivec2 resolution_{0, 0};
    int samples_ = 0, budget_ = 1, dispatches_ = 0;
};

/// A whole per-pixel pass: the inputs above, the debug images on units 1, 2, ... in order, the
/// program in 8×8 groups over the image (its local size), then the barrier.
inline void runPixelPass(const FrameInputs& f, const ShaderProgram& program,
                         std::initializer_list<const GlTexture*> debugImages) {
    bindPixelPassInputs(f);
    GLuint unit = 1;
    for (const GlTexture* image : debugImages) bindDebugImage(unit++, *image);
    const glm::ivec2 r = f.gbuffer.resolution();
    program.dispatch2D(r.x, r.y, 8, 8);
    finishPixelPass();
}

} // namespace shadowlab
