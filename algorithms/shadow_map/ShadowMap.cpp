#include "algorithms/shadow_map/ShadowMap.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/core/CheckedMath.h"
#include "framework/render/LightUniforms.h"

#include <glm/gtc/matrix_transform.hpp>

namespace shadowlab {
namespace {

struct ShadowMapParams {
    int resolution;     ///< texels per side (per cube face)
    float biasConstant; ///< × scene radius
    float biasSlope;    ///< × texel size × tan θ
    int pcf;            ///< kernel radius, texels
};

const ParamStruct<ShadowMapParams>& params() {
    using P = ShadowMapParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        .integer("resolution", &P::resolution, 2048, 64, 8192, "texels",
                 "side of the shadow map (of each cube face for point lights)", ParamChange::Rebuild)
        .real("bias_constant", &P::biasConstant, 0.002, 0.0, 0.1, "× scene radius", "depth bias added to every comparison",
              ParamChange::Update)
        .real("bias_slope", &P::biasSlope, 1.5, 0.0, 20.0, "× texel size × tan θ",
              "slope-scaled bias: grows with the receiver's angle to the light", ParamChange::Update)
        .integer("pcf", &P::pcf, 1, 0, 7, "texels", "PCF kernel radius: 0 = hard, k = (2k+1)² taps", ParamChange::Update);
    return s;
}

const ParamSchema& schema() { return params().schema(); }

// Cube face view matrices in GL's face order (+X, -X, +Y, -Y, +Z, -Z).
const glm::vec3 kFaceDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
const glm::vec3 kFaceUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};

class ShadowMap : public ShadowAlgorithm {
public:
    explicit ShadowMap(const ParamValues& p) : p_(params().read(p)) {
        depthProgram_ = ShaderProgram::graphics("shadow_map/depth.vert", "shadow_map/depth.frag");
        lookup2D_ = ShaderProgram::compute("shadow_map/lookup.comp", {{"CUBE", "0"}});
        lookupCube_ = ShaderProgram::compute("shadow_map/lookup.comp", {{"CUBE", "1"}});
    }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        allocate();
    }

    void paramsChanged(const ParamValues& p, ParamChange) override {
        p_ = params().read(p);  // a Rebuild (resolution) is followed by setScene(), which reallocates
    }

    void computeVisibility(const FrameInputs& f) override {
        const Light& light = f.light;
        const bool cube = light.type == LightType::Point;
        const float radius = scene_->bounds().radius();
        const glm::vec3 center = scene_->bounds().center();
        const int res = p_.resolution;
        ensureTargets(cube);

        f.timer.begin("shadow_pass");
        glViewport(0, 0, res, res);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDisable(GL_CULL_FACE);
        depthProgram_.set("uLightPosition", light.position);
        depthProgram_.set("uDirectional", light.type == LightType::Directional ? 1 : 0);
        depthProgram_.set("uLightDirection", light.direction());
        depthProgram_.use();
        scene_->bindStorage();
        glm::mat4 lightViewProj(1.0f);
        float texelAngle = 0, orthoTexel = 0; // receiver-independent parts of a texel's world size
        const float clear = 3.0e38f, one = 1.0f;
        if (cube) {
            glm::mat4 proj = glm::perspective(glm::radians(90.0f), 1.0f, 1e-3f * radius, 4.0f * radius + glm::length(light.position - center));
            for (int face = 0; face < 6; ++face) {
                glm::mat4 vp = proj * glm::lookAt(light.position, light.position + kFaceDir[face], kFaceUp[face]);
                glBindFramebuffer(GL_FRAMEBUFFER, faceFbo_[face].id());
                glClearNamedFramebufferfv(faceFbo_[face].id(), GL_COLOR, 0, &clear);
                glClearNamedFramebufferfv(faceFbo_[face].id(), GL_DEPTH, 0, &one);
                depthProgram_.set("uViewProj", vp);
                scene_->draw();
            }
            texelAngle = 2.0f / float(res);
        } else {
            glm::vec3 dir = light.direction();
            glm::vec3 up = std::abs(dir.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
            if (light.type == LightType::Directional) {
                glm::vec3 eye = center - dir * (2.0f * radius);
                lightViewProj = glm::ortho(-radius, radius, -radius, radius, 0.0f, 4.0f * radius) * glm::lookAt(eye, center, up);
                orthoTexel = 2.0f * radius / float(res);
                depthProgram_.set("uLightPosition", eye);
            } else { // spot: the frustum encloses the cone
                float fov = std::min(2.0f * light.coneDeg + 2.0f, 179.0f);
                float far = glm::length(light.position - center) + 2.0f * radius;
                lightViewProj = glm::perspective(glm::radians(fov), 1.0f, 1e-3f * radius, far) *
                                glm::lookAt(light.position, light.position + dir, up);
                texelAngle = 2.0f * std::tan(glm::radians(fov) * 0.5f) / float(res);
            }
            glBindFramebuffer(GL_FRAMEBUFFER, fbo2D_.id());
            glClearNamedFramebufferfv(fbo2D_.id(), GL_COLOR, 0, &clear);
            glClearNamedFramebufferfv(fbo2D_.id(), GL_DEPTH, 0, &one);
            depthProgram_.set("uViewProj", lightViewProj);
            scene_->draw();
        }
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        f.timer.end();

        f.timer.begin("lookup");
        const ShaderProgram& p = cube ? lookupCube_ : lookup2D_;
        setLightUniforms(p, light);
        p.set("uLightViewProj", lightViewProj);
        p.set("uDirectionalOrigin", center - light.direction() * (2.0f * radius));
        p.set("uBiasConstant", p_.biasConstant * radius);
        p.set("uBiasSlope", p_.biasSlope);
        p.set("uTexelAngle", texelAngle);
        p.set("uOrthoTexel", orthoTexel);
        p.set("uPcf", p_.pcf);
        p.set("uMapSize", float(res));
        glBindTextureUnit(0, f.gbuffer.position());
        glBindTextureUnit(1, f.gbuffer.normal());
        glBindTextureUnit(2, cube ? cubeMap_.id() : map2D_.id());
        glBindImageTexture(0, f.visibility, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        p.dispatch2D(f.gbuffer.resolution().x, f.gbuffer.resolution().y, 8, 8);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
        f.timer.end();
    }

    size_t memoryBytes() const override {
        size_t r = size_t(p_.resolution);
        // distance (R32F) + depth (32F): 8 bytes per texel, on one 2D map and/or six cube faces
        return r * r * 8 * ((map2D_ ? 1 : 0) + (cubeMap_ ? 6 : 0));
    }

private:
    // Targets are made on first use for the light type at hand, so a spot light costs one 2D map
    // and a point light one cube map; a resolution change drops both.
    void allocate() {
        map2D_.reset(); depth2D_.reset(); cubeMap_.reset(); cubeDepth_.reset(); fbo2D_.reset();
        for (auto& f : faceFbo_) f.reset();
    }

    void ensureTargets(bool cube) {
        const int r = p_.resolution;
        GLuint fbo = 0;
        if (cube && !cubeMap_) {
            GLuint tex[2];
            glCreateTextures(GL_TEXTURE_CUBE_MAP, 2, tex);
            glTextureStorage2D(tex[0], 1, GL_R32F, r, r);
            glTextureParameteri(tex[0], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(tex[0], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            glTextureStorage2D(tex[1], 1, GL_DEPTH_COMPONENT32F, r, r);
            cubeMap_ = GlTexture(tex[0]);
            cubeDepth_ = GlTexture(tex[1]);
            for (int face = 0; face < 6; ++face) {
                glCreateFramebuffers(1, &fbo);
                faceFbo_[face] = GlFramebuffer(fbo);
                glNamedFramebufferTextureLayer(fbo, GL_COLOR_ATTACHMENT0, tex[0], 0, face);
                glNamedFramebufferTextureLayer(fbo, GL_DEPTH_ATTACHMENT, tex[1], 0, face);
            }
        }
        if (!cube && !map2D_) {
            map2D_ = makeTexture2D(GL_R32F, r, r, GL_NEAREST);
            depth2D_ = makeTexture2D(GL_DEPTH_COMPONENT32F, r, r);
            glCreateFramebuffers(1, &fbo);
            fbo2D_ = GlFramebuffer(fbo);
            glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, map2D_.id(), 0);
            glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth2D_.id(), 0);
        }
    }

    ShadowMapParams p_;
    const SceneGpu* scene_ = nullptr;
    ShaderProgram depthProgram_, lookup2D_, lookupCube_;
    GlTexture map2D_, depth2D_, cubeMap_, cubeDepth_;
    GlFramebuffer faceFbo_[6], fbo2D_;
};

} // namespace

/// Its maps at the configured resolution, on the six faces of a cube map and one 2D map (the plan
/// does not know the light: the most any light asks for): 14 bytes a texel of each, distance and
/// depth and what llvmpipe holds beside them (results/reference/memory_bounds_llvmpipe.md).
Footprint shadowMapFootprint(const FootprintQuery& q) {
    const size_t r = size_t(std::get<int>(q.params->get("resolution")));
    Footprint f;
    f.bytes = saturatingMul(saturatingMul(r, r), 7 * 14);
    f.textureBytes = f.bytes;
    return f;
}

AlgorithmInfo shadowMapInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<ShadowMap>("shadow_map",
                                        "shadow maps: 2D for spot/directional, cube map for point lights, constant + slope bias, PCF",
                                        {LightType::Point, LightType::Spot, LightType::Directional}, false, &schema);
    info.footprint = &shadowMapFootprint;
    return info;
}

} // namespace shadowlab
