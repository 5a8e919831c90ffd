// The plugin: per scene the edge adjacency (EdgeAdjacency.h); per frame four stages:
// `silhouettes` (facing.comp, silhouettes.comp: which way each volume is wound, which edges bound
// the union and how often), `volumes` (with the hardware depth test, depth.frag first: the
// G-buffer's depth at the test points; then (volume.vert/.frag: quads and caps counted on the stencil and in an
// exact R32F count, close calls marked) and `resolve` (resolve.comp: count to visibility, close
// calls listed) and `close_calls` (close_rays.comp: the listed pixels by the reference's ray, traced
// through the scene's BVH, framework/accel).
#include "algorithms/shadow_volumes/ShadowVolumes.h"

#include "algorithms/shadow_volumes/EdgeAdjacency.h"
#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/PixelList.h"
#include "framework/algorithm/SharedParams.h"
#include "framework/accel/SceneBvh.h"
#include "framework/core/CheckedMath.h"
#include "framework/core/Error.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"
#include "shaders/shadow_volumes/layout.glsl"

#include <cmath>

namespace shadowlab {
namespace {

enum class SvMethod { Zfail, Zpass };
enum class SvDepthTest { Analytic, Hardware };
enum class SvVolumes { AllTriangles, LightFacing };

struct ShadowVolumesParams {
    SvMethod method;
    SvDepthTest depthTest;
    SvVolumes volumes;
    bool closeCalls;
    float rayOffset;
};

const ParamStruct<ShadowVolumesParams>& shadowVolumesParams() {
    using P = ShadowVolumesParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        // zfail by default: exact wherever the eye is (Carmack's reverse, with caps). zpass counts
        // the faces in front of the point and needs no caps, the papers' fast setting, but every
        // pixel is wrong whose view ray starts inside a volume (tests/ShadowVolumesGLTest.cpp).
        .choice("method", &P::method, SvMethod::Zfail, {{"zfail", SvMethod::Zfail}, {"zpass", SvMethod::Zpass}},
                "count the volume faces behind the point, with caps (zfail: exact with the eye in shadow) or in "
                "front of it, without caps (zpass: cheaper, wrong where the eye is inside a volume)",
                ParamChange::Recompile)
        // analytic by default: the depth buffer's resolution far from the near plane makes every
        // face within centimetres of a point a close call on a big scene (13 % of the peer engine
        // orbit's pixels at 256², against 0.1 % analytic; docs/algorithms/shadow_volumes.md).
        .choice("depth_test", &P::depthTest, SvDepthTest::Analytic,
                {{"analytic", SvDepthTest::Analytic}, {"hardware", SvDepthTest::Hardware}},
                "which faces count: those the view ray meets beyond the point, decided in world space at float "
                "precision (analytic) or by the depth test against the G-buffer's depth (hardware: the papers')",
                ParamChange::Recompile)
        // all_triangles by default: every triangle bounds a volume (flipped when it faces away), so
        // open meshes, soups and two-sided planes cast as the reference sees them; light_facing is
        // the classic setting, half the caps and counts, exact for closed meshes only.
        .choice("volumes", &P::volumes, SvVolumes::AllTriangles,
                {{"all_triangles", SvVolumes::AllTriangles}, {"light_facing", SvVolumes::LightFacing}},
                "which triangles bound a shadow volume: every one, wound to face the light (exact for open meshes "
                "and soups), or only those facing the light (the classic setting: exact for closed meshes only)",
                ParamChange::Recompile)
        .boolean("close_calls", &P::closeCalls, true,
                 "decide by the reference's ray test the pixels where a volume face passes too near the point (or "
                 "the rasteriser's rounding could have given the pixel to its neighbour); off = the counts decide "
                 "every pixel (the papers' method)",
                 ParamChange::Recompile)
        .apply(rayOffsetRow(&P::rayOffset));
    return s;
}

const ParamSchema& shadowVolumesSchema() { return shadowVolumesParams().schema(); }

/// The GL state of one volume pass, set and put back as GBuffer and the shading pass expect it.
struct VolumeState {
    VolumeState(bool zfail, bool analytic) {
        // Analytic: the fragment shader discards what does not count, and every other fragment
        // reaches the stencil's depth-pass op with the depth test off.
        if (analytic) glDisable(GL_DEPTH_TEST);
        else glEnable(GL_DEPTH_TEST);
        glDepthMask(GL_FALSE);
        // Counted are the fragments that pass: ZFAIL's "behind the point" as GEQUAL (the classic
        // depth-fail ops under LESS count the same fragments), so the count attachment, which only
        // passing fragments reach, sees exactly what the stencil sees.
        glDepthFunc(zfail ? GL_GEQUAL : GL_LESS);
        glEnable(GL_DEPTH_CLAMP);
        glDisable(GL_CULL_FACE);
        glEnable(GL_STENCIL_TEST);
        glStencilFunc(GL_ALWAYS, 0, 0xFF);
        glStencilMask(0xFF);
        glStencilOpSeparate(GL_BACK, GL_KEEP, GL_KEEP, zfail ? GL_INCR_WRAP : GL_DECR_WRAP);
        glStencilOpSeparate(GL_FRONT, GL_KEEP, GL_KEEP, zfail ? GL_DECR_WRAP : GL_INCR_WRAP);
        glEnablei(GL_BLEND, 0);
        glBlendFunci(0, GL_ONE, GL_ONE);
        glBlendEquationi(0, GL_FUNC_ADD);
    }
    ~VolumeState() {
        glDisablei(GL_BLEND, 0);
        glDisable(GL_STENCIL_TEST);
        glDisable(GL_DEPTH_CLAMP);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }
    VolumeState(const VolumeState&) = delete;
    VolumeState& operator=(const VolumeState&) = delete;
};

class ShadowVolumes final : public ShadowAlgorithm {
public:
    ShadowVolumes(const ParamValues& p, const AlgorithmOptions& o) : p_(shadowVolumesParams().read(p)), options_(o) {
        subpixelBits_ = subpixelBits();
        compile();
        GLuint vao = 0;
        glCreateVertexArrays(1, &vao);
        emptyVao_ = GlVertexArray(vao);
    }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        const EdgeAdjacency adj = buildEdgeAdjacency(scene.cpu());
        edges_ = adj.edgeCount();
        maxSides_ = adj.maxSides;
        openEdges_ = adj.openEdges;
        nonManifold_ = adj.nonManifold;
        capacity_ = std::max<size_t>(adj.sides.size(), 1);
        // Empty buffers cannot be bound: one word stands in (no edge reads it).
        sides_ = GlBuffer::fromVector(adj.sides.empty() ? std::vector<uint32_t>{0u} : adj.sides, 0);
        first_ = GlBuffer::fromVector(adj.first.empty() ? std::vector<uint32_t>{0u} : adj.first, 0);
        facing_ = GlBuffer(std::max<size_t>(scene.triangleCount(), 1) * sizeof(int32_t), nullptr, 0);
        records_ = GlBuffer(capacity_ * sizeof(uint32_t), nullptr, 0);
        draw_ = GlBuffer(SV_DRAW_WORDS * sizeof(uint32_t), nullptr, GL_DYNAMIC_STORAGE_BIT);
        facingTexels_ = makeBufferTexture(facing_, GL_R32I, 4, "shadow_volumes' facing signs");
        recordTexels_ = makeBufferTexture(records_, GL_R32UI, 4, "shadow_volumes' silhouette records");
        sideTexels_ = makeBufferTexture(sides_, GL_R32UI, 4, "shadow_volumes' edge sides");
        // The close calls' rays trace through the scene's BVH (leaves of 4, the default build).
        bvh_.build(scene, bvh::BuildOptions{}, maxShaderStorageBlockBytes(), "shadow_volumes");
        counters_.allocate();
    }

    // Moving parts: the silhouettes and volumes follow the posed scene buffers by themselves; the
    // close calls' BVH is refitted to them.
    void sceneMoved(const FrameInputs& f) override { bvh_.refit(*scene_, f.timer); }

    void resize(glm::ivec2 r) override {
        depthStencil_ = makeTexture2D(GL_DEPTH32F_STENCIL8, r.x, r.y);
        glTextureParameteri(depthStencil_.id(), GL_DEPTH_STENCIL_TEXTURE_MODE, GL_STENCIL_INDEX);
        count_ = makeTexture2D(GL_R32F, r.x, r.y);
        close_ = makeTexture2D(GL_R32UI, r.x, r.y);
        other_ = makeTexture2D(GL_R32I, r.x, r.y);
        closeList_.resize(r);
        if (options_.statistics) {
            closeView_ = makeTexture2D(GL_R32F, r.x, r.y);
            countView_ = makeTexture2D(GL_R32F, r.x, r.y);
        }
        GLuint fbo = 0;
        glCreateFramebuffers(1, &fbo);
        fbo_ = GlFramebuffer(fbo);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, count_.id(), 0);
        glNamedFramebufferTexture(fbo, GL_DEPTH_STENCIL_ATTACHMENT, depthStencil_.id(), 0);
        if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw RuntimeError("shadow_volumes: the stencil framebuffer is incomplete");
        resolution_ = r;
    }

    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = shadowVolumesParams().read(p);
        if (change == ParamChange::Recompile) compile();
    }

    void computeVisibility(const FrameInputs& f) override {
        counters_.clear();
        scene_->bindStorage();
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, SV_COUNTER_BINDING);
        const float offset = rayOffsetLength(p_.rayOffset, *scene_); // the reference's, in world units
        findSilhouettes(f);
        drawVolumes(f, offset);
        resolve(f, offset);
        traceCloseCalls(f, offset);
        counters_.markStale();
        zfailLast_ = p_.method == SvMethod::Zfail;
    }

    std::vector<Counter> counters() const override {
        const auto& c = counters_.read();
        std::vector<Counter> out = {{"silhouette_edges", double(c[SV_C_SILHOUETTES])},
                                    {"silhouette_quads", double(c[SV_C_QUADS])},
                                    {"cap_triangles", zfailLast_ ? 2.0 * double(scene_->triangleCount()) : 0.0},
                                    {"close_call_pixels", double(c[SV_C_CLOSE_PIXELS])},
                                    {"stencil_wrapped_pixels", double(c[SV_C_WRAPPED])},
                                    {"loop_capped_pixels", double(c[SV_C_CUT_LOOPS])},
                                    {"stack_overflow_pixels", double(c[SV_C_STACK_OVERFLOW])},
                                    {"eye_in_volumes", double(c[SV_C_EYE])},
                                    {"inconsistent_pixels", double(c[SV_C_INCONSISTENT])},
                                    {"open_edges", double(openEdges_)},
                                    {"non_manifold_edges", double(nonManifold_)},
                                    {"max_triangles_per_edge", double(maxSides_)},
                                    {"subpixel_bits", double(subpixelBits_)}};
        if (options_.statistics) {
            const double pixels = double(resolution_.x) * double(resolution_.y);
            const double fragments = double(counters_.wide(SV_C_FRAGMENTS_LO));
            const double close = double(c[SV_C_CLOSE_PIXELS]);
            out.push_back({"volume_fragments", fragments});
            out.push_back({"fill_per_pixel", pixels > 0 ? fragments / pixels : 0.0});
            out.push_back({"close_call_tests_mean", close > 0 ? double(counters_.wide(SV_C_CLOSE_TESTS_LO)) / close : 0.0});
            out.push_back({"lit_pixels", double(c[SV_C_LIT])});
        }
        return out;
    }
    std::vector<DebugView> debugViews() const override {
        if (!options_.statistics) return {};
        return {{"close_calls", closeView_.id(), 1.0f, "decided by the ray"}, {"volume_count", countView_.id(), 0.0f, "volumes"}};
    }
    size_t memoryBytes() const override {
        const size_t pixels = size_t(resolution_.x) * size_t(resolution_.y);
        return sides_.size() + first_.size() + facing_.size() + records_.size() + draw_.size() + counters_.size() +
               bvh_.gpu().bytes() + pixels * (8 + 4 + 4 + 4 + 4); // depth-stencil, count, other side, close-call image and list
    }
    uint64_t overflowCount() const override {
        const auto& c = counters_.read();
        return uint64_t(c[SV_C_RECORD_OVERFLOW]) + c[SV_C_WRAPPED] + c[SV_C_CUT_LOOPS] + c[SV_C_STACK_OVERFLOW];
    }

private:
    /// Each triangle's facing, then the silhouette edges (with their multiplicity) written as the
    /// indirect draw's quads; with the analytic ZFAIL check, the volumes holding the eye.
    void findSilhouettes(const FrameInputs& f) {
        const unsigned triangles = unsigned(scene_->triangleCount());
        f.timer.begin("silhouettes");
        const uint32_t command[SV_DRAW_WORDS] = {6u, 0u, 0u, 0u, 8u, 0u, 0u, 0u, 2u, 0u, 0u, 0u}; // faces, border lines, corners
        glNamedBufferSubData(draw_.id(), 0, sizeof(command), command);
        facing_.bindBase(GL_SHADER_STORAGE_BUFFER, SV_FACING_BINDING);
        sides_.bindBase(GL_SHADER_STORAGE_BUFFER, SV_SIDES_BINDING);
        first_.bindBase(GL_SHADER_STORAGE_BUFFER, SV_FIRST_BINDING);
        records_.bindBase(GL_SHADER_STORAGE_BUFFER, SV_RECORDS_BINDING);
        draw_.bindBase(GL_SHADER_STORAGE_BUFFER, SV_DRAW_BINDING);
        setLightUniforms(facingPass_, f.light);
        facingPass_.set("uTriangleCount", triangles);
        facingPass_.dispatchLinear(std::max(1u, triangles), 64);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        silhouettePass_.set("uEdgeCount", unsigned(edges_));
        silhouettePass_.set("uCapacity", unsigned(capacity_));
        silhouettePass_.dispatchLinear(std::max<size_t>(1, edges_), 64);
        if (checked()) {
            // The volumes holding the eye, for the resolve pass's check.
            setLightUniforms(eyePass_, f.light);
            eyePass_.set("uEye", f.camera.position);
            eyePass_.use();
            for (unsigned first = 0; first < triangles; first += SV_EYE_RANGE) {
                eyePass_.set("uFirst", first);
                eyePass_.set("uEnd", unsigned(std::min<size_t>(triangles, size_t(first) + SV_EYE_RANGE)));
                glDispatchCompute(1, 1, 1);
            }
        }
        glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
        f.timer.end();
    }

    /// The stencil (and count) targets cleared, the G-buffer bound, with the hardware depth test
    /// its depth buffer written, and the volumes drawn: one stage.
    void drawVolumes(const FrameInputs& f, float offset) {
        const bool zfail = p_.method == SvMethod::Zfail, analytic = p_.depthTest == SvDepthTest::Analytic;
        const unsigned triangles = unsigned(scene_->triangleCount());
        const glm::ivec2 r = f.gbuffer.resolution();
        f.timer.begin("volumes");
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
        glViewport(0, 0, r.x, r.y);
        const float zero[4] = {0, 0, 0, 0};
        glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 0, zero);
        glClearNamedFramebufferfi(fbo_.id(), GL_DEPTH_STENCIL, 0, 1.0f, 0);
        const GLuint noClose = 0;
        glClearTexImage(close_.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &noClose);
        const GLint noFaces = 0;
        if (checked()) glClearTexImage(other_.id(), 0, GL_RED_INTEGER, GL_INT, &noFaces);
        glBindTextureUnit(0, f.gbuffer.position());
        glBindTextureUnit(1, f.gbuffer.normal());
        glBindTextureUnit(SV_DEPTH_UNIT, f.gbuffer.depth());
        glBindTextureUnit(SV_TRIANGLE_ID_UNIT, f.gbuffer.triangleId());
        glBindVertexArray(emptyVao_.id());
        if (!analytic) {
            // The hardware depth test's buffer: the G-buffer's depth at the test points.
            glEnable(GL_DEPTH_TEST);
            glDepthFunc(GL_ALWAYS);
            glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
            depthPass_.set("uViewProj", f.gbuffer.viewProjection());
            depthPass_.set("uEye", f.camera.position);
            depthPass_.set("uRayOffset", offset);
            depthPass_.use();
            glDrawArrays(GL_TRIANGLES, 0, 3);
            glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        }
        {
            VolumeState state(zfail, analytic);
            glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
            glBindTextureUnit(SV_FACING_UNIT, facingTexels_.id());
            glBindTextureUnit(SV_RECORDS_UNIT, recordTexels_.id());
            glBindTextureUnit(SV_SIDES_UNIT, sideTexels_.id());
            glBindImageTexture(SV_CLOSE_IMAGE, close_.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
            if (checked()) glBindImageTexture(SV_OTHER_IMAGE, other_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32I);
            setLightUniforms(volumePass_, f.light);
            volumePass_.set("uViewProj", f.gbuffer.viewProjection());
            volumePass_.set("uInverseViewProj", glm::inverse(f.gbuffer.viewProjection()));
            volumePass_.set("uCapacity", unsigned(capacity_));
            volumePass_.set("uEye", f.camera.position);
            volumePass_.set("uForward", glm::normalize(f.camera.target - f.camera.position));
            const float n = f.camera.nearPlane, fa = f.camera.farPlane;
            volumePass_.set("uDepthScale", (fa - n) / (fa * n));
            volumePass_.set("uPixelAngle", 2.0f * std::tan(glm::radians(f.camera.fovYDeg) * 0.5f) / float(r.y));
            volumePass_.set("uBorderMargin", borderMargin());
            volumePass_.set("uRayOffset", offset);
            volumePass_.set("uCloseCall", closeCallLength());
            volumePass_.set("uCoordinateTolerance", coordinateTolerance(f.camera.position));
            volumePass_.set("uCountSign", zfail ? -1.0f : 1.0f);
            volumePass_.set("uCountBehind", zfail ? 1 : 0);
            volumePass_.set("uPass", 0);
            volumePass_.set("uBorder", 0);
            volumePass_.use();
            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, draw_.id());
            glDrawArraysIndirect(GL_TRIANGLES, nullptr);
            glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
            if (zfail && triangles > 0) {
                volumePass_.set("uPass", 1);
                glDrawArrays(GL_TRIANGLES, 0, GLsizei(6u * triangles));
            }
            if (p_.closeCalls) drawBorders(f, offset, triangles);
            glBindVertexArray(0);
        }
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
        f.timer.end();
    }

    /// The border pass (volume.frag, SV_BORDER_PASS): every face's borders as lines and its finite
    /// corners as points, counting nothing, each fragment marking the pixels around it that the
    /// face separates from their test points. Inside the volume pass's state, with the stencil, the
    /// count and the depth test off.
    void drawBorders(const FrameInputs& f, float offset, unsigned triangles) {
        glDisable(GL_STENCIL_TEST);
        glDisable(GL_DEPTH_TEST);
        glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        setLightUniforms(borderPass_, f.light);
        borderPass_.set("uViewProj", f.gbuffer.viewProjection());
        borderPass_.set("uCapacity", unsigned(capacity_));
        borderPass_.set("uEye", f.camera.position);
        borderPass_.set("uRayOffset", offset);
        borderPass_.set("uCloseCall", closeCallLength());
        borderPass_.use();
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, draw_.id());
        borderPass_.set("uPass", 0);
        borderPass_.set("uBorder", 1);
        glDrawArraysIndirect(GL_LINES, reinterpret_cast<const void*>(4 * sizeof(uint32_t)));
        borderPass_.set("uBorder", 2);
        glDrawArraysIndirect(GL_POINTS, reinterpret_cast<const void*>(8 * sizeof(uint32_t)));
        glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
        if (triangles > 0) {
            borderPass_.set("uPass", 1);
            borderPass_.set("uBorder", 1);
            glDrawArrays(GL_LINES, 0, GLsizei(6u * triangles));
            borderPass_.set("uBorder", 2);
            glDrawArrays(GL_POINTS, 0, GLsizei(3u * triangles));
        }
        glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }

    /// Each pixel's count read: shadowed, lit, or listed as a close call.
    void resolve(const FrameInputs& f, float offset) {
        f.timer.begin("resolve");
        glBindTextureUnit(SV_STENCIL_UNIT, depthStencil_.id());
        glBindTextureUnit(SV_COUNT_UNIT, count_.id());
        glBindImageTexture(SV_CLOSE_IMAGE, close_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
        if (checked()) glBindImageTexture(SV_OTHER_IMAGE, other_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32I);
        closeList_.begin();
        setLightUniforms(resolvePass_, f.light);
        resolvePass_.set("uRayOffset", offset);
        resolvePass_.set("uCloseCall", closeCallLength());
        if (p_.closeCalls) resolvePass_.set("uViewProj", f.gbuffer.viewProjection());
        scene_->bindStorage();  // the own triangle's plane (resolve.comp)
        glBindTextureUnit(SV_TRIANGLE_ID_UNIT, f.gbuffer.triangleId());
        if (options_.statistics) runPixelPass(f, resolvePass_, {&closeView_, &countView_});
        else runPixelPass(f, resolvePass_, {});
        f.timer.end();
    }

    /// The close calls: one ray each through the BVH, an indirect dispatch sized by the list.
    void traceCloseCalls(const FrameInputs& f, float offset) {
        f.timer.begin("close_calls");
        bindPixelPassInputs(f);
        bvh_.gpu().bind(SV_BVH_NODE_UNIT, SV_BVH_TRI_UNIT);
        setLightUniforms(closeRayPass_, f.light);
        closeRayPass_.set("uRayOffset", offset);
        closeRayPass_.set("uBvhStepCap", unsigned(bvh_.gpu().stepCap));
        closeList_.dispatch(closeRayPass_);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        finishPixelPass();
        f.timer.end();
    }

    /// The rasteriser's subpixel precision (GL_SUBPIXEL_BITS; GL guarantees 4, today's GPUs and
    /// llvmpipe have 8). The test fault SHADOWLAB_FAULT_SUBPIXEL_BITS stands for a device with 4.
    static int subpixelBits() {
        GLint bits = 0;
        glGetIntegerv(GL_SUBPIXEL_BITS, &bits);
        if (shaderFaultActive("SHADOWLAB_FAULT_SUBPIXEL_BITS")) bits = 4;
        if (bits < 4)
            throw RuntimeError("shadow_volumes: the GL reports " + std::to_string(bits) +
                               " subpixel bits, fewer than the 4 GL guarantees: its rasteriser's rounding is unknown");
        return bits;
    }
    /// How near a face's border, in pixels, the rasteriser may hand the pixel to the neighbour
    /// across it (volume.frag): four steps of its subpixel grid (1/64 of a pixel at 8 bits, 1/4 at 4).
    float borderMargin() const { return std::ldexp(4.0f, -subpixelBits_); }

    // The plane tests' own rounding, in world units: 2e-6 of the scene's size (the depth buffer's,
    // far coarser, is added per pixel by volume.frag).
    float closeCallLength() const {
        const Bounds& b = scene_->bounds();
        return b.empty() ? 2e-6f : 2e-6f * std::max(b.radius(), glm::length(b.center()));
    }

    /// The rounding of world coordinates that a depth projected from them carries, in world units:
    /// 16 float steps of the largest coordinate of the scene and the eye (volume.frag, hardware,
    /// magnifies it by the projection's z / near).
    float coordinateTolerance(glm::vec3 eye) const {
        const Bounds& b = scene_->bounds();
        glm::vec3 largest = glm::abs(eye);
        if (!b.empty()) largest = glm::max(largest, glm::max(glm::abs(b.min), glm::abs(b.max)));
        return std::ldexp(16.0f * std::max(largest.x, std::max(largest.y, largest.z)), -23);
    }

    /// The two-sided count check (volume.frag): analytic ZFAIL, the only mode that draws every face
    /// and classifies both sides of the test point.
    bool checked() const { return p_.depthTest == SvDepthTest::Analytic && p_.method == SvMethod::Zfail; }

    void compile() {
        const auto instr = statisticsDefine(options_);
        const std::pair<std::string, std::string> check{"SV_CHECK", checked() ? "1" : "0"};
        const std::pair<std::string, std::string> facingOnly{"SV_LIGHT_FACING_ONLY", p_.volumes == SvVolumes::LightFacing ? "1" : "0"};
        facingPass_ = ShaderProgram::compute("shadow_volumes/facing.comp", {facingOnly, {"SCENE_POSITION_TEXELS", "1"}});
        silhouettePass_ = ShaderProgram::compute("shadow_volumes/silhouettes.comp", {});
        depthPass_ = ShaderProgram::graphics("shading/fullscreen.vert", "shadow_volumes/depth.frag", {});
        volumePass_ = ShaderProgram::graphics("shadow_volumes/volume.vert", "shadow_volumes/volume.frag",
                                              {instr, check, {"SV_CLOSE_CALLS", p_.closeCalls ? "1" : "0"},
                                               {"SV_ANALYTIC", p_.depthTest == SvDepthTest::Analytic ? "1" : "0"}});
        if (p_.closeCalls)
            borderPass_ = ShaderProgram::graphics("shadow_volumes/volume.vert", "shadow_volumes/volume.frag",
                                                  {{"SV_CLOSE_CALLS", "1"}, {"SV_BORDER_PASS", "1"}, {"SV_ANALYTIC", "1"}});
        resolvePass_ = ShaderProgram::compute("shadow_volumes/resolve.comp",
                                              {instr, check, {"SV_CLOSE_CALLS", p_.closeCalls ? "1" : "0"}});
        eyePass_ = ShaderProgram::compute("shadow_volumes/eye_count.comp", {{"SCENE_POSITION_TEXELS", "1"}});
        closeList_.compile(SV_CLOSE_LIST_BINDING, SV_CLOSE_ARGS_BINDING);
        closeRayPass_ = ShaderProgram::compute("shadow_volumes/close_rays.comp", {instr});
    }

    ShadowVolumesParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    size_t edges_ = 0, capacity_ = 1, maxSides_ = 0, openEdges_ = 0, nonManifold_ = 0;
    glm::ivec2 resolution_{0};
    int subpixelBits_ = 8;
    bool zfailLast_ = true;
    ShaderProgram eyePass_, facingPass_, silhouettePass_, depthPass_, volumePass_, borderPass_, resolvePass_, closeRayPass_;
    GlBuffer sides_, first_, facing_, records_, draw_;
    PixelList closeList_;
    bvh::SceneBvh bvh_; ///< the close calls' rays trace through it
    GlTexture facingTexels_, recordTexels_, sideTexels_, depthStencil_, count_, close_, other_, closeView_, countView_;
    GlFramebuffer fbo_;
    GlVertexArray emptyVao_;
    GpuCounters<SV_COUNTER_WORDS> counters_;
};

} // namespace

/// Edge sides and silhouette records (12 bytes a triangle each, storage blocks), the first side of
/// each edge and the facing sign (4 each), the close calls' BVH (48 bytes a triangle in leaf order,
/// nodes of 64 bytes for every two, bvh_raytrace's default leaves of 4; 152 bytes a triangle more
/// held for its refits when the scene moves), 24 bytes a pixel; the BVH's build peaks at ~152 bytes
/// a triangle on the host, the edge adjacency's at ~130. The triangles are read through the scene
/// positions' view.
Footprint shadowVolumesFootprint(const FootprintQuery& q) {
    Footprint f;
    const size_t n = q.triangles;
    const size_t nodes = n / 2 + 1;
    f.bytes = saturatingSum({saturatingMul(44, n), saturatingMul(48, n), saturatingMul(64, nodes), q.moving ? saturatingMul(152, n) : 0,
                             24 * size_t(q.resolution.x) * size_t(q.resolution.y)});
    f.peakBytes = saturatingMul(152, n);
    f.refusal = storageRefusal(q, "its edge sides", saturatingMul(12, n));
    if (f.refusal.empty()) f.refusal = texelRefusal(q, "the scene positions' view it reads", saturatingMul(3, n));
    if (f.refusal.empty()) f.refusal = storageRefusal(q, "its BVH's leaf-ordered triangles", saturatingMul(48, n), true);
    if (f.refusal.empty()) f.refusal = storageRefusal(q, "its BVH's nodes", saturatingMul(64, nodes), true);
    return f;
}
AlgorithmInfo shadowVolumesInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<ShadowVolumes>("shadow_volumes",
                                            "stencil shadow volumes: GPU silhouettes with multiplicity, ZFAIL (caps) or ZPASS",
                                            {LightType::Point, LightType::Spot, LightType::Directional}, true,
                                            &shadowVolumesSchema);
    info.footprint = &shadowVolumesFootprint;
    info.motion = MotionHandling::Refit; // the close calls' BVH; the volumes follow the posed buffers
    return info;
}

} // namespace shadowlab
