#pragma once
// The shading pass shared by every algorithm: G-buffer + visibility → final RGBA8 image.
#include "framework/gl/Shader.h"
#include "framework/render/GBuffer.h"
#include "framework/view/Light.h"

namespace shadowlab {

class ShadingPass {
public:
    explicit ShadingPass(glm::ivec2 resolution);
    /// Shades into output() with visibility from the R32F texture `visibility`.
    void run(const GBuffer& gbuffer, GLuint visibility, const Light& light);
    GLuint output() const { return color_.id(); } ///< RGBA8, display gamma

    float ambient = 0.15f;                  ///< share of albedo seen without direct light, in [0, 1]
    glm::vec3 background{0.55f, 0.62f, 0.72f}; ///< colour of pixels with no geometry (display space)

private:
    glm::ivec2 size_;
    GlTexture color_;
    GlFramebuffer fbo_;
    GlVertexArray emptyVao_;
    ShaderProgram program_;
};

} // namespace shadowlab
