#include "tests/ShadowTestScenes.h"

#include "framework/scene/GltfLoader.h"
#include "framework/scene/Procedural.h"
#include "tests/TestSupport.h"

#include <glm/gtc/matrix_transform.hpp>

#include <vector>

namespace shadowlab::test {

glm::mat4 translate(glm::vec3 t) { return glm::translate(glm::mat4(1.0f), t); }
glm::mat4 rotate(float deg, glm::vec3 axis) { return glm::rotate(glm::mat4(1.0f), glm::radians(deg), axis); }
glm::mat4 scale(glm::vec3 s) { return glm::scale(glm::mat4(1.0f), s); }

Scene ground(float size) { return makePlane({size, size}, 4, Material{glm::vec3(0.7f), 1.0f}); }

Camera lookAt(glm::vec3 from, glm::vec3 to, float fovYDeg) {
    Camera c;
    c.position = from;
    c.target = to;
    c.fovYDeg = fovYDeg;
    c.nearPlane = 0.02f;
    c.farPlane = 50.0f;
    return c;
}

Light pointLight(glm::vec3 position) {
    Light l;
    l.type = LightType::Point;
    l.position = position;
    return l;
}

Light directionalLight(glm::vec3 from) {
    Light l;
    l.type = LightType::Directional;
    l.position = from;
    l.target = {0, 0, 0};
    return l;
}

Shot intersectingTriangles() {
    Shot s;
    s.scene = ground();
    Material m{glm::vec3(0.8f, 0.4f, 0.3f), 1.0f};
    s.scene.addTriangles({{-1.2f, 0.4f, -0.6f}, {1.2f, 0.4f, -0.6f}, {0.0f, 1.2f, 0.9f},     // gently sloped
                          {-0.9f, 1.3f, -0.9f}, {1.0f, 0.3f, 0.8f}, {0.7f, 1.4f, 0.1f},      // crosses the first
                          {-1.6f, -0.6f, 1.0f}, {-0.3f, -0.6f, 1.2f}, {-0.9f, 1.1f, 0.4f}}, // pierces the ground
                         m);
    s.camera = lookAt({2.5f, 3.0f, 3.5f}, {0, 0.3f, 0});
    s.light = pointLight({0.6f, 4.0f, -0.4f});
    return s;
}

Shot omniInsideShell() {
    Shot s;
    const glm::vec3 c(0.0f, 1.5f, 0.0f);
    Scene sphere = makeSphere(0.6f, 800, Material{});
    std::vector<glm::vec3> kept;
    const glm::vec3 holes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0.6f, 0, -0.8f}};
    for (size_t t = 0; t < sphere.triangleCount(); ++t) {
        glm::vec3 centroid = (sphere.positions[3 * t] + sphere.positions[3 * t + 1] + sphere.positions[3 * t + 2]) / 3.0f;
        bool hole = false;
        for (glm::vec3 h : holes) hole = hole || glm::dot(glm::normalize(centroid), glm::normalize(h)) > 0.97f;
        if (!hole)
            for (int k = 0; k < 3; ++k) kept.push_back(sphere.positions[3 * t + k] + c);
    }
    s.scene.addTriangles(kept, Material{glm::vec3(0.9f, 0.8f, 0.3f), 1.0f});
    Scene wall = makePlane({6, 6}, 3, Material{glm::vec3(0.7f), 1.0f});
    s.scene.append(wall, glm::mat4(1.0f));                                  // floor
    s.scene.append(wall, translate({0, 3, 0}) * rotate(180, {1, 0, 0}));     // ceiling
    s.scene.append(wall, translate({-3, 1.5f, 0}) * rotate(-90, {0, 0, 1})); // walls
    s.scene.append(wall, translate({3, 1.5f, 0}) * rotate(90, {0, 0, 1}));
    s.scene.append(wall, translate({0, 1.5f, -3}) * rotate(90, {1, 0, 0}));
    s.scene.append(wall, translate({0, 1.5f, 3}) * rotate(-90, {1, 0, 0}));
    s.camera = lookAt({2.6f, 2.6f, 2.6f}, {-0.5f, 1.0f, -0.5f}, 100.0f);
    s.light = pointLight(c + glm::vec3(0.05f, -0.03f, 0.02f));
    return s;
}

Shot directionalObjects() {
    Shot s;
    s.scene = ground();
    s.scene.append(makeSphere(0.6f, 600, Material{}), translate({-0.8f, 0.8f, 0}));
    s.scene.append(makeTorus(0.5f, 0.15f, 500, Material{}), translate({0.9f, 0.6f, 0.3f}) * rotate(60, {1, 0, 0}));
    s.scene.append(makeCylinder(0.25f, 1.2f, 200, Material{}), translate({0.2f, 0.0f, -1.0f}));
    s.camera = lookAt({0.0f, 3.0f, 4.5f}, {0, 0.3f, 0});
    s.light = directionalLight({3.0f, 5.0f, 2.0f});
    return s;
}

Shot cameraInsideShadow() {
    Shot s;
    s.scene = ground();
    s.scene.append(makePlane({3, 3}, 2, Material{}), translate({0, 1.5f, 0}));
    s.scene.append(makeSphere(0.3f, 300, Material{}), translate({0.8f, 0.3f, 0.8f}));
    s.camera = lookAt({0.2f, 0.8f, 0.3f}, {3.0f, 0.0f, 3.0f});
    s.light = pointLight({0.3f, 5.0f, 0.2f});
    return s;
}

// `scene`'s triangles whose centroid passes `keep`, as a new open mesh.
namespace {
template <class Keep> Scene cut(const Scene& scene, Keep keep) {
    std::vector<glm::vec3> kept;
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
        const glm::vec3* v = &scene.positions[3 * t];
        if (keep((v[0] + v[1] + v[2]) / 3.0f))
            for (int k = 0; k < 3; ++k) kept.push_back(v[k]);
    }
    Scene out;
    out.addTriangles(kept, Material{});
    return out;
}
} // namespace

// A point light amid 600 random triangles (a soup: no two share an edge, many pierce one another)
// and two boxes of open planes, over a ground: volumes start all around the light.
Shot lightAmidClutter() {
    Shot s;
    s.scene = ground();
    s.scene.append(makeTriangleSoup(600, {3.0f, 1.6f, 3.0f}, 0.25f, 11, Material{}), translate({0, 1.6f, 0}));
    s.camera = lookAt({0.5f, 4.5f, 4.0f}, {0, 0.5f, 0});
    s.light = pointLight({0.1f, 1.7f, 0.2f});
    return s;
}

// A fence of thin posts and rails under a directional light 4° above the horizon: long, thin
// shadows on ground lit at a grazing angle (n . l = 0.07).
Shot grazingOverThin() {
    Shot s;
    s.scene = ground();
    s.scene.append(makeFence(9, 0.45f, 0.6f, 0.015f, 2, 24, Material{}), translate({0, 0, -0.5f}));
    s.camera = lookAt({0.4f, 2.5f, 3.0f}, {0, 0, -1.0f});
    const float elevation = glm::radians(4.0f);
    s.light = directionalLight({std::cos(elevation) * 0.6f, std::sin(elevation), -std::cos(elevation) * 0.8f});
    return s;
}

// Open meshes: a bowl (the lower half of a sphere), a tube (a cylinder without its ends) and a
// box without a lid, under a point light that shines into all three.
Shot openMeshes() {
    Shot s;
    s.scene = ground();
    Scene bowl = cut(makeSphere(0.5f, 800, Material{}), [](glm::vec3 c) { return c.y < 0.0f; });
    s.scene.append(bowl, translate({-1.0f, 0.6f, 0.2f}));
    Scene tube = cut(makeCylinder(0.25f, 0.9f, 200, Material{}), [](glm::vec3 c) { return c.y > 0.01f && c.y < 0.89f; });
    s.scene.append(tube, translate({0.8f, 0.3f, -0.6f}) * rotate(30, {0, 0, 1}));
    Scene box;
    box.append(makePlane({0.8f, 0.8f}, 1, Material{}), glm::mat4(1.0f));
    for (int k = 0; k < 4; ++k)
        box.append(makePlane({0.8f, 0.6f}, 1, Material{}),
                   rotate(90.0f * float(k), {0, 1, 0}) * translate({0, 0.3f, 0.4f}) * rotate(90, {1, 0, 0}));
    s.scene.append(box, translate({0.4f, 0.05f, 0.9f}));
    s.camera = lookAt({0.0f, 3.2f, 4.0f}, {0, 0.3f, 0});
    s.light = pointLight({-0.6f, 3.0f, 1.2f});
    return s;
}

// Non-manifold fins: five quads around one vertical edge (that edge has five triangles, each
// other edge of a fin one or two), a soup of 300 triangles, and a sphere, under a spot light.
Shot finsAndSoup() {
    Shot s;
    s.scene = ground();
    for (int k = 0; k < 5; ++k)
        s.scene.append(makePlane({0.6f, 0.8f}, 1, Material{}),
                       translate({-0.6f, 0.45f, 0}) * rotate(72.0f * float(k), {0, 1, 0}) * translate({0.3f, 0, 0}) *
                           rotate(90, {1, 0, 0}));
    s.scene.append(makeTriangleSoup(300, {1.2f, 0.6f, 1.2f}, 0.2f, 5, Material{}), translate({0.8f, 0.9f, 0.3f}));
    s.scene.append(makeSphere(0.3f, 300, Material{}), translate({0.2f, 0.3f, -0.9f}));
    s.camera = lookAt({0.0f, 3.0f, 4.0f}, {0, 0.3f, 0});
    s.light = pointLight({0.4f, 3.5f, 1.0f});
    s.light.type = LightType::Spot;
    s.light.target = {0, 0, 0};
    s.light.coneDeg = 40.0f;
    return s;
}

Shot engineOnGround() {
    Shot s;
    Scene e = loadGltf(kEngineGlb);
    const float k = 3.0f / e.bounds.radius();
    const glm::vec3 c = e.bounds.center();
    s.scene = ground(12.0f);
    s.scene.append(e, translate({0, 1.6f, 0}) * scale(glm::vec3(k)) * translate(-c));
    s.camera = lookAt({4.0f, 4.5f, 5.5f}, {0, 1.2f, 0});
    s.light = pointLight({3.0f, 8.0f, 2.0f});
    return s;
}

Shot thousandsOfTriangles() {
    Shot s;
    s.scene = ground();
    s.scene.append(makeSphere(0.6f, 2000, Material{}), translate({-0.8f, 0.8f, 0}));
    s.scene.append(makeTorus(0.5f, 0.15f, 1500, Material{}), translate({0.9f, 0.6f, 0.3f}) * rotate(60, {1, 0, 0}));
    s.camera = lookAt({0.0f, 3.0f, 5.0f}, {0, 0.4f, 0});
    s.light = pointLight({2.0f, 4.0f, 1.5f});
    return s;
}

Shot smokePointShot() {
    Shot s;
    s.scene = makePlane({8, 8}, 4, Material{});
    s.scene.append(makeSphere(0.6f, 2000, Material{}), translate({-0.8f, 0.8f, 0}));
    s.scene.append(makeTorus(0.5f, 0.15f, 1500, Material{}), translate({0.9f, 0.6f, 0.3f}) * rotate(60, {1, 0, 0}));
    s.scene.append(makeFence(6, 0.35f, 1.0f, 0.03f, 2, 32, Material{}), translate({0, 0, -1.2f}));
    s.camera = lookAt({0, 3.0f, 5.0f}, {0, 0.4f, 0}, 55.0f);
    s.light = pointLight({2.0f, 4.0f, 1.5f});
    return s;
}

Shot smokeSpotShot() {
    Shot s = smokePointShot();
    s.light.type = LightType::Spot;
    s.light.position = {-1.5f, 3.5f, 2.0f};
    s.light.target = {0, 0, 0};
    s.light.coneDeg = 35.0f;
    return s;
}

Shot narrowSpot() {
    Shot s = smokeSpotShot();
    s.light.coneDeg = 22.0f;
    return s;
}

Shot smokeDirectionalShot() {
    Shot s = smokePointShot();
    s.light = directionalLight({3.0f, 4.0f, 2.0f});
    return s;
}

Shot smokeAreaShot(int samples, float side, const char* pattern) {
    Shot s = smokePointShot();
    s.light.type = LightType::Area;
    s.light.position = {1.5f, 3.0f, 1.5f};
    s.light.target = {0, 0, 0};
    s.light.size = {side, side};
    s.light.samples = samples;
    s.light.pattern = pattern;
    return s;
}

Shot withEdgeOnWall(Shot s) {
    // makePlane lies in y = 0; turned about z it lies in x = 0, then moved to the light's x.
    const glm::vec3 l = s.light.position, c = s.scene.bounds.center();
    s.scene.append(makePlane({2.0f, 2.0f}, 2, Material{}), translate({l.x, c.y, c.z}) * rotate(90, {0, 0, 1}));
    return s;
}

} // namespace shadowlab::test
