#include "framework/render/SceneGpu.h"

#include <cstring>

namespace shadowlab {

namespace {
struct TriangleInfo { // std430, 16 bytes; mirrored in shaders/common/scene.glsl
    float nx, ny, nz;
    uint32_t material;
};
struct MaterialInfo { // std430, 16 bytes
    float r, g, b, opacity;
};
static_assert(sizeof(TriangleInfo) == 16 && sizeof(MaterialInfo) == 16);
} // namespace

SceneGpu::SceneGpu(const Scene& scene) : scene_(&scene) {
    positions_ = GlBuffer::fromVector(scene.positions, 0);
    std::vector<TriangleInfo> tris(scene.triangleCount());
    // Per-vertex attribute (normal.xyz, material): the rasteriser needs per-triangle data at each
    // vertex; reading it from an SSBO by gl_VertexID would cap the scene at the SSBO size limit.
    std::vector<TriangleInfo> perVertex(scene.triangleCount() * 3);
    for (size_t t = 0; t < tris.size(); ++t) {
        glm::vec3 n = scene.normals[t];
        tris[t] = {n.x, n.y, n.z, scene.materialIds[t]};
        for (int k = 0; k < 3; ++k) perVertex[3 * t + k] = tris[t];
    }
    triangles_ = GlBuffer::fromVector(tris, 0);
    vertexNormals_ = GlBuffer::fromVector(perVertex, 0);
    std::vector<MaterialInfo> mats;
    for (const auto& m : scene.materials) mats.push_back({m.albedo.x, m.albedo.y, m.albedo.z, m.opacity});
    materials_ = GlBuffer::fromVector(mats, 0);

    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    vao_ = GlVertexArray(vao);
    glVertexArrayVertexBuffer(vao, 0, positions_.id(), 0, sizeof(glm::vec3));
    glEnableVertexArrayAttrib(vao, 0);
    glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
    glVertexArrayVertexBuffer(vao, 1, vertexNormals_.id(), 0, sizeof(TriangleInfo));
    glEnableVertexArrayAttrib(vao, 1);
    glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 1, 1);
    glEnableVertexArrayAttrib(vao, 2);
    glVertexArrayAttribIFormat(vao, 2, 1, GL_UNSIGNED_INT, 12);
    glVertexArrayAttribBinding(vao, 2, 1);
}

void SceneGpu::bindStorage() const {
    positions_.bindBase(GL_SHADER_STORAGE_BUFFER, kScenePositionsBinding);
    triangles_.bindBase(GL_SHADER_STORAGE_BUFFER, kSceneTrianglesBinding);
    materials_.bindBase(GL_SHADER_STORAGE_BUFFER, kSceneMaterialsBinding);
}

void SceneGpu::draw() const {
    glBindVertexArray(vao_.id());
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(scene_->triangleCount() * 3));
    glBindVertexArray(0);
}

} // namespace shadowlab
