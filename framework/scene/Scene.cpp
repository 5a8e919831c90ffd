#include "framework/scene/Scene.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace shadowlab {

void Scene::addTriangles(const std::vector<glm::vec3>& tri, const Material& material) {
    uint32_t mat = static_cast<uint32_t>(materials.size());
    bool used = false;
    for (size_t i = 0; i + 2 < tri.size(); i += 3) {
        glm::vec3 n = glm::cross(tri[i + 1] - tri[i], tri[i + 2] - tri[i]);
        float len = glm::length(n);
        if (!(len > 0.0f) || !std::isfinite(len)) continue;
        positions.insert(positions.end(), {tri[i], tri[i + 1], tri[i + 2]});
        normals.push_back(n / len);
        materialIds.push_back(mat);
        for (int k = 0; k < 3; ++k) bounds.extend(tri[i + k]);
        used = true;
    }
    if (used) materials.push_back(material);
}

void Scene::append(const Scene& other, const glm::mat4& m) {
    uint32_t matBase = static_cast<uint32_t>(materials.size());
    materials.insert(materials.end(), other.materials.begin(), other.materials.end());
    // A mirroring transform flips the winding; keep normals consistent with the winding.
    bool mirrored = glm::determinant(glm::mat3(m)) < 0.0f;
    // Grow geometrically (at least doubling): appending many objects one by one stays linear.
    if (positions.capacity() < positions.size() + other.positions.size()) {
        const size_t want = std::max(positions.size() + other.positions.size(), 2 * positions.capacity());
        positions.reserve(want);
        normals.reserve(want / 3);
        materialIds.reserve(want / 3);
    }
    for (size_t t = 0; t < other.triangleCount(); ++t) {
        glm::vec3 v[3];
        for (int k = 0; k < 3; ++k) v[k] = glm::vec3(m * glm::vec4(other.positions[3 * t + k], 1.0f));
        if (mirrored) std::swap(v[1], v[2]);
        glm::vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
        float len = glm::length(n);
        if (!(len > 0.0f) || !std::isfinite(len)) continue;
        positions.insert(positions.end(), {v[0], v[1], v[2]});
        normals.push_back(n / len);
        materialIds.push_back(matBase + other.materialIds[t]);
        for (auto& p : v) bounds.extend(p);
    }
}

void Scene::updateBounds() {
    bounds = Bounds{};
    for (const auto& p : positions) bounds.extend(p);
}

uint64_t Scene::contentHash() const {
    // FNV-1a over the raw bytes: stable across runs and platforms of the same endianness.
    uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* data, size_t n) {
        const auto* b = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    };
    mix(positions.data(), positions.size() * sizeof(glm::vec3));
    mix(materialIds.data(), materialIds.size() * sizeof(uint32_t));
    mix(materials.data(), materials.size() * sizeof(Material));
    return h;
}

} // namespace shadowlab
