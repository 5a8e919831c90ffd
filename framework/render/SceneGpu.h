#pragma once
// The scene uploaded once to the GPU. The same buffers feed the G-buffer rasterisation (as vertex
// buffers) and the algorithms (as SSBOs), so the geometry exists once in GPU memory.
#include "framework/gl/GlObjects.h"
#include "framework/scene/Scene.h"

namespace shadowlab {

/// SSBO binding points of the shared scene buffers (mirrored in shaders/common/scene.glsl).
enum SceneBinding : GLuint {
    kScenePositionsBinding = 0, ///< float[9 n]: triangle i = floats 9i..9i+8 (three xyz vertices)
    kSceneTrianglesBinding = 1, ///< TriangleInfo[n]: normal.xyz + material id
    kSceneMaterialsBinding = 2, ///< MaterialInfo[]: albedo.rgb + opacity
};

class SceneGpu {
public:
    explicit SceneGpu(const Scene& scene);

    const Scene& cpu() const { return *scene_; }
    size_t triangleCount() const { return scene_->triangleCount(); }
    const Bounds& bounds() const { return scene_->bounds; }

    const GlBuffer& positions() const { return positions_; }
    const GlBuffer& triangles() const { return triangles_; }
    const GlBuffer& materials() const { return materials_; }
    GLuint vertexArray() const { return vao_.id(); }

    /// Binds positions, triangles and materials to their SceneBinding points.
    void bindStorage() const;
    /// Draws every triangle (non-indexed) with the bound program.
    void draw() const;

private:
    const Scene* scene_;
    GlBuffer positions_, triangles_, materials_, vertexNormals_;
    GlVertexArray vao_;
};

} // namespace shadowlab
