#include "framework/render/GBuffer.h"

#include "framework/core/Error.h"

namespace shadowlab {

GBuffer::GBuffer(glm::ivec2 resolution) : size_(resolution) {
    position_ = makeTexture2D(GL_RGBA32F, size_.x, size_.y);
    normal_ = makeTexture2D(GL_RGBA16F, size_.x, size_.y);
    albedo_ = makeTexture2D(GL_RGBA8, size_.x, size_.y);
    triangleId_ = makeTexture2D(GL_R32UI, size_.x, size_.y);
    depth_ = makeTexture2D(GL_DEPTH_COMPONENT32F, size_.x, size_.y);
    GLuint fbo = 0;
    glCreateFramebuffers(1, &fbo);
    fbo_ = GlFramebuffer(fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, position_.id(), 0);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT1, normal_.id(), 0);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT2, albedo_.id(), 0);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT3, triangleId_.id(), 0);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth_.id(), 0);
    const GLenum bufs[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
    glNamedFramebufferDrawBuffers(fbo, 4, bufs);
    if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw RuntimeError("G-buffer framebuffer is incomplete");
    program_ = ShaderProgram::graphics("gbuffer/gbuffer.vert", "gbuffer/gbuffer.frag");
}

void GBuffer::render(const SceneGpu& scene, const Camera& camera) {
    viewProj_ = camera.projection(float(size_.x) / float(size_.y)) * camera.view();
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, size_.x, size_.y);
    const float zero[4] = {0, 0, 0, 0};
    const GLuint zeroId[4] = {0, 0, 0, 0};
    const float one = 1.0f;
    glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 1, zero);
    glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 2, zero);
    glClearNamedFramebufferuiv(fbo_.id(), GL_COLOR, 3, zeroId);
    glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE); // two-sided: planes and open meshes are seen from both sides
    program_.set("uViewProj", viewProj_);
    program_.set("uCameraPosition", camera.position);
    program_.use();
    scene.bindStorage();
    scene.draw();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

CpuGBuffer GBuffer::readBack() const {
    CpuGBuffer out;
    out.width = size_.x;
    out.height = size_.y;
    out.position = readTextureRGBA32F(position_.id(), size_.x, size_.y);
    out.normal = readTextureRGBA32F(normal_.id(), size_.x, size_.y);
    return out;
}

} // namespace shadowlab
