// The reference (EmbreeTracer) against shadows known in closed form: horizontal squares over a
// ground plane, seen through a synthetic CPU G-buffer whose "pixels" are points on y = 0.
// No GL: the tracer is GL-free, and the algorithm entry is only inspected, never run.
#include "framework/core/Error.h"
#include "framework/reference/EmbreeTracer.h"
#include "algorithms/reference/Reference.h"
#include "framework/scene/GltfLoader.h"
#include "tests/ShadowTestScenes.h"
#include "tests/TestSupport.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <thread>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>

namespace shadowlab {
namespace {

const float kNaN = std::numeric_limits<float>::quiet_NaN();
// Absolute ray offset of these tests. The ground plane is part of the scene, so a zero offset
// would let the receiving points shadow themselves; 1e-3 is far above float error at this scale.
const float kOffset = 1e-3f;

/// A horizontal square caster: side a, at height h, centred over (centre.x, centre.y) in xz.
struct Layer {
    float h, a;
    glm::vec2 centre;
    float opacity = 1.0f;
};

void addSquare(Scene& s, glm::vec2 c, float a, float y, float opacity) {
    float r = 0.5f * a;
    glm::vec3 p00(c.x - r, y, c.y - r), p10(c.x + r, y, c.y - r), p11(c.x + r, y, c.y + r), p01(c.x - r, y, c.y + r);
    s.addTriangles({p00, p11, p10, p00, p01, p11}, Material{glm::vec3(0.8f), opacity});
}

Scene layeredScene(const std::vector<Layer>& layers, bool ground = true) {
    Scene s;
    if (ground) addSquare(s, {0, 0}, 100.0f, 0.0f, 1.0f); // the ground the receivers lie on
    for (const auto& l : layers) addSquare(s, l.centre, l.a, l.h, l.opacity);
    return s;
}

/// n × n points on y = 0 over [-half, half]², normal `normal`; every `holeEvery`-th pixel is background.
CpuGBuffer groundGrid(int n, float half, glm::vec3 normal = {0, 1, 0}, int holeEvery = 0) {
    CpuGBuffer g;
    g.width = g.height = n;
    g.position.resize(4 * size_t(n) * n);
    g.normal.resize(4 * size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            size_t i = size_t(y) * n + x;
            float px = -half + 2 * half * (x + 0.5f) / n, pz = -half + 2 * half * (y + 0.5f) / n;
            bool hole = holeEvery > 0 && i % size_t(holeEvery) == 0;
            float* p = &g.position[4 * i];
            p[0] = px, p[1] = 0, p[2] = pz, p[3] = hole ? 0.0f : 1.0f;
            float* q = &g.normal[4 * i];
            q[0] = normal.x, q[1] = normal.y, q[2] = normal.z, q[3] = 0;
        }
    return g;
}

using test::pointLight;

Light directionalLight(glm::vec3 dir) {
    Light l;
    l.type = LightType::Directional;
    l.target = glm::vec3(0);
    l.position = -glm::normalize(dir) * 10.0f;
    return l;
}

Light spotLight(glm::vec3 pos, float coneDeg) {
    Light l = pointLight(pos);
    l.type = LightType::Spot;
    l.target = {pos.x, 0, pos.z};
    l.coneDeg = coneDeg;
    return l;
}

/// The square's shadow on y = 0: [min.x, max.x] × [min.y, max.y] in xz. Projecting a horizontal
/// axis-aligned square from a point (a scaling about the light's foot) or along a direction (a
/// translation) keeps it an axis-aligned square, so the corners' bounding box is the shadow.
struct Rect {
    glm::vec2 min{1e30f}, max{-1e30f};
};

Rect projectLayer(const Layer& ly, const Light& light) {
    Rect r;
    for (int k = 0; k < 4; ++k) {
        glm::vec3 c(ly.centre.x + (k & 1 ? 0.5f : -0.5f) * ly.a, ly.h, ly.centre.y + (k & 2 ? 0.5f : -0.5f) * ly.a);
        glm::vec3 p;
        if (light.type == LightType::Directional) {
            glm::vec3 d = light.direction();
            p = c - d * (c.y / d.y);
        } else {
            glm::vec3 l = light.position;
            p = l + (c - l) * (l.y / (l.y - c.y));
        }
        r.min = glm::min(r.min, glm::vec2(p.x, p.z));
        r.max = glm::max(r.max, glm::vec2(p.x, p.z));
    }
    return r;
}

/// Expected hard-shadow visibility at ground point p: the product of the transmissions of the
/// layers whose shadow (shrunk by margin) contains p; NaN where p is within `margin` of an edge.
float hardShadow(const std::vector<Layer>& layers, const Light& light, glm::vec3 p, float margin) {
    float v = 1.0f;
    for (const auto& ly : layers) {
        Rect r = projectLayer(ly, light);
        bool inside = p.x > r.min.x + margin && p.x < r.max.x - margin && p.z > r.min.y + margin && p.z < r.max.y - margin;
        bool outside = p.x < r.min.x - margin || p.x > r.max.x + margin || p.z < r.min.y - margin || p.z > r.max.y + margin;
        if (!inside && !outside) return kNaN;
        if (inside) v *= 1.0f - ly.opacity;
    }
    return v;
}

/// Expected area-light visibility at p: the fraction of sample segments (from the ray origin, as the
/// tracer casts them) that miss every opaque layer; NaN where a segment passes within `margin`
/// of a square's edge, where float rounding may decide either way.
float areaShadow(const std::vector<Layer>& layers, const Light& light, glm::vec3 p, float margin) {
    glm::vec3 o = p + glm::vec3(0, kOffset, 0);
    auto samples = light.samplePoints();
    float visible = 0.0f;
    for (glm::vec3 s : samples) {
        bool blocked = false;
        for (const auto& ly : layers) {
            glm::vec3 q = o + (s - o) * ((ly.h - o.y) / (s.y - o.y)); // the segment at the square's height
            float dx = std::abs(q.x - ly.centre.x) - 0.5f * ly.a, dz = std::abs(q.z - ly.centre.y) - 0.5f * ly.a;
            if (std::abs(dx) < margin || std::abs(dz) < margin) return kNaN;
            blocked = blocked || (dx < 0 && dz < 0);
        }
        if (!blocked) visible += 1.0f;
    }
    return visible / float(samples.size());
}

/// One row of the table: a scene, a light, receivers, and the expected visibility per receiver.
struct Case {
    const char* name;
    std::vector<Layer> layers;
    Light light;
    CpuGBuffer gbuffer;
    /// Expected visibility of covered pixel (p, n); NaN = too close to an edge to decide, skipped.
    std::function<float(const Case&, glm::vec3 p, glm::vec3 n)> expected;
    float tolerance; ///< |traced - expected| allowed
    int minChecked;  ///< the case must actually test this many pixels
    bool ground = true; ///< whether the ground plane under the receivers is part of the scene
};

std::vector<Case> analyticCases() {
    // Margin of the hard cases: grid points closer than this to a shadow edge are skipped, since the
    // ray origin sits kOffset above the point (moving the edge by up to kOffset · |slope| ≈ 3e-3 here)
    // and the edge position itself carries float error. The grid spacing is 0.047, so few are skipped.
    const float m = 0.01f;
    auto hard = [m](const Case& c, glm::vec3 p, glm::vec3) { return hardShadow(c.layers, c.light, p, m); };
    std::vector<Case> cases;
    // (a) point light, square centred below it, and off-centre with an off-centre light.
    cases.push_back({"point_centred", {{1.0f, 1.0f, {0, 0}}}, pointLight({0, 5, 0}), groundGrid(128, 3), hard, 0, 5000});
    cases.push_back({"point_off_centre", {{1.5f, 0.8f, {0.3f, -0.4f}}}, pointLight({1.2f, 4, -0.7f}), groundGrid(128, 3),
                     hard, 0, 5000});
    // A caster close to the light: a 6x magnified shadow.
    cases.push_back({"point_magnified", {{2.5f, 0.4f, {0, 0}}}, pointLight({0, 3, 0}), groundGrid(128, 3), hard, 0, 5000});
    // (b) directional light: straight down and oblique.
    cases.push_back({"directional_vertical", {{1.0f, 1.2f, {0.2f, 0.1f}}}, directionalLight({0, -1, 0}), groundGrid(128, 3),
                     hard, 0, 5000});
    cases.push_back({"directional_oblique", {{1.0f, 1.0f, {0, 0}}}, directionalLight({0.6f, -1, 0.3f}), groundGrid(128, 3),
                     hard, 0, 5000});
    // (c) area light: exact fraction of the 16 sample segments that clear the square. The counts are
    // exact and so is k/16 in float, hence tolerance 0.
    {
        Light area;
        area.type = LightType::Area;
        area.position = {0.2f, 4, 0.1f};
        area.target = {0.2f, 0, 0.1f};
        area.size = {1.5f, 1.0f};
        area.samples = 16;
        area.pattern = "stratified";
        area.seed = 7;
        auto fn = [](const Case& c, glm::vec3 p, glm::vec3) { return areaShadow(c.layers, c.light, p, 1e-4f); };
        cases.push_back({"area_penumbra", {{1.5f, 1.0f, {0, 0}}}, area, groundGrid(96, 3), fn, 0, 5000});
    }
    // (d) spot light, 30° cone, with a caster inside the cone: outside the cone 0, inside the hard shadow.
    {
        Light spot = spotLight({0, 4, 0}, 30.0f);
        auto fn = [m](const Case& c, glm::vec3 p, glm::vec3) {
            float angle = glm::degrees(std::acos(glm::dot(glm::normalize(p - c.light.position), c.light.direction())));
            // 0.2°: the cone test is one float comparison of a cosine; stay clear of its rounding.
            if (std::abs(angle - c.light.coneDeg) < 0.2f) return kNaN;
            return angle > c.light.coneDeg ? 0.0f : hardShadow(c.layers, c.light, p, m);
        };
        cases.push_back({"spot_cone", {{2.0f, 0.5f, {0.3f, 0}}}, spot, groundGrid(128, 3.5f), fn, 0, 5000});
    }
    // (e) transparent casters: 0.5 under one half-transparent square, 0.25 under two stacked ones,
    // 0 where an opaque one is stacked over a transparent one. 1 - 0.5 and 0.5 · 0.5 are exact in float.
    cases.push_back({"transparent_single", {{1.0f, 1.0f, {0, 0}, 0.5f}}, pointLight({0, 5, 0}), groundGrid(128, 3), hard, 0,
                     5000});
    cases.push_back({"transparent_stacked", {{1.0f, 1.0f, {0, 0}, 0.5f}, {2.0f, 1.0f, {0.2f, 0}, 0.5f}},
                     pointLight({0, 5, 0}), groundGrid(128, 3), hard, 0, 5000});
    cases.push_back({"transparent_under_opaque", {{1.0f, 1.0f, {0, 0}, 0.5f}, {2.0f, 0.6f, {0, 0}, 1.0f}},
                     pointLight({0, 5, 0}), groundGrid(128, 3), hard, 0, 5000});
    // (f) back-facing receivers (normal away from the light) are unlit whatever the occluders; a
    // grazing normal (N·L = 0 for the light straight above) counts as back-facing too. No ground
    // here: it would block these rays anyway and hide a missing N·L test.
    auto unlit = [](const Case&, glm::vec3, glm::vec3) { return 0.0f; };
    cases.push_back({"back_facing", {{1.0f, 1.0f, {0, 0}}}, pointLight({0, 5, 0}), groundGrid(32, 3, {0, -1, 0}), unlit, 0,
                     1000, false});
    cases.push_back({"grazing_normal", {}, directionalLight({0, -1, 0}), groundGrid(32, 3, {1, 0, 0}), unlit, 0, 1000,
                     false});
    // Background pixels (w = 0) are skipped by `expected` and checked to be 1 by the runner.
    cases.push_back({"background_pixels", {{1.0f, 1.0f, {0, 0}}}, pointLight({0, 5, 0}), groundGrid(64, 3, {0, 1, 0}, 3),
                     hard, 0, 2000});
    return cases;
}

TEST(ReferenceTracer, AnalyticShadows) {
    for (const Case& c : analyticCases()) {
        SCOPED_TRACE(c.name);
        EmbreeTracer tracer(layeredScene(c.layers, c.ground));
        std::vector<float> vis;
        tracer.traceVisibility(c.gbuffer, c.light, kOffset, 2, vis);
        ASSERT_EQ(vis.size(), size_t(c.gbuffer.width) * c.gbuffer.height);
        int checked = 0, failures = 0, fractional = 0;
        for (size_t i = 0; i < vis.size(); ++i) {
            float want = c.gbuffer.covered(i) ? c.expected(c, c.gbuffer.positionAt(i), c.gbuffer.normalAt(i)) : 1.0f;
            if (std::isnan(want)) continue;
            ++checked;
            if (want > 0.0f && want < 1.0f) ++fractional;
            if (std::abs(vis[i] - want) > c.tolerance && ++failures <= 5)
                ADD_FAILURE() << "pixel " << i << " at (" << c.gbuffer.positionAt(i).x << ", "
                              << c.gbuffer.positionAt(i).z << "): traced " << vis[i] << ", expected " << want;
        }
        EXPECT_EQ(failures, 0);
        EXPECT_GE(checked, c.minChecked);
        if (std::string(c.name) == "area_penumbra") {
            EXPECT_GT(fractional, 500) << "the penumbra was not exercised";
        }
        if (std::string(c.name).rfind("transparent_", 0) == 0) {
            EXPECT_TRUE(tracer.hasTransparency());
        }
    }
}

TEST(ReferenceTracer, AreaLightCornerCases) {
    // A huge square hides the whole light rectangle from points under it; far out, nothing does.
    Light area;
    area.type = LightType::Area;
    area.position = {0, 4, 0};
    area.target = {0, 0, 0};
    area.size = {1, 1};
    area.samples = 25;
    area.pattern = "grid";
    EmbreeTracer tracer(layeredScene({{2.0f, 3.0f, {0, 0}}}));
    CpuGBuffer g = groundGrid(2, 10); // points at (±5, 0, ±5): fully lit
    g.position[0] = g.position[2] = 0.0f; // pixel 0 at the origin: fully hidden
    std::vector<float> vis;
    tracer.traceVisibility(g, area, kOffset, 1, vis);
    EXPECT_EQ(vis[0], 0.0f);
    for (int i = 1; i < 4; ++i) EXPECT_EQ(vis[i], 1.0f);
    EXPECT_EQ(tracer.lastRayCount(), 4u * 25u);
    // Behind the area light's plane, nothing is lit.
    g.position[1] = 5.0f;
    g.normal[1] = -1.0f;
    tracer.traceVisibility(g, area, kOffset, 1, vis);
    EXPECT_EQ(vis[0], 0.0f);
}

TEST(ReferenceTracer, MultiThreadedEqualsSingleThreadedBitForBit) {
    // A cluttered scene with transparent and opaque triangles under an area light: every code path.
    Scene s = layeredScene({});
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> pos(-2.5f, 2.5f), hgt(0.2f, 3.0f), off(-0.3f, 0.3f);
    for (int t = 0; t < 400; ++t) {
        glm::vec3 c(pos(rng), hgt(rng), pos(rng));
        s.addTriangles({c + glm::vec3(off(rng), off(rng), off(rng)), c + glm::vec3(off(rng), off(rng), off(rng)),
                        c + glm::vec3(off(rng), off(rng), off(rng))},
                       Material{glm::vec3(0.5f), t % 3 == 0 ? 0.4f : 1.0f});
    }
    Light area;
    area.type = LightType::Area;
    area.position = {0.5f, 4, 0};
    area.target = {0, 0, 0};
    area.samples = 16;
    EmbreeTracer tracer(s);
    CpuGBuffer g = groundGrid(96, 3, {0, 1, 0}, 7);
    std::vector<float> one, two, many;
    tracer.traceVisibility(g, area, kOffset, 1, one);
    uint64_t raysOne = tracer.lastRayCount();
    tracer.traceVisibility(g, area, kOffset, 2, two);
    tracer.traceVisibility(g, area, kOffset, 13, many); // more threads than cores and an uneven split
    ASSERT_EQ(one.size(), two.size());
    ASSERT_EQ(one.size(), many.size());
    EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(one.data(), many.data(), one.size() * sizeof(float)), 0);
    EXPECT_EQ(tracer.lastRayCount(), raysOne);
    int partial = 0;
    for (float v : one) partial += v > 0.0f && v < 1.0f;
    EXPECT_GT(partial, 100); // the comparison covered soft and transparent shadows
}

TEST(ReferenceTracer, OccludedAndTransmission) {
    EmbreeTracer tracer(layeredScene({{1.0f, 1.0f, {0, 0}, 0.5f}}));
    glm::vec3 o(0, 0.5f, 0), up(0, 1, 0);
    EXPECT_TRUE(tracer.occluded(o, up, 10.0f));    // any triangle blocks, whatever its opacity
    EXPECT_FALSE(tracer.occluded(o, up, 0.4f));    // the segment ends below the square
    EXPECT_FALSE(tracer.occluded({3, 0.5f, 0}, up, 10.0f)); // misses it
    // Through the square's centre, i.e. exactly through the diagonal both of its triangles share:
    // one surface crossing, so 0.5 and not 0.25.
    EXPECT_EQ(tracer.transmission(o, up, 10.0f), 0.5f);
    EXPECT_EQ(tracer.transmission({0.5f, 0.5f, 0.5f}, up, 10.0f), 0.5f); // through a corner vertex
    EXPECT_EQ(tracer.transmission({0.2f, 0.5f, -0.1f}, up, 10.0f), 0.5f); // inside one triangle
    EXPECT_EQ(tracer.transmission(o, up, 0.4f), 1.0f);
    EXPECT_EQ(tracer.transmission(o, -up, 10.0f), 0.0f); // the opaque ground
    // Hits count on (0, tfar], as in the algorithms' test (common/watertight.glsl): a triangle whose
    // plane holds the origin (t = 0) does not block (the exactness fuzzer: far from the origin, where
    // coordinates fall on a coarse grid, an origin on a post's face was shadowed by the reference
    // alone). Embree takes t >= tnear.
    const glm::vec3 onPlane(0.2f, 1.0f, -0.1f);
    EXPECT_FALSE(tracer.occluded(onPlane, up, 10.0f));
    EXPECT_EQ(tracer.transmission(onPlane, up, 10.0f), 1.0f);
    EXPECT_TRUE(tracer.occluded({0.2f, std::nextafter(1.0f, 0.0f), -0.1f}, up, 10.0f));
}

// A scene with a moving part: after moveTriangles + commitMoves the tracer answers for the moved
// triangles, by refit and by rebuild alike.
TEST(ReferenceTracer, MovedTrianglesAreTracedWhereTheyMoved) {
    for (auto update : {EmbreeTracer::MotionUpdate::Refit, EmbreeTracer::MotionUpdate::Rebuild}) {
        Scene s;
        s.addTriangles({{-1, 1, -1}, {1, 1, -1}, {0, 1, 1}}, Material{});  // a roof above the origin
        MovingPart part;
        part.triangleCount = 1;
        part.setLocal(s.positions);
        part.worldFromLocal = [](double t) { return glm::translate(glm::mat4(1.0f), {float(t) * 10.0f, 0, 0}); };
        s.moving.push_back(part);
        s.updateBounds();
        EmbreeTracer tracer(s, update);
        const glm::vec3 up(0, 1, 0);
        EXPECT_TRUE(tracer.occluded({0, 0, 0}, up, 5.0f));
        EXPECT_FALSE(tracer.occluded({10, 0, 0}, up, 5.0f));
        std::vector<glm::vec3> moved = s.positions;
        for (glm::vec3& v : moved) v.x += 10.0f;
        tracer.moveTriangles(0, moved.data(), 1);
        tracer.commitMoves();
        EXPECT_FALSE(tracer.occluded({0, 0, 0}, up, 5.0f));
        EXPECT_TRUE(tracer.occluded({10, 0, 0}, up, 5.0f));
        EXPECT_THROW(tracer.moveTriangles(1, moved.data(), 1), RuntimeError);
    }
}

TEST(ReferenceTracer, EmptySceneIsFullyLit) {
    EmbreeTracer tracer(Scene{});
    std::vector<float> vis;
    tracer.traceVisibility(groundGrid(8, 1), pointLight({0, 2, 0}), kOffset, 0, vis);
    ASSERT_EQ(vis.size(), 64u);
    for (float v : vis) EXPECT_EQ(v, 1.0f);
    tracer.traceVisibility(CpuGBuffer{}, pointLight({0, 2, 0}), kOffset, 0, vis);
    EXPECT_TRUE(vis.empty());
}

TEST(ReferenceTracer, TwoMillionTriangles) {
    const int n = 2'000'000;
    Scene s;
    std::vector<glm::vec3> tris;
    tris.reserve(3 * size_t(n));
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> pos(-20.0f, 20.0f), hgt(0.5f, 10.0f), off(-0.05f, 0.05f);
    for (int t = 0; t < n; ++t) {
        glm::vec3 c(pos(rng), hgt(rng), pos(rng));
        for (int k = 0; k < 3; ++k) tris.push_back(c + glm::vec3(off(rng), off(rng), off(rng)));
    }
    s.addTriangles(tris, Material{});
    tris = {};
    ASSERT_GT(s.triangleCount(), size_t(n) * 99 / 100); // random triangles are almost never degenerate

    auto t0 = std::chrono::steady_clock::now();
    EmbreeTracer tracer(s);
    auto t1 = std::chrono::steady_clock::now();
    std::vector<float> vis;
    tracer.traceVisibility(groundGrid(128, 20), pointLight({0, 30, 0}), kOffset, 0, vis);
    auto t2 = std::chrono::steady_clock::now();
    int lit = 0, dark = 0;
    for (float v : vis) lit += v == 1.0f, dark += v == 0.0f;
    EXPECT_EQ(lit + dark, int(vis.size())); // a point light gives hard shadows only
    EXPECT_GT(lit, 0);
    EXPECT_GT(dark, 0);
    // The index and vertex copies alone are 48 bytes per triangle; the BVH comes on top.
    EXPECT_GT(tracer.memoryBytes(), s.triangleCount() * 48);
    std::printf("[ info ] 2M triangles: build %.2f s, trace %.3f s, %.0f MB\n",
                std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count(),
                tracer.memoryBytes() / 1e6);
}

// The layouts that save memory at scale answer every ray as the default one does: the vertices
// read in place from the Scene (no copy) and the compact BVH nodes, on
// the engine, with rays grazing its thin parts and aimed at its vertices and edges.
TEST(ReferenceTest, SharedVerticesAndCompactBvhAnswerEveryRayAlike) {
    Scene s = loadGltf(test::kEngineGlb);
    EmbreeTracer copied(s, EmbreeTracer::MotionUpdate::Refit);
    EmbreeTracer shared(s, EmbreeTracer::MotionUpdate::Refit, EmbreeTracer::Vertices::Share);
    EmbreeTracer compact(s, EmbreeTracer::MotionUpdate::Refit, EmbreeTracer::Vertices::Share, true);
    EXPECT_FALSE(copied.sharesVertices());
    EXPECT_TRUE(shared.sharesVertices());
    EXPECT_LT(shared.memoryBytes() + 30 * s.triangleCount(), copied.memoryBytes()); // no 36-byte copy
    EXPECT_LT(compact.memoryBytes(), shared.memoryBytes());
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const glm::vec3 lo = s.bounds.min, ext = s.bounds.extent();
    int blocked = 0;
    for (int i = 0; i < 20000; ++i) {
        // Half the rays pass a hair inside a triangle next to an edge's midpoint (a thousandth of
        // the way to its third vertex), halfway along; half run from anywhere to above the engine.
        // None starts on a triangle or runs exactly along an edge: whether a hit at t = 0 or on a
        // mesh's open border counts is decided by each layout's rounding (the two differed there on
        // an AVX2 machine), and the reference asks neither (its rays start ray_offset off the surface).
        const size_t t = size_t(u(rng) * float(s.triangleCount() - 1));
        const glm::vec3 above = lo + ext * glm::vec3(u(rng), 1.5f + u(rng), u(rng));
        const glm::vec3 at = i % 2 ? above : lo + ext * glm::vec3(u(rng), u(rng), u(rng));
        const glm::vec3 nearEdge = 0.4995f * (s.positions[3 * t] + s.positions[3 * t + 1]) + 0.001f * s.positions[3 * t + 2];
        const glm::vec3 dir = i % 2 ? 2.0f * (nearEdge - above) : above - at;
        const bool a = copied.occluded(at, dir, 1.0f);
        ASSERT_EQ(shared.occluded(at, dir, 1.0f), a) << i;
        ASSERT_EQ(compact.occluded(at, dir, 1.0f), a) << i;
        blocked += a;
    }
    EXPECT_GT(blocked, 2000); // the rays do meet the engine
}

TEST(ReferenceAlgorithm, RegistryEntry) {
    AlgorithmInfo info = referenceInfo();
    EXPECT_EQ(info.name, "reference");
    EXPECT_TRUE(info.exact);
    for (LightType t : {LightType::Point, LightType::Spot, LightType::Directional, LightType::Area})
        EXPECT_NE(std::find(info.lights.begin(), info.lights.end(), t), info.lights.end()) << toString(t);
    const ParamSchema& schema = info.schema();
    EXPECT_EQ(&schema, &info.schema()); // built once
    ASSERT_EQ(schema.specs().size(), 4u);
    ASSERT_TRUE(schema.find("bvh"));
    EXPECT_EQ(std::get<std::string>(schema.find("bvh")->def), "auto");
    EXPECT_EQ(info.motion, MotionHandling::Refit);
    const ParamSpec* motion = schema.find("motion_update");
    ASSERT_TRUE(motion);
    EXPECT_EQ(std::get<std::string>(motion->def), "refit");
    EXPECT_EQ(motion->change, ParamChange::Rebuild);
    const ParamSpec* threads = schema.find("threads");
    const ParamSpec* offset = schema.find("ray_offset");
    ASSERT_TRUE(threads && offset);
    EXPECT_EQ(std::get<int>(threads->def), 0);
    EXPECT_EQ(threads->max, 256);
    EXPECT_EQ(std::get<double>(offset->def), 1e-4);
    EXPECT_EQ(offset->max, 1e-2);
    EXPECT_EQ(offset->change, ParamChange::Update);
    // Creating it touches no GL (the tracer is built in setScene()).
    auto algo = info.create(ParamValues(schema), AlgorithmOptions{});
    ASSERT_TRUE(algo);
    EXPECT_EQ(algo->memoryBytes(), 0u);
}

// Threads for a frame: what was asked, else one per kPixelsPerThread pixels up to the hardware's
// (a small frame on every hardware thread was slower and noisier than on one: the start-up and
// the join cost more than they save).
TEST(ReferenceTest, ThreadsFollowTheFramesSize) {
    const int hardware = int(std::max(1u, std::thread::hardware_concurrency()));
    EXPECT_EQ(EmbreeTracer::threadsFor(0, 128 * 128), 1);
    EXPECT_EQ(EmbreeTracer::threadsFor(0, 0), 1);
    EXPECT_EQ(EmbreeTracer::threadsFor(0, 2 * EmbreeTracer::kPixelsPerThread), std::min(2, hardware));
    EXPECT_EQ(EmbreeTracer::threadsFor(0, size_t(1) << 40), hardware);
    EXPECT_EQ(EmbreeTracer::threadsFor(13, 16), 13);
}

} // namespace
} // namespace shadowlab
