#include "framework/render/ShadingPass.h"

#include "framework/core/Error.h"
#include "framework/render/LightUniforms.h"

namespace shadowlab {

ShadingPass::ShadingPass(glm::ivec2 resolution) : size_(resolution) {
    color_ = makeTexture2D(GL_RGBA8, size_.x, size_.y);
    GLuint fbo = 0, vao = 0;
    glCreateFramebuffers(1, &fbo);
    fbo_ = GlFramebuffer(fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color_.id(), 0);
    if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw RuntimeError("shading framebuffer is incomplete");
    glCreateVertexArrays(1, &vao); // core profile draws need a bound VAO even without attributes
    emptyVao_ = GlVertexArray(vao);
    program_ = ShaderProgram::graphics("shading/fullscreen.vert", "shading/shade.frag");
}

void ShadingPass::run(const GBuffer& gbuffer, GLuint visibility, const Light& light) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, size_.x, size_.y);
    glDisable(GL_DEPTH_TEST);
    setLightUniforms(program_, light);
    program_.set("uAmbient", ambient);
    program_.set("uBackground", background);
    program_.use();
    glBindTextureUnit(0, gbuffer.position());
    glBindTextureUnit(1, gbuffer.normal());
    glBindTextureUnit(2, gbuffer.albedo());
    glBindTextureUnit(3, visibility);
    glBindVertexArray(emptyVao_.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

} // namespace shadowlab
