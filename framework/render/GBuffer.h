#pragma once
// The deferred G-buffer shared by every algorithm: world position, normal, albedo, triangle id, depth.
#include "framework/gl/Shader.h"
#include "framework/render/SceneGpu.h"
#include "framework/view/Camera.h"

#include <glm/glm.hpp>
#include <vector>

namespace shadowlab {

/// G-buffer read back to the CPU (for the reference, the lit mask and the metrics).
struct CpuGBuffer {
    int width = 0, height = 0;
    std::vector<float> position; ///< RGBA: world xyz, w = 1 on geometry, 0 on background
    std::vector<float> normal;   ///< RGBA: unit normal facing the camera, w unused
    bool covered(size_t i) const { return position[4 * i + 3] > 0.5f; }
    glm::vec3 positionAt(size_t i) const { return {position[4 * i], position[4 * i + 1], position[4 * i + 2]}; }
    glm::vec3 normalAt(size_t i) const { return {normal[4 * i], normal[4 * i + 1], normal[4 * i + 2]}; }
};

class GBuffer {
public:
    explicit GBuffer(glm::ivec2 resolution);

    /// Rasterises the scene from `camera`. Normals are flipped to face the camera (two-sided surfaces).
    void render(const SceneGpu& scene, const Camera& camera);
    /// Reads position and normal back (after render()).
    CpuGBuffer readBack() const;

    glm::ivec2 resolution() const { return size_; }
    GLuint position() const { return position_.id(); }   ///< RGBA32F
    GLuint normal() const { return normal_.id(); }       ///< RGBA16F
    GLuint albedo() const { return albedo_.id(); }       ///< RGBA8
    GLuint triangleId() const { return triangleId_.id(); } ///< R32UI: triangle index + 1, 0 = background
    GLuint depth() const { return depth_.id(); }         ///< DEPTH32F
    const glm::mat4& viewProjection() const { return viewProj_; }

private:
    glm::ivec2 size_;
    GlTexture position_, normal_, albedo_, triangleId_, depth_;
    GlFramebuffer fbo_;
    ShaderProgram program_;
    glm::mat4 viewProj_{1.0f};
};

} // namespace shadowlab
