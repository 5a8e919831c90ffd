// The watertight ray–triangle test that every exact GPU algorithm decides by
// (shaders/common/watertight.glsl), shot at a ray through an edge two triangles share. Without
// `precise`, GLSL 4.50 section 4.7.1 lets a compiler contract `a*b - c*d` into
// `fma(a, b, -(c*d))`, and NVIDIA and AMD do by default: then each triangle rounds the other
// product, both edge values can come out negative and the ray slips between the triangles. The
// fault SHADOWLAB_FAULT_FMA_EDGES writes every edge function in that contracted form, which
// llvmpipe never produces by itself.
#include "framework/gl/GlObjects.h"
#include "framework/gl/Shader.h"
#include "framework/reference/EmbreeTracer.h"
#include "framework/reference/Watertight.h"
#include "tests/TestSupport.h"

#include <glm/glm.hpp>
#include <cmath>
#include <random>
#include <vector>

namespace shadowlab {
namespace {

using namespace test;

// Two triangles in z = 0 sharing the edge B–C: (A, B, C) and (D, C, B). The ray runs along +z
// through the origin, where the edge passes within a rounding error: B.x·C.y and B.y·C.x differ by
// 3.9e-8 and round to the same float, so uncontracted the edge value is exactly 0 (decided in
// double: triangle 0 is hit), while contracted each triangle's edge value is negative (found by a
// search over such pairs; any pair with both contracted values negative will do).
const glm::vec3 kA{-0x1.7c7888p+1f, 0x1.a30bd8p+0f, 0.0f};
const glm::vec3 kB{0x1.46db84p-1f, 0x1.28c4bcp+0f, 0.0f};
const glm::vec3 kC{-0x1.ff3c2cp-1f, -0x1.d02c52p+0f, 0.0f};
const glm::vec3 kD{0x1.7c7888p+1f, -0x1.a30bd8p+0f, 0.0f};
const glm::vec3 kOrigin{0.0f, 0.0f, -1.0f};
const glm::vec3 kDirection{0.0f, 0.0f, 1.0f};
constexpr float kTfar = 2.0f;

/// The mask of the triangles the probe shader's ray hits.
uint32_t gpuHits(const std::vector<glm::vec3>& triangles, glm::vec3 origin, glm::vec3 dir, float tfar) {
    std::vector<glm::vec4> vertices;
    for (glm::vec3 v : triangles) vertices.emplace_back(v, 1.0f);
    const std::vector<glm::vec4> rays{glm::vec4(origin, tfar), glm::vec4(dir, 0.0f)};
    GlBuffer tris = GlBuffer::fromVector(vertices);
    GlBuffer rayBuffer = GlBuffer::fromVector(rays);
    GlBuffer hits = GlBuffer::fromVector(std::vector<uint32_t>{0xDEADu});
    ShaderProgram probe = ShaderProgram::compute("tests/watertight_probe.comp");
    probe.set("uTriangles", unsigned(triangles.size() / 3));
    tris.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    rayBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
    hits.bindBase(GL_SHADER_STORAGE_BUFFER, 2);
    probe.use();
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    return hits.read<uint32_t>(1)[0];
}

class WatertightGLTest : public GLTest {};

TEST_F(WatertightGLTest, ARayThroughASharedEdgeHitsOneTriangleAsTheReferenceDoes) {
    const std::vector<glm::vec3> quad{kA, kB, kC, kD, kC, kB};
    Scene scene;
    scene.addTriangles(quad, Material{});
    EXPECT_TRUE(EmbreeTracer(scene).occluded(kOrigin, kDirection, kTfar)) << "the reference sees the quad";
    EXPECT_EQ(gpuHits(quad, kOrigin, kDirection, kTfar), 1u) << "triangle 0 alone, as decided in double";
}

TEST_F(WatertightGLTest, FaultContractedEdgeFunctionsStillHitOneTriangle) {
    ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_FMA_EDGES", "1"}});
    const std::vector<glm::vec3> quad{kA, kB, kC, kD, kC, kB};
    const uint32_t hits = gpuHits(quad, kOrigin, kDirection, kTfar);
    EXPECT_TRUE(hits == 1u || hits == 2u) << "hit mask " << hits << ": the ray slipped between the triangles";
}

// ---- The BVH's slab test (shaders/common/slab.glsl) never drops a box whose triangle is hit ---------

struct GrazingRays {
    std::vector<glm::vec4> vertices; // 3 per pair
    std::vector<glm::vec4> rays;     // (o, tfar), (d, 0) per pair
};

/// Rays aimed at a point on an edge or at a vertex of a triangle, where the triangle touches its
/// bounding box: half the triangles axis-aligned (floors and walls: a flat box), half anywhere,
/// origins 0.5 to 50 away in any direction, at offsets from the origin up to 1e3.
GrazingRays grazingRays(int pairs, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), frac(0.0f, 1.0f), dist(0.5f, 50.0f);
    std::uniform_int_distribution<int> axis(0, 2), where(0, 3);
    GrazingRays out;
    for (int i = 0; i < pairs; ++i) {
        const float offset = i % 4 == 0 ? 1e3f : 1.0f;
        glm::vec3 v[3];
        for (glm::vec3& p : v) p = glm::vec3(unit(rng), unit(rng), unit(rng)) * offset;
        if (i % 2 == 0) {
            const int a = axis(rng);
            for (glm::vec3& p : v) p[a] = v[0][a];
        }
        const int e = where(rng) % 3;
        const glm::vec3 target = where(rng) == 0 ? v[e] : glm::mix(v[e], v[(e + 1) % 3], frac(rng));
        const glm::vec3 o = target + glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng))) * dist(rng);
        for (const glm::vec3& p : v) out.vertices.emplace_back(p, 1.0f);
        out.rays.emplace_back(o, 2.0f);
        out.rays.emplace_back(target - o, 0.0f);
    }
    return out;
}

/// The probe's bits per pair: the watertight test (bit 0) and the slab test (bit 1).
std::vector<uint32_t> probePairs(const GrazingRays& g) {
    const unsigned pairs = unsigned(g.rays.size() / 2);
    GlBuffer tris = GlBuffer::fromVector(g.vertices);
    GlBuffer rays = GlBuffer::fromVector(g.rays);
    GlBuffer hits = GlBuffer::fromVector(std::vector<uint32_t>(pairs, 0u));
    ShaderProgram probe = ShaderProgram::compute("tests/slab_probe.comp");
    probe.set("uPairs", pairs);
    tris.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    rays.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
    hits.bindBase(GL_SHADER_STORAGE_BUFFER, 2);
    probe.use();
    glDispatchCompute((pairs + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    return hits.read<uint32_t>(pairs);
}

/// Pairs whose triangle the watertight test hits but whose box the slab test misses.
size_t hitsOutsideTheirBox(const GrazingRays& g, size_t* hitCount) {
    size_t outside = 0;
    *hitCount = 0;
    for (uint32_t h : probePairs(g)) {
        *hitCount += (h & 1u) != 0;
        outside += h == 1u;
    }
    return outside;
}

constexpr int kGrazingPairs = 40000;

TEST_F(WatertightGLTest, TheSlabTestKeepsEveryBoxWhoseTriangleARayGrazes) {
    size_t hit = 0;
    EXPECT_EQ(hitsOutsideTheirBox(grazingRays(kGrazingPairs, 1), &hit), 0u);
    EXPECT_GT(hit, size_t(kGrazingPairs / 4)) << "the rays must hit their triangles, or nothing is tested";
}

// A reciprocal 2 ULP off the worst way round (GLSL allows 2.5): the widening must cover it.
TEST_F(WatertightGLTest, FaultLooseReciprocalStillKeepsEveryGrazedBox) {
    ScopedShaderFaults faults(ShaderDefines{{"SHADOWLAB_FAULT_LOOSE_RECIPROCAL", "1"}});
    size_t hit = 0;
    EXPECT_EQ(hitsOutsideTheirBox(grazingRays(kGrazingPairs, 2), &hit), 0u);
    EXPECT_GT(hit, size_t(kGrazingPairs / 4));
}

// ---- The reference's C++ twin (framework/reference/Watertight.cpp) decides every pair alike -------

/// The pairs scaled by 2^k (exact, unless it leaves the normal range): from k = -42 on, the edge
/// values' products and the hit distances start to fall below the smallest normal float, which a
/// GPU may flush and C++ would not, unless both flush on purpose.
GrazingRays scaled(GrazingRays g, int k) {
    for (glm::vec4& v : g.vertices) v = glm::vec4(glm::vec3(std::ldexp(v.x, k), std::ldexp(v.y, k), std::ldexp(v.z, k)), 1.0f);
    for (glm::vec4& r : g.rays) r = glm::vec4(std::ldexp(r.x, k), std::ldexp(r.y, k), std::ldexp(r.z, k), r.w); // o and d
    return g;
}

/// Pairs on which the shader's and the twin's decisions differ; `hitCount`: the twin's hits.
size_t twinDisagreements(const GrazingRays& g, size_t* hitCount) {
    const std::vector<uint32_t> gpu = probePairs(g);
    size_t differ = 0;
    *hitCount = 0;
    for (size_t i = 0; i < gpu.size(); ++i) {
        const glm::vec4 o = g.rays[2 * i], d = g.rays[2 * i + 1];
        const watertight::Ray r = watertight::makeRay(glm::vec3(o), glm::vec3(d), o.w);
        const bool cpu = watertight::hit(r, glm::vec3(g.vertices[3 * i]), glm::vec3(g.vertices[3 * i + 1]), glm::vec3(g.vertices[3 * i + 2]));
        *hitCount += cpu;
        differ += cpu != ((gpu[i] & 1u) != 0);
    }
    return differ;
}

// Rays aimed at edges and vertices, where a tie is likeliest, at unit scale, far from the origin
// (the generator's 1e3 offsets, and 2^20 times that), and into the subnormal range: the shader and
// the reference's twin must agree on every one (the campaign's two pixels where Embree's own test
// and the shader's disagreed are tests/data/exactness/reference_tie_grazing_silhouette_*.json).
TEST_F(WatertightGLTest, TheReferencesTwinDecidesEveryGrazingPairAsTheShaderDoes) {
    for (int k : {0, 20, -40, -44}) {
        size_t hit = 0;
        EXPECT_EQ(twinDisagreements(scaled(grazingRays(kGrazingPairs, 3 + unsigned(k + 200)), k), &hit), 0u) << "scale 2^" << k;
        // At 2^-44 the edge values' products of a quarter of the pairs fall below the smallest normal float.
        EXPECT_GT(hit, size_t(kGrazingPairs / 8)) << "scale 2^" << k << ": the rays must hit their triangles";
    }
}

// The segment to a point light as both sides set it up (s - o, t in (0, 1]): rays that end exactly
// on a triangle's plane or just short of it, decided alike.
TEST_F(WatertightGLTest, TheReferencesTwinAgreesAtTheSegmentsEnd) {
    GrazingRays g = grazingRays(kGrazingPairs, 7);
    for (size_t i = 0; i < g.rays.size(); i += 2) g.rays[i].w = 1.0f; // end on the target point
    size_t hit = 0;
    EXPECT_EQ(twinDisagreements(g, &hit), 0u);
    EXPECT_GT(hit, size_t(kGrazingPairs / 8));
}

} // namespace
} // namespace shadowlab
