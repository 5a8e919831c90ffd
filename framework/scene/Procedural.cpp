#include "framework/scene/Procedural.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <random>

// Every generator writes its triangles straight into the Scene (instead of building a temporary
// vector for Scene::addTriangles) so a 10 M triangle object costs one copy of the data, not two.
// Closed shapes compute each grid vertex once and index it, so triangles that share an edge share
// bit-identical endpoints: the soup stays watertight (every edge used by exactly two triangles).

namespace shadowlab {
namespace {

constexpr float kTwoPi = 6.28318530717958647692f;
constexpr float kPi = 3.14159265358979323846f;

/// Appends triangles with the same rule as Scene::addTriangles (zero-area ones dropped), material 0.
class Writer {
public:
    Writer(Scene& scene, const Material& m, size_t expectedTriangles) : s_(scene) {
        s_.materials = {m};
        s_.positions.reserve(3 * expectedTriangles);
        s_.normals.reserve(expectedTriangles);
        s_.materialIds.reserve(expectedTriangles);
    }
    void add(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
        glm::vec3 n;
        if (!unitNormal(a, b, c, n)) return;
        s_.positions.insert(s_.positions.end(), {a, b, c});
        s_.normals.push_back(n);
        s_.materialIds.push_back(0);
        s_.bounds.extend(a);
        s_.bounds.extend(b);
        s_.bounds.extend(c);
    }
    /// Quad a-b-c-d (counter-clockwise seen from the front) as two triangles.
    void quad(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d) {
        add(a, b, c);
        add(a, c, d);
    }

private:
    Scene& s_;
};

int roundPositive(double x, int minimum) { return std::max(minimum, static_cast<int>(std::lround(x))); }

} // namespace

size_t planeTriangles(int subdivisions) {
    const size_t s = size_t(std::max(1, subdivisions));
    return 2 * s * s;
}

SphereTessellation sphereTessellation(int triangles) {
    // A UV sphere with `stacks` latitude bands and `slices` longitude segments has a fan of
    // `slices` triangles at each pole and 2·slices per inner band: T = 2·slices·(stacks − 1).
    // Near-square cells want slices ≈ 2·stacks, so T ≈ 4·stacks·(stacks − 1), i.e.
    // stacks = (1 + √(1 + T)) / 2; slices is then re-fitted to T / (2·(stacks − 1)). The remaining
    // error comes from rounding slices: at most 1 / (2·slices), under 1.6 % for T ≥ 1000.
    // Minimum 3 stacks × 4 slices = 16 triangles.
    const double t = std::max(1, triangles);
    SphereTessellation s;
    s.stacks = roundPositive((1.0 + std::sqrt(1.0 + t)) / 2.0, 3);
    s.slices = roundPositive(t / (2.0 * (s.stacks - 1)), 4);
    return s;
}

TorusTessellation torusTessellation(float majorRadius, float minorRadius, int triangles) {
    // A (major × minor) grid of quads: T = 2·U·V. Cells are kept roughly square by making the
    // segment counts proportional to the circumferences, U/V = k = R/r (clamped to [1, 8]):
    // V = √(T / (2k)), then U re-fitted to T / (2V). The error is at most 1 / (2U): under 2 %
    // for T ≥ 1000 (U ≥ 22 there). Minimum 3 × 3 = 18 triangles.
    const double t = std::max(1, triangles);
    const double k = std::clamp(double(majorRadius) / std::max(double(minorRadius), 1e-9), 1.0, 8.0);
    TorusTessellation s;
    s.minor = roundPositive(std::sqrt(t / (2.0 * k)), 3);
    s.major = roundPositive(t / (2.0 * s.minor), 3);
    return s;
}

CylinderTessellation cylinderTessellation(float radius, float height, int triangles) {
    // `slices` around, `stacks` bands up the side, a fan on each cap: T = 2·slices·(stacks + 1).
    // Near-square side cells want stacks ≈ slices·h / (2πr), so T ≈ slices²·h / (πr):
    // slices = √(T·πr / h); then stacks + 1 = T / (2·slices) and slices is re-fitted to
    // T / (2·(stacks + 1)). Rounding leaves under 1.5 % for T ≥ 1000 (for height/radius from
    // 0.01 to 10^4: long thin cylinders get few slices and many stacks, and vice versa).
    // Minimum 3 slices × 1 stack = 12 triangles.
    const double t = std::max(1, triangles);
    const double aspect = double(height) / std::max(double(radius), 1e-9);
    CylinderTessellation s;
    s.slices = roundPositive(std::sqrt(t * kPi / std::max(aspect, 1e-9)), 3);
    s.stacks = roundPositive(t / (2.0 * s.slices) - 1.0, 1);
    s.slices = roundPositive(t / (2.0 * (s.stacks + 1)), 3);
    return s;
}

FenceLayout fenceLayout(int posts, float spacing, float height, float radius, int rails, int trianglesPerCylinder) {
    FenceLayout f;
    f.posts = std::max(1, posts);
    f.firstX = -0.5f * float(f.posts - 1) * spacing;
    f.length = float(f.posts - 1) * spacing;
    f.rails = f.length > 0.0f ? std::max(0, rails) : 0; // a single post has nothing to join
    f.post = cylinderTessellation(radius, height, trianglesPerCylinder);
    if (f.rails > 0) f.rail = cylinderTessellation(radius, f.length, trianglesPerCylinder);
    return f;
}

size_t soupTriangles(int triangles) { return size_t(std::max(0, triangles)); }

size_t gridCopies(glm::ivec3 count) {
    const glm::ivec3 c = glm::max(count, glm::ivec3(1));
    return size_t(c.x) * size_t(c.y) * size_t(c.z);
}

Scene makePlane(glm::vec2 size, int subdivisions, const Material& m) {
    int s = std::max(1, subdivisions);
    Scene scene;
    Writer w(scene, m, planeTriangles(s));
    auto x = [&](int i) { return size.x * (float(i) / float(s) - 0.5f); };
    auto z = [&](int k) { return size.y * (float(k) / float(s) - 0.5f); };
    for (int k = 0; k < s; ++k)
        for (int i = 0; i < s; ++i)
            // (x0,z0) → (x0,z1) → (x1,z1) → (x1,z0) turns counter-clockwise seen from +Y.
            w.quad({x(i), 0, z(k)}, {x(i), 0, z(k + 1)}, {x(i + 1), 0, z(k + 1)}, {x(i + 1), 0, z(k)});
    return scene;
}

Scene makeSphere(float radius, int triangles, const Material& m) {
    const SphereTessellation tess = sphereTessellation(triangles);
    const int stacks = tess.stacks, slices = tess.slices;
    // Ring vertices once: rings 1..stacks-1, poles separate. Column `slices` wraps to column 0.
    std::vector<glm::vec3> ring(size_t(stacks - 1) * size_t(slices));
    for (int i = 1; i < stacks; ++i) {
        float theta = kPi * float(i) / float(stacks);
        for (int j = 0; j < slices; ++j) {
            float phi = kTwoPi * float(j) / float(slices);
            ring[size_t(i - 1) * size_t(slices) + size_t(j)] =
                radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
        }
    }
    auto v = [&](int i, int j) -> const glm::vec3& { return ring[size_t(i - 1) * size_t(slices) + size_t(j % slices)]; };
    glm::vec3 north(0, radius, 0), south(0, -radius, 0);
    Scene scene;
    Writer w(scene, m, tess.triangles());
    // With θ growing southwards and φ eastwards, (p, p + dφ, p + dθ) is counter-clockwise from outside.
    for (int j = 0; j < slices; ++j) w.add(north, v(1, j + 1), v(1, j));
    for (int i = 1; i + 1 < stacks; ++i)
        for (int j = 0; j < slices; ++j) w.quad(v(i, j), v(i, j + 1), v(i + 1, j + 1), v(i + 1, j));
    for (int j = 0; j < slices; ++j) w.add(v(stacks - 1, j), v(stacks - 1, j + 1), south);
    return scene;
}

Scene makeTorus(float majorRadius, float minorRadius, int triangles, const Material& m) {
    // With minorRadius ≥ majorRadius the tube reaches the axis and triangles there degenerate.
    const TorusTessellation tess = torusTessellation(majorRadius, minorRadius, triangles);
    const int major = tess.major, minor = tess.minor;
    std::vector<glm::vec3> grid(size_t(major) * size_t(minor));
    for (int i = 0; i < major; ++i) {
        float u = kTwoPi * float(i) / float(major);
        for (int j = 0; j < minor; ++j) {
            float vAngle = kTwoPi * float(j) / float(minor);
            float rr = majorRadius + minorRadius * std::cos(vAngle);
            grid[size_t(i) * size_t(minor) + size_t(j)] = {rr * std::cos(u), minorRadius * std::sin(vAngle), rr * std::sin(u)};
        }
    }
    auto p = [&](int i, int j) -> const glm::vec3& { return grid[size_t(i % major) * size_t(minor) + size_t(j % minor)]; };
    Scene scene;
    Writer w(scene, m, tess.triangles());
    // Outward normal is ∂v × ∂u here, so walk v first: (p, p + dv, p + du + dv, p + du).
    for (int i = 0; i < major; ++i)
        for (int j = 0; j < minor; ++j) w.quad(p(i, j), p(i, j + 1), p(i + 1, j + 1), p(i + 1, j));
    return scene;
}

Scene makeCylinder(float radius, float height, int triangles, const Material& m) {
    const CylinderTessellation tess = cylinderTessellation(radius, height, triangles);
    const int slices = tess.slices, stacks = tess.stacks;
    std::vector<glm::vec3> grid(size_t(stacks + 1) * size_t(slices));
    for (int i = 0; i <= stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            float phi = kTwoPi * float(j) / float(slices);
            // The top ring uses `height` itself so cap and side share exact vertices.
            float y = i == stacks ? height : height * float(i) / float(stacks);
            grid[size_t(i) * size_t(slices) + size_t(j)] = {radius * std::cos(phi), y, radius * std::sin(phi)};
        }
    auto p = [&](int i, int j) -> const glm::vec3& { return grid[size_t(i) * size_t(slices) + size_t(j % slices)]; };
    Scene scene;
    Writer w(scene, m, tess.triangles());
    glm::vec3 bottom(0, 0, 0), top(0, height, 0);
    for (int j = 0; j < slices; ++j) {
        w.add(bottom, p(0, j), p(0, j + 1));         // faces −Y
        w.add(top, p(stacks, j + 1), p(stacks, j));  // faces +Y
        // Side: ∂y × ∂φ points outward, so go up first, then around.
        for (int i = 0; i < stacks; ++i) w.quad(p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
    }
    return scene;
}

Scene makeFence(int posts, float spacing, float height, float radius, int rails, int trianglesPerCylinder, const Material& m) {
    const FenceLayout layout = fenceLayout(posts, spacing, height, radius, rails, trianglesPerCylinder);
    const float firstX = layout.firstX;
    Scene post = makeCylinder(radius, height, trianglesPerCylinder, m);
    Scene rail = layout.rails ? makeCylinder(radius, layout.length, trianglesPerCylinder, m) : Scene{};
    Scene scene;
    // Reserved at its exact size (+ 1 vertex: see Scene::append), so the fence holds no slack.
    const size_t triangles = size_t(layout.posts) * post.triangleCount() + size_t(layout.rails) * rail.triangleCount();
    scene.positions.reserve(3 * triangles + 1);
    scene.normals.reserve(triangles);
    scene.materialIds.reserve(triangles);
    for (int i = 0; i < layout.posts; ++i)
        scene.append(post, glm::translate(glm::mat4(1.0f), {firstX + float(i) * spacing, 0, 0}));
    // A cylinder along +Y turned −90° about Z lies along +X, starting at the first post.
    glm::mat4 toX = glm::rotate(glm::mat4(1.0f), -0.5f * kPi, glm::vec3(0, 0, 1));
    // Rails split the height evenly and leave a gap at the ground: y = height·(k + 1)/(rails + 1).
    for (int k = 0; k < layout.rails; ++k) {
        float y = height * float(k + 1) / float(layout.rails + 1);
        scene.append(rail, glm::translate(glm::mat4(1.0f), {firstX, y, 0}) * toX);
    }
    // append() copies the material per copy; one material is enough since they are all `m`.
    scene.materials = std::vector<Material>{m}; // a new vector: the copies' capacity goes with the old one
    std::fill(scene.materialIds.begin(), scene.materialIds.end(), 0u);
    return scene;
}

Scene makeTriangleSoup(int triangles, glm::vec3 extent, float triangleSize, uint32_t seed, const Material& m) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-0.5f, 0.5f);
    // Vertices at distance r = size/√3 from the centre in random directions: an equilateral triangle
    // with that circumradius has edge `size`, random ones have edges of that order.
    float r = triangleSize / std::sqrt(3.0f);
    // Keep whole triangles inside the box: centres stay r away from its faces where there is room.
    glm::vec3 half = glm::max(0.5f * extent - glm::vec3(r), glm::vec3(0.0f));
    glm::vec3 boxHalf = 0.5f * extent;
    Scene scene;
    const size_t n = soupTriangles(triangles);
    Writer w(scene, m, n);
    float minCross = 1e-4f * triangleSize * triangleSize;
    for (size_t t = 0; t < n; ++t) {
        // Retry the rare (near) degenerate draw so the count is exactly the request; a box too flat to
        // hold any triangle (zero extent in two axes) gives up instead of looping forever.
        size_t before = scene.triangleCount();
        for (int attempt = 0; attempt < 100 && scene.triangleCount() == before; ++attempt) {
            glm::vec3 c = 2.0f * half * glm::vec3(unit(rng), unit(rng), unit(rng));
            glm::vec3 v[3];
            for (auto& p : v) {
                // Uniform direction on the sphere (Archimedes: z uniform in [-1, 1], angle uniform).
                float z = 2.0f * unit(rng), phi = kTwoPi * unit(rng), s = std::sqrt(1.0f - z * z);
                p = glm::clamp(c + r * glm::vec3(s * std::cos(phi), s * std::sin(phi), z), -boxHalf, boxHalf);
            }
            if (glm::length(glm::cross(v[1] - v[0], v[2] - v[0])) > minCross) w.add(v[0], v[1], v[2]);
        }
    }
    return scene;
}

Scene makeMesh(const std::vector<glm::vec3>& vertices, const std::vector<glm::ivec3>& triangles, const Material& m) {
    Scene scene;
    Writer w(scene, m, triangles.size());
    for (const glm::ivec3& t : triangles) w.add(vertices[size_t(t.x)], vertices[size_t(t.y)], vertices[size_t(t.z)]);
    return scene;
}

glm::mat4 gridCopyTransform(glm::ivec3 count, glm::vec3 spacing, glm::vec3 rotateStepDeg, size_t copy) {
    count = glm::max(count, glm::ivec3(1));
    const size_t x = copy % size_t(count.x), z = copy / size_t(count.x) % size_t(count.z);
    const size_t y = copy / size_t(count.x) / size_t(count.z);
    // Centred in X and Z, stacked upwards from the object's own height in Y.
    const glm::vec3 first(-0.5f * float(count.x - 1) * spacing.x, 0.0f, -0.5f * float(count.z - 1) * spacing.z);
    const glm::vec3 offset = first + glm::vec3(float(x), float(y), float(z)) * spacing;
    const glm::mat4 turn = rotateStepDeg == glm::vec3(0.0f)
                               ? glm::mat4(1.0f)
                               : composeTransform(glm::vec3(0.0f), float(copy) * rotateStepDeg, glm::vec3(1.0f));
    return glm::translate(glm::mat4(1.0f), offset) * turn;
}

Scene makeGrid(const Scene& object, glm::ivec3 count, glm::vec3 spacing, glm::vec3 rotateStepDeg) {
    count = glm::max(count, glm::ivec3(1));
    Scene scene;
    const size_t copies = gridCopies(count);
    scene.positions.reserve(copies * object.positions.size() + 1); // + 1: see Scene::append
    scene.normals.reserve(copies * object.normals.size());
    scene.materialIds.reserve(copies * object.materialIds.size());
    for (size_t copy = 0; copy < copies; ++copy) {
        size_t matBase = scene.materials.size(), triBase = scene.triangleCount();
        scene.append(object, gridCopyTransform(count, spacing, rotateStepDeg, copy));
        // The copies share the object's materials: drop the duplicates append() made.
        if (matBase > 0) {
            scene.materials.resize(matBase);
            for (size_t t = triBase; t < scene.triangleCount(); ++t) scene.materialIds[t] -= uint32_t(matBase);
        }
    }
    return scene;
}

} // namespace shadowlab
