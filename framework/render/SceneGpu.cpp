#include "framework/render/SceneGpu.h"

#include <algorithm>
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

SceneGpu::SceneGpu(const Scene& scene) : scene_(&scene), bounds_(scene.bounds) {
    positions_ = GlBuffer::fromVector(scene.positions, 0);
    // The buffer-texture view holds at most GL_MAX_TEXTURE_BUFFER_SIZE texels, three per triangle
    // (44.7 M triangles on llvmpipe): past that there is no view, and the algorithms that read the
    // positions through it refuse the scene up front (their memory estimate says so).
    if (scene.positions.size() <= size_t(maxTextureBufferTexels()))
        positionTexels_ = makeBufferTexture(positions_, GL_RGB32F, 12, "scene positions");
    // normal.xyz + material per triangle, read by the algorithms (SSBO) and by the G-buffer through
    // a buffer-texture view indexed by gl_PrimitiveID: no per-vertex copy (48 bytes a triangle).
    std::vector<TriangleInfo> tris(scene.triangleCount());
    for (size_t t = 0; t < tris.size(); ++t) {
        glm::vec3 n = scene.normals[t];
        tris[t] = {n.x, n.y, n.z, scene.materialIds[t]};
    }
    triangles_ = GlBuffer::fromVector(tris, 0);
    tris = {};
    triangleTexels_ = makeBufferTexture(triangles_, GL_RGBA32UI, 16, "scene triangles");
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
    if (scene.dynamic()) uploadMotion();
}

void SceneGpu::uploadMotion() {
    std::vector<glm::vec4> local;       // xyz per vertex, w unused: std430 vec4 needs no repacking in the shader
    std::vector<glm::uvec2> index;      // (scene triangle, part) per moving triangle
    for (size_t p = 0; p < scene_->moving.size(); ++p) {
        const MovingPart& part = scene_->moving[p];
        for (size_t i = 0; i < part.triangleCount; ++i) {
            for (int k = 0; k < 3; ++k) local.emplace_back(part.local[3 * i + size_t(k)], 1.0f);
            index.emplace_back(uint32_t(part.firstTriangle + i), uint32_t(p));
        }
    }
    local_ = GlBuffer::fromVector(local, 0);
    movingIndex_ = GlBuffer::fromVector(index, 0);
    transforms_ = GlBuffer(scene_->moving.size() * sizeof(glm::mat4), nullptr, GL_DYNAMIC_STORAGE_BIT);
    update_ = ShaderProgram::compute("common/scene_update.comp");
    // The GPU pass poses even the rest pose: its floats may differ from the CPU's in the last bit
    // (fused multiply-adds), and every consumer must see the very same triangles. So version 1 is
    // the first GPU pose, and algorithms built from Scene::positions follow it via sceneMoved().
    pose_.clear();
    setTime(0.0);
}

std::vector<glm::vec3> SceneGpu::readPositions(size_t firstTriangle, size_t count) const {
    std::vector<glm::vec3> out(3 * count);
    if (count)
        glGetNamedBufferSubData(positions_.id(), GLintptr(firstTriangle * 3 * sizeof(glm::vec3)),
                                GLsizeiptr(out.size() * sizeof(glm::vec3)), out.data());
    return out;
}

void SceneGpu::readMovingPositions(std::vector<glm::vec3>& positions) const {
    for (const MovingPart& part : scene_->moving) {
        std::vector<glm::vec3> v = readPositions(part.firstTriangle, part.triangleCount);
        std::copy(v.begin(), v.end(), positions.begin() + ptrdiff_t(3 * part.firstTriangle));
    }
}

Scene SceneGpu::posedScene() const {
    Scene s = *scene_;
    readMovingPositions(s.positions);
    for (const MovingPart& part : s.moving)
        for (size_t t = part.firstTriangle; t < part.firstTriangle + part.triangleCount; ++t) {
            const glm::vec3* v = &s.positions[3 * t];
            const glm::vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
            s.normals[t] = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0, 1, 0);
        }
    s.updateBounds();
    return s;
}

void SceneGpu::setTime(double time) {
    if (!scene_->dynamic()) return;
    std::vector<glm::mat4> pose = scene_->poseAt(time);
    if (pose == pose_ && poseVersion_ > 0) return;
    pose_ = std::move(pose);
    ++poseVersion_;
    bounds_ = scene_->boundsAt(pose_);
    transforms_.upload(pose_.data(), pose_.size() * sizeof(glm::mat4));
    local_.bindBase(GL_SHADER_STORAGE_BUFFER, 3);
    movingIndex_.bindBase(GL_SHADER_STORAGE_BUFFER, 4);
    transforms_.bindBase(GL_SHADER_STORAGE_BUFFER, 5);
    positions_.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    triangles_.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
    const size_t moving = scene_->movingTriangleCount();
    update_.set("uCount", unsigned(moving));
    update_.use();
    update_.dispatchLinear(moving, 64);
    // Everything after reads the posed scene: algorithms as SSBOs, the G-buffer as vertex attributes.
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
                    GL_TEXTURE_FETCH_BARRIER_BIT);
}

TimedWork SceneGpu::setTime(double time, StageTimer& timer) {
    if (!dynamic()) return {};
    return timeWork(timer, [&] {
        timer.begin("scene_update");
        setTime(time);
        timer.end();
    });
}

void SceneGpu::bindStorage() const {
    positions_.bindBase(GL_SHADER_STORAGE_BUFFER, kScenePositionsBinding);
    triangles_.bindBase(GL_SHADER_STORAGE_BUFFER, kSceneTrianglesBinding);
    materials_.bindBase(GL_SHADER_STORAGE_BUFFER, kSceneMaterialsBinding);
    glBindTextureUnit(kScenePositionUnit, positionTexels_.id());
    glBindTextureUnit(kSceneTriangleUnit, triangleTexels_.id());
}

size_t SceneGpu::bytes() const { return positions_.size() + triangles_.size() + materials_.size() + local_.size() + movingIndex_.size() + transforms_.size(); }

void SceneGpu::draw() const {
    glBindVertexArray(vao_.id());
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(scene_->triangleCount() * 3));
    glBindVertexArray(0);
}

} // namespace shadowlab
