#pragma once
// The scene uploaded once to the GPU. The same buffers feed the G-buffer rasterisation (as vertex
// buffers) and the algorithms (as SSBOs), so the geometry exists once in GPU memory.
// Moving parts are posed on the GPU: setTime() re-transforms only their triangles from object-space
// copies (shaders/common/scene_update.comp), the static rest is never touched.
#include "framework/gl/GlObjects.h"
#include "framework/gl/Shader.h"
#include "framework/gl/StageTimer.h"
#include "framework/scene/Scene.h"

namespace shadowlab {

/// SSBO binding points of the shared scene buffers (mirrored in shaders/common/scene.glsl).
enum SceneBinding : GLuint {
    kScenePositionsBinding = 0, ///< float[9 n]: triangle i = floats 9i..9i+8 (three xyz vertices)
    kSceneTrianglesBinding = 1, ///< TriangleInfo[n]: normal.xyz + material id
    kSceneMaterialsBinding = 2, ///< MaterialInfo[]: albedo.rgb + opacity
};
/// Texture unit of the positions' buffer-texture view (scene.glsl, SCENE_POSITION_TEXELS).
constexpr GLuint kScenePositionUnit = 15;
/// Texture unit of the triangles' buffer-texture view (RGBA32UI: normal bits + material), read by
/// the G-buffer by gl_PrimitiveID.
constexpr GLuint kSceneTriangleUnit = 14;

class SceneGpu {
public:
    explicit SceneGpu(const Scene& scene);

    /// The scene on the CPU: static triangles as they are, moving parts at their rest pose (time 0).
    const Scene& cpu() const { return *scene_; }
    size_t triangleCount() const { return scene_->triangleCount(); }
    /// Bounds of the scene as currently posed.
    const Bounds& bounds() const { return bounds_; }

    bool dynamic() const { return scene_->dynamic(); }
    /// Poses the moving parts at `time` (a no-op for a static scene or an unchanged pose): one
    /// compute pass over their triangles rewriting positions and normals in place.
    void setTime(double time);
    /// setTime() as the shared per-frame stage `scene_update`, timed as algorithms' frames are
    /// (timeWork); nothing, and no stage, for a static scene.
    TimedWork setTime(double time, StageTimer& timer);
    /// Changes whenever the pose does: 0 is Scene::positions as they are (a static scene's only
    /// version); a moving scene is posed by the GPU from the start, so its versions begin at 1.
    uint64_t poseVersion() const { return poseVersion_; }
    /// The posed positions of triangles [firstTriangle, firstTriangle + count) read back from the GPU
    /// (3 per triangle): the very floats the G-buffer and the GPU algorithms see, for CPU consumers.
    std::vector<glm::vec3> readPositions(size_t firstTriangle, size_t count) const;
    /// Overwrites the moving parts' ranges of `positions` (3 per scene triangle) with their posed values.
    void readMovingPositions(std::vector<glm::vec3>& positions) const;
    /// The whole scene as posed now, on the CPU (positions, normals and bounds), for algorithms that
    /// rebuild from scratch at each pose.
    Scene posedScene() const;

    const GlBuffer& positions() const { return positions_; }
    const GlBuffer& triangles() const { return triangles_; }
    const GlBuffer& materials() const { return materials_; }
    /// mat4 per moving part, the current pose (std430; a 4-byte dummy for a static scene).
    const GlBuffer& partTransforms() const { return transforms_; }
    GLuint vertexArray() const { return vao_.id(); }

    /// GPU bytes of the scene's buffers (positions, triangles, materials, moving parts' copies).
    size_t bytes() const;
    /// Whether the positions have a buffer-texture view (SCENE_POSITION_TEXELS): not past
    /// GL_MAX_TEXTURE_BUFFER_SIZE texels, three per triangle.
    bool hasPositionTexels() const { return positionTexels_.id() != 0; }

    /// Binds positions, triangles and materials to their SceneBinding points, and the positions'
    /// buffer-texture view (RGB32F, vertex k of triangle i = texel 3i + k) to kScenePositionUnit, and the
    /// triangles' view to kSceneTriangleUnit.
    void bindStorage() const;
    /// Draws every triangle (non-indexed) with the bound program.
    void draw() const;

private:
    void uploadMotion();

    const Scene* scene_;
    GlBuffer positions_, triangles_, materials_;
    GlTexture positionTexels_, triangleTexels_;
    GlVertexArray vao_;
    Bounds bounds_;
    std::vector<glm::mat4> pose_;
    uint64_t poseVersion_ = 0;
    GlBuffer local_, movingIndex_, transforms_;
    ShaderProgram update_;
};

} // namespace shadowlab
