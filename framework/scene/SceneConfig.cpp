// The "scene" object of a config (full reference with examples: docs/scene.md).
//
//   {"objects": [OBJECT, ...],                                   at least one object
//    "max_triangles": N,                                         budget of the whole scene (1..200,000,000; default:
//                                                                 what the machine's memory could hold at the least
//                                                                 cost a triangle has, 104 bytes), checked before
//                                                                 anything that size is built
//    "time_range": [start, end]}                                 the clock the frames sample uniformly (default:
//                                                                 the camera path's, else the light path's, else
//                                                                 the span of the objects' motion)
//   OBJECT = {"gltf": "file.glb", "transform": T, "material": M,  path relative to the config file;
//             "animation": NAME or INDEX,                         M replaces the file's materials only if given;
//             "node_paths": [{"node": INDEX, "path": P,          the animation's node channels move its nodes; a
//                             "pivot": "centre" | "origin"}]}   node path moves a node in its own frame, about
//                                                                 the centre of its meshes (or its origin)
//          | {"procedural": KIND, ...generator keys..., "transform": T, "material": M}
//     either may carry "path": P, which moves it rigidly: world(t) = P(t) · T · object
//   P = {"keyframes": [{"time": s, "translate": [0, 0, 0], "rotate_deg": [0, 0, 0], "scale": 1 or [sx, sy, sz] (> 0)}, ...],
//        "interpolation": "catmull_rom" (default) | "linear" | "step"}
//   KIND and its keys (lengths in scene units, metres by convention):
//     plane     size [w, d] = [10, 10] (> 0), subdivisions = 1 (1..4096)      2·subdivisions² triangles
//     sphere    radius = 1, triangles = 2000                                  UV sphere at the origin
//     torus     major_radius = 1, minor_radius = 0.3 (< major), triangles = 2000  around the Y axis
//     cylinder  radius = 0.5, height = 1, triangles = 500                     along Y from y = 0, capped
//     fence     posts = 10, spacing = 0.5, height = 1.5, radius = 0.03, rails = 2, triangles_per_cylinder = 64
//     soup      triangles = 1000, extent [4, 4, 4], triangle_size = 0.2, seed = 1
//     mesh      vertices [[x, y, z], ...], indices [[a, b, c], ...] (default: the vertices three by
//               three)                                                  the triangles as written
//     grid      object = OBJECT (any, recursively), count [nx, ny, nz] = [2, 1, 2] (1..100000),
//               spacing [sx, sy, sz] = [2, 2, 2], rotate_step_deg [rx, ry, rz] = [0, 0, 0] (copy i, counted
//               along x, then z, then y, is turned by i × step about its own origin, Euler as in T);
//               M replaces the object's materials only if given
//     triangle requests are 1..max_triangles; generated counts are within 5 % of them (>= 1000),
//     below that each shape's closed minimum (sphere 16, torus 18, cylinder 12 triangles)
//   T = {"translate": [0, 0, 0], "rotate_deg": [0, 0, 0] (Euler degrees: X first, then Y, then Z),
//        "scale": 1 or [sx, sy, sz] (non-zero; negative mirrors),
//        "fit_size": 0 (off; > 0: scale uniformly so the largest bounding-box extent is fit_size and
//                       put the box centred on the origin in X/Z with its bottom at y = 0, before the rest)}
//   M = {"albedo": [0.8, 0.8, 0.8] (linear RGB in [0, 1]), "opacity": 1 (in [0, 1])}
//
// The whole config is read and checked (unknown keys included) before anything is generated or
// loaded, so a typo in the last object fails at once instead of after building a 10 M triangle sphere.
#include "framework/scene/SceneConfig.h"

#include "framework/core/CheckedMath.h"
#include "framework/core/JsonParse.h"
#include "framework/core/SystemMemory.h"
#include "framework/core/Text.h"
#include "framework/scene/GltfLoader.h"
#include "framework/scene/Procedural.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <utility>

namespace shadowlab {
namespace {

const std::vector<std::string> kKinds = {"plane", "sphere", "torus", "cylinder", "fence", "soup", "mesh", "grid"};
constexpr int kMaxTrianglesCeiling = int(kMaxSceneTriangles);
/// The default max_triangles follows the machine: the triangles whose least possible footprint
/// (kMinBytesPerTriangle: the Scene's 52 bytes on the host and its 52 on the GPU, which a software
/// renderer also keeps in host memory) fits in its memory. It guards against a typo (a grid of
/// 10,000 × 10,000); what a run will really need is checked against the memory available by
/// checkMemoryPlan (framework/experiment/MemoryPlan.h) before anything that size is made.
int defaultMaxTriangles() {
    const double total = double(systemMemory().total);
    if (!(total > 0)) return 20'000'000; // no /proc/meminfo: the old fixed default
    return int(std::min<double>(kMaxTrianglesCeiling, total / double(kMinBytesPerTriangle)));
}
constexpr int kMaxGridDepth = 8;

/// An object's generator (run later) and the triangles it will make, known without making them
/// (generated objects from the tessellation their generator uses, a glTF file by loading it), so
/// the memory a scene needs can be checked before anything that size exists. Only triangles made
/// degenerate by a size or transform are dropped when made: the count is then an upper bound.
struct Builder {
    std::function<Scene()> make;
    std::function<size_t()> count;
    bool moves = false; ///< it has a path, an animation or node paths (or holds an object that does)
    /// The materials it brings (Scene::append keeps every one of them): 1 when not set.
    std::function<size_t()> materials = {};
    size_t materialCount() const { return materials ? materials() : 1; }
    /// Triangles in moving parts and the parts (upper bounds); none when not set.
    std::function<std::pair<size_t, size_t>()> moving = {};
    std::pair<size_t, size_t> movingCount() const { return moving ? moving() : std::pair<size_t, size_t>{0, 0}; }
    /// Grids: the triangles of the object the innermost grid repeats (its copies lie one after the
    /// other in the built scene, however the grids nest); 0 when not set (not a grid).
    std::function<size_t()> leaf = {};
    size_t leafCount() const { return leaf ? leaf() : 0; }
    /// Its triangles are a mesh's (or a grid's of a mesh), each held to the 1 % shape rule
    /// wherever it is placed: by a transform, a grid's copy or a path's pose.
    bool written = false;
    Scene operator()() const { return make(); }
};

/// The triangles of a grid of `copies` copies of an object of `objectTriangles`; a grid past the
/// scene's budget (a product past 2^64 included) is refused at its "count", whether it is being
/// made or only predicted.
size_t gridTriangles(const JsonNode& grid, size_t objectTriangles, size_t copies, int budget) {
    const std::optional<size_t> total = checkedMul(objectTriangles, copies);
    if (!total || *total > size_t(budget))
        grid.fail("count", "the grid would have " + (total ? std::to_string(*total) : "more than 2^64") + " triangles (" +
                               std::to_string(copies) + " copies of " + std::to_string(objectTriangles) +
                               "), more than the scene's max_triangles (" + std::to_string(budget) + ")");
    return *total;
}

/// The scene's triangles once `objectTriangles` more are added to `sceneTriangles`, refused at the
/// object that takes the scene past its budget.
size_t addWithinBudget(const JsonNode& object, size_t sceneTriangles, size_t objectTriangles, int budget) {
    const std::optional<size_t> total = checkedAdd(sceneTriangles, objectTriangles);
    if (!total || *total > size_t(budget))
        object.failHere("the scene would have " + (total ? std::to_string(*total) : "more than 2^64") +
                        " triangles with this object, more than max_triangles (" + std::to_string(budget) + ")");
    return *total;
}

float positive(JsonNode& node, const std::string& key, double def) {
    double v = node.getFloat(key, def, 0.0);
    if (!(v > 0.0)) node.fail(key, "must be greater than 0");
    return float(v);
}

Material readMaterial(JsonNode node) {
    Material m;
    m.albedo = node.getVec3("albedo", glm::vec3(0.8f));
    if (glm::any(glm::lessThan(m.albedo, glm::vec3(0.0f))) || glm::any(glm::greaterThan(m.albedo, glm::vec3(1.0f))))
        node.fail("albedo", "values must lie in [0, 1]");
    m.opacity = float(node.getFloat("opacity", 1.0, 0.0, 1.0));
    node.finish();
    return m;
}

struct Transform {
    glm::mat4 matrix{1.0f};  // translate · rotate · scale, applied after the fit
    float fitSize = 0.0f;
};

Transform readTransform(JsonNode node) {
    glm::vec3 translate = node.getPoint("translate", glm::vec3(0.0f));
    glm::vec3 rotDeg = node.getVec3("rotate_deg", glm::vec3(0.0f));
    glm::vec3 scale = readScale(node);
    if (glm::any(glm::equal(scale, glm::vec3(0.0f)))) node.fail("scale", "scale factors must be non-zero");
    Transform t;
    t.fitSize = float(node.getFloat("fit_size", 0.0, 0.0));
    node.finish();
    t.matrix = composeTransform(translate, rotDeg, scale);
    return t;
}

/// Transforms a scene in place (no second copy of a big scene), with Scene::append's rules:
/// mirroring flips the winding back, triangles that become degenerate are dropped.
void transformInPlace(Scene& s, const glm::mat4& m) {
    if (s.dynamic()) {  // moving triangles are never dropped and their motions take `m`: append's rules
        Scene out;
        out.append(s, m);
        s = std::move(out);
        return;
    }
    bool mirrored = glm::determinant(glm::mat3(m)) < 0.0f;
    size_t kept = 0;
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        glm::vec3 v[3];
        for (int k = 0; k < 3; ++k) v[k] = glm::vec3(m * glm::vec4(s.positions[3 * t + size_t(k)], 1.0f));
        if (mirrored) std::swap(v[1], v[2]);
        glm::vec3 n;
        if (!unitNormal(v[0], v[1], v[2], n)) continue;
        for (int k = 0; k < 3; ++k) s.positions[3 * kept + size_t(k)] = v[k];
        s.normals[kept] = n;
        s.materialIds[kept] = s.materialIds[t];
        ++kept;
    }
    s.positions.resize(3 * kept);
    s.normals.resize(kept);
    s.materialIds.resize(kept);
    s.updateBounds();
}

void overrideMaterials(Scene& s, const Material& m) {
    s.materials = {m};
    std::fill(s.materialIds.begin(), s.materialIds.end(), 0u);
}

Builder parseObject(JsonNode node, int depth, int budget);

/// The floats a mesh's written coordinates become must keep each triangle's shape: its longest
/// edge and its height over it within 1 % of the written ones (ninth probe: a sliver 0.004 wide
/// written at x = 1e5 became 0.0078 wide, within the 1 % of its 4-unit length). Coordinates
/// written as floats (as the exactness fuzzer writes them) change nothing.
void checkWrittenShapes(JsonNode& node, const std::vector<glm::vec3>& vertices, const std::vector<glm::ivec3>& triangles, bool indexed) {
    const Json& raw = node.raw().at("vertices");
    auto written = [&](int v) {
        const Json& p = raw[size_t(v)];
        return glm::dvec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    };
    for (size_t t = 0; t < triangles.size(); ++t) {
        const glm::ivec3 i = triangles[t];
        const glm::dvec3 exact[3] = {written(i.x), written(i.y), written(i.z)};
        const glm::vec3 f[3] = {vertices[size_t(i.x)], vertices[size_t(i.y)], vertices[size_t(i.z)]};
        const double change = shapeChange(f, exact);
        const double height = edgeAndHeight(exact[0], exact[1], exact[2]).second;
        const double heightF = edgeAndHeight(glm::dvec3(f[0]), glm::dvec3(f[1]), glm::dvec3(f[2])).second;
        if (!(change <= 0.01)) {
            char text[320];
            std::snprintf(text, sizeof text,
                          "triangle %zu: its coordinates as floats change its shape by %.3g %% (at most 1 %%; its height %.3g becomes %.3g): "
                          "move it nearer the origin or make it larger",
                          t, 100.0 * change, height, heightF);
            node.fail(indexed ? "indices/" + std::to_string(t) : "vertices/" + std::to_string(3 * t), text);
        }
    }
}

/// A mesh's triangles, as written (the exactness fuzzer's scenes and the cases it shrinks,
/// docs/exactness_fuzzing.md): vertices and optional index triples. A triangle without area at
/// float precision is refused, never dropped: a run does not succeed on a scene it changed.
Builder parseMesh(JsonNode& node, const Material& m, int budget) {
    if (!node.has("vertices")) node.fail("vertices", "a mesh needs its \"vertices\"");
    const std::vector<glm::vec3> vertices = node.getPointList("vertices");
    if (vertices.size() > 3 * size_t(budget))
        node.fail("vertices", std::to_string(vertices.size()) + " vertices, more than 3 × the scene's max_triangles (" +
                                  std::to_string(budget) + ")");
    const bool indexed = node.has("indices");
    std::vector<glm::ivec3> triangles = node.getIndexTriples("indices", int(vertices.size()));
    if (!indexed) {
        if (vertices.size() < 3 || vertices.size() % 3 != 0)
            node.fail("vertices", "without \"indices\" the vertices are taken three by three: " + std::to_string(vertices.size()) +
                                      " is not a positive multiple of 3");
        for (int v = 0; v < int(vertices.size()); v += 3) triangles.emplace_back(v, v + 1, v + 2);
    }
    if (triangles.empty()) node.fail("indices", "a mesh needs at least one triangle");
    if (triangles.size() > size_t(budget))
        node.fail("indices", std::to_string(triangles.size()) + " triangles, more than the scene's max_triangles (" +
                                 std::to_string(budget) + ")");
    for (size_t t = 0; t < triangles.size(); ++t) {
        glm::vec3 n;
        const glm::ivec3 i = triangles[t];
        const glm::vec3 &a = vertices[size_t(i.x)], &b = vertices[size_t(i.y)], &c = vertices[size_t(i.z)];
        if (unitNormal(a, b, c, n)) continue;
        // Two causes, told apart (twenty-first probe: edges of 1e15 were called collinear).
        const bool overflows = !std::isfinite(glm::length(glm::cross(b - a, c - a)));
        node.fail(indexed ? "indices/" + std::to_string(t) : "vertices/" + std::to_string(3 * t),
                  "triangle " + std::to_string(t) +
                      (overflows ? " has edges too long for float (past about 1e9 units its normal's length overflows)"
                                 : " has no area at float precision (its vertices are collinear or repeated)"));
    }
    checkWrittenShapes(node, vertices, triangles, indexed);
    const size_t count = triangles.size();
    Builder b{[=] { return makeMesh(vertices, triangles, m); }, [=] { return count; }};
    b.written = true;
    return b;
}

/// Each triangle of `placed` (the triangles of `object`, copy after copy, each copy placed by
/// `matrixOf(copy)`) keeps, as floats, the shape of the object's floats placed in double within 1 %
/// (tenth probe: a mesh's sliver in a grid copy 2 units away lost 20 % of its height). A placement
/// that dropped triangles is refused by checkBuilt() instead.
void checkPlacedShapes(const JsonNode& node, const Scene& object, const Scene& placed, const char* what,
                       const std::function<glm::mat4(size_t)>& matrixOf) {
    const size_t n = object.triangleCount();
    if (n == 0 || placed.triangleCount() % n != 0) return;
    for (size_t copy = 0; copy < placed.triangleCount() / n; ++copy) {
        const glm::dmat4 m(matrixOf(copy));
        for (size_t t = 0; t < n; ++t) {
            glm::dvec3 exact[3];
            for (size_t k = 0; k < 3; ++k) exact[k] = glm::dvec3(m * glm::dvec4(glm::dvec3(object.positions[3 * t + k]), 1.0));
            const double change = shapeChange(&placed.positions[3 * (copy * n + t)], exact);
            if (!(change <= 0.01)) {
                char text[320];
                std::snprintf(text, sizeof text, "triangle %zu of the mesh %s %zu: placed there, its float coordinates change its "
                                                 "shape by %.3g %% (at most 1 %%): place it nearer the origin or make it larger",
                              t, what, copy + 1, 100.0 * change);
                node.failHere(text);
            }
        }
    }
}

/// Reads a procedural object's generator keys; returns the generator (run later). `budget` is the
/// scene's triangle limit: a request above it fails here, before any memory is spent on it.
Builder parseGenerator(JsonNode& node, const std::string& kind, const Material& m, int depth, int budget) {
    auto triangles = [&](int def) { return node.getInt("triangles", def, 1, budget); };
    if (kind == "plane") {
        glm::vec2 size = node.getVec2("size", glm::vec2(10.0f));
        if (!(size.x > 0.0f && size.y > 0.0f)) node.fail("size", "both sizes must be greater than 0");
        int sub = node.getInt("subdivisions", 1, 1, 4096);
        return Builder{[=] { return makePlane(size, sub, m); }, [=] { return planeTriangles(sub); }};
    }
    if (kind == "sphere") {
        float r = positive(node, "radius", 1.0);
        int n = triangles(2000);
        return Builder{[=] { return makeSphere(r, n, m); }, [=] { return sphereTessellation(n).triangles(); }};
    }
    if (kind == "torus") {
        float major = positive(node, "major_radius", 1.0), minor = positive(node, "minor_radius", 0.3);
        // A tube reaching the axis (horn or spindle torus) is not a closed surface any more.
        if (!(minor < major))
            node.fail("minor_radius", "must be smaller than major_radius (as floats they are " + shortNumber(minor, 9) + " and " +
                                          shortNumber(major, 9) + ")");
        int n = triangles(2000);
        return Builder{[=] { return makeTorus(major, minor, n, m); },
                       [=] { return torusTessellation(major, minor, n).triangles(); }};
    }
    if (kind == "cylinder") {
        float r = positive(node, "radius", 0.5), h = positive(node, "height", 1.0);
        int n = triangles(500);
        return Builder{[=] { return makeCylinder(r, h, n, m); }, [=] { return cylinderTessellation(r, h, n).triangles(); }};
    }
    if (kind == "fence") {
        int posts = node.getInt("posts", 10, 1, 100000);
        float spacing = positive(node, "spacing", 0.5), height = positive(node, "height", 1.5);
        float radius = positive(node, "radius", 0.03);
        int rails = node.getInt("rails", 2, 0, 1000);
        int perCylinder = node.getInt("triangles_per_cylinder", 64, 1, 1'000'000);
        const size_t fenceTriangles = fenceLayout(posts, spacing, height, radius, rails, perCylinder).triangles();
        if (fenceTriangles > size_t(budget))
            node.fail("triangles_per_cylinder", "the fence would have " + std::to_string(fenceTriangles) +
                                                    " triangles, more than the scene's max_triangles (" +
                                                    std::to_string(budget) + ")");
        return Builder{[=] { return makeFence(posts, spacing, height, radius, rails, perCylinder, m); },
                       [=] { return fenceTriangles; }};
    }
    if (kind == "soup") {
        int n = triangles(1000);
        glm::vec3 extent = node.getVec3("extent", glm::vec3(4.0f));
        if (glm::any(glm::lessThan(extent, glm::vec3(0.0f)))) node.fail("extent", "extents must not be negative");
        float size = positive(node, "triangle_size", 0.2);
        uint32_t seed = uint32_t(node.getInt("seed", 1, 0));
        return Builder{[=] { return makeTriangleSoup(n, extent, size, seed, m); }, [=] { return soupTriangles(n); }};
    }
    if (kind == "mesh") return parseMesh(node, m, budget);
    // grid
    if (depth >= kMaxGridDepth) node.fail("object", "grids nest deeper than " + std::to_string(kMaxGridDepth) + " levels");
    if (!node.has("object")) node.fail("object", "a grid needs the \"object\" to repeat");
    // Shared by the four functions below, never copied into each: a copy per function and level
    // grew as 8^depth (fourth probe: 8 nested grids of one plane took 10 GB before anything was made).
    const auto inner = std::make_shared<const Builder>(parseObject(node.child("object"), depth + 1, budget));
    glm::ivec3 count = node.getIVec3("count", glm::ivec3(2, 1, 2), 1, 100000);
    glm::vec3 spacing = node.getVec3("spacing", glm::vec3(2.0f));
    glm::vec3 rotateStep = node.getVec3("rotate_step_deg", glm::vec3(0.0f));
    const size_t copies = gridCopies(count);
    Builder grid{[=] {
        Scene object = (*inner)();
        gridTriangles(node, object.triangleCount(), copies, budget);
        Scene made = makeGrid(object, count, spacing, rotateStep);
        if (inner->written)
            checkPlacedShapes(node, object, made, "in the grid's copy",
                              [&](size_t copy) { return gridCopyTransform(count, spacing, rotateStep, copy); });
        return made;
    }, [=] { return gridTriangles(node, inner->count(), copies, budget); }, inner->moves,
                   [=] { return saturatingMul(inner->materialCount(), copies); },
                   [=] {
                       const auto [triangles, parts] = inner->movingCount();
                       return std::pair{saturatingMul(triangles, copies), saturatingMul(parts, copies)};
                   },
                   [=] { return inner->leafCount() ? inner->leafCount() : inner->count(); }};
    grid.written = inner->written;
    return grid;
}

/// Refuses `what` (lying in `b`) where a float's spacing exceeds 1 % of its size.
void checkPrecision(JsonNode& node, const std::string& what, const Bounds& b) {
    if (const std::string why = floatDistortion(b); !why.empty())
        node.failHere(what + ", " + why + ": move the scene nearer the origin or make the object larger");
}

/// A mesh's triangles are each written by hand: each is held to the 1 % rule on its own (eighth
/// probe: one large triangle hid a small one that rounding had changed by half its size). The
/// error names the triangle where it was written.
/// And placed by `m`, each keeps its written shape within 1 % as a placed triangle's floats: its
/// longest edge and its height over it against the written coordinates placed in double (tenth
/// probe: a sliver that passed as written, moved by 1 in z, lost 20 % of its height).
void checkEachTriangle(const Scene& s, JsonNode& node, const glm::mat4& m) {
    const bool indexed = node.has("indices");
    const Json& raw = node.raw().at("vertices");
    const Json& indices = indexed ? node.raw().at("indices") : Json();
    const glm::dmat4 dm(m);
    auto placed = [&](size_t t, int k) {
        const size_t v = indexed ? indices[t][size_t(k)].get<size_t>() : 3 * t + size_t(k);
        const Json& p = raw[v];
        return glm::dvec3(dm * glm::dvec4(p[0].get<double>(), p[1].get<double>(), p[2].get<double>(), 1.0));
    };
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        const std::string where = indexed ? "indices/" + std::to_string(t) : "vertices/" + std::to_string(3 * t);
        Bounds b;
        for (size_t k = 0; k < 3; ++k) b.extend(s.positions[3 * t + k]);
        if (const std::string why = floatDistortion(b); !why.empty())
            node.fail(where, "triangle " + std::to_string(t) + ", " + why + ": move the scene nearer the origin or make the triangle larger");
        if (m == glm::mat4(1.0f)) continue; // as written: checkWrittenShapes
        const glm::dvec3 exact[3] = {placed(t, 0), placed(t, 1), placed(t, 2)};
        const double change = shapeChange(&s.positions[3 * t], exact);
        const double height = edgeAndHeight(exact[0], exact[1], exact[2]).second;
        const double heightF = edgeAndHeight(glm::dvec3(s.positions[3 * t]), glm::dvec3(s.positions[3 * t + 1]),
                                             glm::dvec3(s.positions[3 * t + 2])).second;
        if (!(change <= 0.01)) {
            char text[320];
            std::snprintf(text, sizeof text, "triangle %zu: placed by its transform, its float coordinates change its shape by %.3g %% "
                                             "(at most 1 %%; its height %.3g becomes %.3g): place it nearer the origin or make it larger",
                          t, 100.0 * change, height, heightF);
            node.fail(where, text);
        }
    }
}

/// The built object must be usable: an overflowing radius or scale turns every triangle into
/// infinities (then dropped as degenerate) or puts it beyond float range; both are bad input, not
/// an object that silently vanishes.
/// And it must be the object the config describes (sixth probe: a fence with posts at ±1e15 lost
/// 15 of its 50 triangles, a sphere of radius 4e10 64 % of its own, and a sphere moved to 1e7 was
/// drawn as a disc, all runs "valid"): a
/// generated object that lost triangles to float rounding (`exactCount`: what its generator
/// makes, 0 when not known exactly, as for a glTF file's own degenerate triangles), or that lies
/// where a float's spacing exceeds 1 % of its size, is refused, naming the precision there.
void checkBuilt(const Scene& s, JsonNode& node, size_t exactCount, size_t leaf) {
    if (s.triangleCount() == 0)
        node.failHere("the object has no triangles left: every one is degenerate or overflows a float (check sizes, "
                      "radii and scale)");
    for (int i = 0; i < 3; ++i)
        if (!(std::abs(double(s.bounds.min[i])) <= kMaxCoordinate && std::abs(double(s.bounds.max[i])) <= kMaxCoordinate))
            node.failHere("the object reaches beyond ±1e15 scene units (check sizes, radii, scale and translate)");
    if (exactCount > 0 && s.triangleCount() < exactCount && s.moving.empty())
        node.failHere(std::to_string(exactCount - s.triangleCount()) + " of its " + std::to_string(exactCount) +
                      " triangles have no normal in float (" + floatPrecisionAt(s.bounds) +
                      "; a triangle needs an area the coordinates' precision can show, and edges below about 1e9 units): "
                      "move the scene nearer the origin, or change the object's size");
    checkPrecision(node, "the object", s.bounds);
    // A grid's copies, each on its own (seventh probe: 2 copies 1e8 apart of a 2-unit sphere passed
    // as one object 1e8 across; each copy lay where a float's spacing is 4).
    if (leaf > 0 && s.triangleCount() % leaf == 0 && s.triangleCount() > leaf)
        for (size_t first = 0; first < s.triangleCount(); first += leaf) {
            Bounds b;
            for (size_t v = 3 * first; v < 3 * (first + leaf); ++v) b.extend(s.positions[v]);
            checkPrecision(node, "copy " + std::to_string(first / leaf + 1) + " of the grid's " + std::to_string(s.triangleCount() / leaf) +
                                     " (its innermost object)", b);
        }
}

/// Reads and checks one OBJECT (and, for grids, the objects inside it) without building anything.
Builder parseObject(JsonNode node, int depth, int budget) {
    bool isGltf = node.has("gltf"), isProcedural = node.has("procedural");
    if (isGltf && isProcedural) node.failHere("an object takes either \"gltf\" or \"procedural\", not both");
    if (!isGltf && !isProcedural)
        node.failHere("an object needs \"gltf\" (a file) or \"procedural\" (plane, sphere, torus, cylinder, fence, "
                      "soup, mesh or grid)");

    Builder build;
    std::string kind = isGltf ? "gltf" : node.getEnum("procedural", "", kKinds);
    // Generated objects always have a material (defaults included); files and grids keep their own unless given one.
    bool overrideMaterial = node.has("material");
    bool readMat = overrideMaterial || (kind != "gltf" && kind != "grid");
    Material material = readMat ? readMaterial(node.child("material")) : Material{};
    if (isGltf) {
        std::string path = node.getPath("gltf", "");
        if (path.empty()) node.fail("gltf", "expected the path of a .gltf or .glb file");
        std::error_code ec;
        const std::filesystem::file_status status = std::filesystem::status(path, ec);
        if (!std::filesystem::exists(status)) node.fail("gltf", "glTF file not found: " + shortText(path, 300));
        if (!std::filesystem::is_regular_file(status))
            node.fail("gltf", "not a regular file (a folder, FIFO or device cannot be a glTF file): " + shortText(path, 300));
        std::string where = node.file() + " at " + node.childPath("gltf");
        std::string animation;  // a name, or an index written as a decimal string
        if (node.has("animation")) {
            const Json& raw = node.raw().at("animation");
            if (raw.is_number_integer() && raw.get<int64_t>() >= 0) animation = std::to_string(raw.get<int64_t>());
            else if (raw.is_string() && !raw.get<std::string>().empty()) animation = raw.get<std::string>();
            else node.fail("animation", "expected an animation's name or index, got " + shortDump(raw));
            node.markRead("animation");
        }
        GltfMotion motion;
        motion.animation = animation;
        std::map<size_t, std::string> nodesMoved;  // node → the node_paths entry that moves it
        for (JsonNode& np : node.objectArray("node_paths")) {
            GltfNodeMotion nm;
            if (!np.has("node")) np.fail("node", "required key is missing");
            if (!np.has("path")) np.fail("path", "required key is missing");
            nm.node = size_t(np.getInt("node", 0, 0));
            // A node has one path: a second would replace the first, which would silently not move.
            if (auto [it, fresh] = nodesMoved.emplace(nm.node, np.path()); !fresh)
                np.fail("node", "node " + std::to_string(nm.node) + " already has a path (" + it->second +
                                    "); give each node one path");
            nm.aboutCentre = np.getEnum("pivot", "centre", {"centre", "origin"}) == "centre";
            RigidPath path = RigidPath::parse(np.child("path"));
            nm.motion = path.motion();
            nm.startTime = path.startTime();
            nm.endTime = path.endTime();
            np.finish();
            motion.nodes.push_back(std::move(nm));
        }
        build.make = [path, where, budget, motion] {
            try {
                return loadGltf(path, nullptr, size_t(budget), motion);
            } catch (const InputError& e) {
                // Still an error about the glTF file; the suffix says which config entry asked for it.
                throw InputError(e.file(), e.jsonPath(), e.cause() + " (loaded from " + where + ")");
            }
        };
        // Counted by loading it, once for both counts.
        auto counted = std::make_shared<std::optional<std::array<size_t, 4>>>();
        auto load = [make = build.make, counted] {
            if (!*counted) {
                const Scene s = make();
                *counted = {s.triangleCount(), s.materials.size(), s.movingTriangleCount(), s.moving.size()};
            }
            return **counted;
        };
        build.count = [load] { return load()[0]; };
        build.materials = [load] { return load()[1]; };
        build.moving = [load] { return std::pair{load()[2], load()[3]}; };
        build.moves = !motion.animation.empty() || !motion.nodes.empty();
    } else {
        build = parseGenerator(node, kind, material, depth, budget);
    }
    JsonNode transformNode = node.child("transform");
    Transform transform = readTransform(transformNode);
    // One copy of the path, shared by every copy of the object a grid makes: a long path in a large
    // grid would otherwise be copied per instance (gigabytes for 20,000 keys in a 30×30 grid).
    std::shared_ptr<const RigidPath> path;
    if (node.has("path")) path = std::make_shared<const RigidPath>(RigidPath::parse(node.child("path")));
    const MotionFn motion = path ? MotionFn([path](double time) { return path->at(time); }) : MotionFn();
    node.finish();

    // One shared copy of what it places (see the grid's).
    const auto built = std::make_shared<const Builder>(std::move(build));
    Builder placed;
    placed.count = [built] { return built->count(); };
    placed.materials = [built] { return built->materialCount(); };
    placed.moves = built->moves || path != nullptr;
    placed.leaf = [built] { return built->leafCount(); };
    placed.written = built->written;
    // A path moves the whole object: its static runs (at most one more than its parts) become parts.
    placed.moving = [built, moves = path != nullptr] {
        if (!moves) return built->movingCount();
        return std::pair{built->count(), saturatingSum({saturatingMul(2, built->movingCount().second), 1})};
    };
    placed.make = [=]() mutable {
        Scene s = (*built)();
        // What it should hold: a generator's exact count (a grid's too), at least what was made
        // before this placement's transform (a glTF file's, its own degenerate triangles dropped).
        const size_t expected = kind == "gltf" ? s.triangleCount() : std::max(s.triangleCount(), built->count());
        if (overrideMaterial && (kind == "gltf" || kind == "grid")) overrideMaterials(s, material);
        glm::mat4 m = transform.matrix;
        if (transform.fitSize > 0.0f) {
            s.updateBounds();
            glm::vec3 ext = s.bounds.extent();
            float largest = std::max({ext.x, ext.y, ext.z});
            if (s.bounds.empty() || !(largest > 0.0f)) transformNode.fail("fit_size", "the object has no extent to fit");
            float k = transform.fitSize / largest;
            glm::vec3 anchor(s.bounds.center().x, s.bounds.min.y, s.bounds.center().z);
            m = m * glm::scale(glm::mat4(1.0f), glm::vec3(k)) * glm::translate(glm::mat4(1.0f), -anchor);
        }
        // A grid of meshes placed by a transform: its triangles against the grid's, placed in double.
        std::optional<Scene> before;
        if (built->written && kind != "mesh" && m != glm::mat4(1.0f)) before = s;
        if (m != glm::mat4(1.0f)) transformInPlace(s, m);
        // The path moves the placed object: world(t) = path(t) · transform · object.
        if (path) {
            s.attachMotion(motion, path->startTime(), path->endTime(), path->file, path->jsonPath);
            // A part starting on a copy's first triangle holds whole copies (a grid's parts are runs of them).
            if (const size_t leaf = built->leafCount(); leaf > 0)
                for (MovingPart& part : s.moving)
                    if (part.firstTriangle % leaf == 0) part.setCopies(leaf);
        }
        if (built->written)
            for (MovingPart& part : s.moving) part.heldEachTriangle = true;  // checked at every pose (Config.cpp)
        checkBuilt(s, node, expected, built->leafCount());
        if (kind == "mesh") checkEachTriangle(s, node, m);
        if (before) checkPlacedShapes(node, *before, s, "in the transformed grid's copy", [&](size_t) { return m; });
        return s;
    };
    return placed;
}

} // namespace

/// The scene's objects, each checked, with the budget they are built under; nothing is generated
/// or loaded yet.
struct ParsedScene {
    int budget;
    bool hasTimeRange = false;
    glm::dvec2 timeRange{0.0};
    std::vector<JsonNode> objects;
    std::vector<Builder> builders;
};

static ParsedScene parseScene(JsonNode& sceneNode) {
    ParsedScene p;
    p.budget = sceneNode.getInt("max_triangles", defaultMaxTriangles(), 1, kMaxTrianglesCeiling);
    if (sceneNode.has("time_range")) {
        glm::vec2 r = sceneNode.getVec2("time_range", glm::vec2(0.0f));
        if (!(r.y >= r.x)) sceneNode.fail("time_range", "expected [start, end] with end >= start");
        p.hasTimeRange = true;
        p.timeRange = glm::dvec2(r);
    }
    p.objects = sceneNode.objectArray("objects");
    for (JsonNode& object : p.objects) p.builders.push_back(parseObject(object, 0, p.budget));
    sceneNode.finish();
    if (p.builders.empty()) sceneNode.fail("objects", "scene has no objects");
    return p;
}

void checkScene(JsonNode sceneNode) { parseScene(sceneNode); }

ScenePrediction predictScene(JsonNode sceneNode) {
    ParsedScene parsed = parseScene(sceneNode);
    ScenePrediction p;
    for (size_t i = 0; i < parsed.builders.size(); ++i) {
        p.triangles = addWithinBudget(parsed.objects[i], p.triangles, parsed.builders[i].count(), parsed.budget);
        p.moving |= parsed.builders[i].moves;
        p.materials = saturatingSum({p.materials, parsed.builders[i].materialCount()});
        const auto [movingTriangles, movingParts] = parsed.builders[i].movingCount();
        p.movingTriangles = saturatingSum({p.movingTriangles, movingTriangles});
        p.movingParts = saturatingSum({p.movingParts, movingParts});
    }
    return p;
}

void absolutiseScenePaths(Json& object, const std::string& baseDir) {
    if (!object.is_object()) return;
    // A path whose text the config's own check refuses is left as written, for that check to name
    // (probe 26: "dd/\u202e/../g.gltf" from a sweep axis folded to "dd/g.gltf" and was taken).
    if (object.contains("gltf") && object["gltf"].is_string() && pathTextProblem(object["gltf"].get<std::string>()).empty())
        object["gltf"] = resolvePath(baseDir, object["gltf"].get<std::string>());
    if (object.contains("object")) absolutiseScenePaths(object["object"], baseDir);
    if (object.contains("objects") && object["objects"].is_array())
        for (Json& o : object["objects"]) absolutiseScenePaths(o, baseDir);
}

/// An object that grew while it was made (a glTF file's meshes appended one by one) keeps no
/// slack for the run: its vectors are copied to their size (positions + 1 vertex, see
/// Scene::append), within the load's peak of twice the scene.
static void fitCapacity(Scene& scene) {
    if (scene.positions.capacity() > scene.positions.size() + 1) {
        std::vector<glm::vec3> tight;
        tight.reserve(scene.positions.size() + 1);
        tight.assign(scene.positions.begin(), scene.positions.end());
        scene.positions.swap(tight);
    }
    scene.normals.shrink_to_fit();
    scene.materialIds.shrink_to_fit();
    scene.materials.shrink_to_fit();
}

Scene buildScene(JsonNode sceneNode) {
    ParsedScene parsed = parseScene(sceneNode);
    const std::vector<Builder>& builders = parsed.builders;
    const std::vector<JsonNode>& objects = parsed.objects;
    const int budget = parsed.budget;
    // Every object is made first, then the scene reserved once at its exact size (+ 1 vertex, see
    // Scene::append) and each object appended and freed in turn: at most twice the scene is ever
    // held (the plan's load peak), where growing the scene object by object would double its
    // capacity and keep the slack for the whole run.
    std::vector<Scene> made;
    size_t total = 0;
    for (size_t i = 0; i < builders.size(); ++i) {
        made.push_back(builders[i]());
        total = addWithinBudget(objects[i], total, made.back().triangleCount(), budget);
    }
    Scene scene;
    if (made.size() == 1) {
        scene = std::move(made[0]);
        fitCapacity(scene);
    } else {
        size_t materials = 0;
        for (const Scene& s : made) materials += s.materials.size();
        scene.positions.reserve(3 * total + 1);
        scene.normals.reserve(total);
        scene.materialIds.reserve(total);
        scene.materials.reserve(materials);
        for (Scene& s : made) {
            scene.append(s, glm::mat4(1.0f));
            s = Scene();
        }
    }
    scene.updateBounds();
    scene.hasTimeRange = parsed.hasTimeRange;
    scene.timeRange = parsed.timeRange;
    return scene;
}

std::vector<std::string> gltfPathsOf(const Json& scene) {
    std::vector<std::string> out;
    const std::function<void(const Json&)> walk = [&](const Json& j) {
        if (j.is_object()) {
            for (const auto& [k, v] : j.items())
                if (k == "gltf" && v.is_string()) out.push_back(v.get<std::string>());
                else walk(v);
        } else if (j.is_array()) {
            for (const Json& v : j) walk(v);
        }
    };
    walk(scene);
    return out;
}

/// The files a glTF file's geometry comes from: itself and, for a .gltf, the buffer files its
/// buffers name (relative, not data: URIs). A file that cannot be read names no buffers.
std::vector<std::string> gltfFiles(const std::string& gltf) {
    std::vector<std::string> files = {gltf};
    try {
        if (gltf.size() < 5 || gltf.compare(gltf.size() - 5, 5, ".gltf") != 0) return files;
        const Json doc = JsonNode::parseFile(gltf);
        if (doc.is_object() && doc.contains("buffers") && doc["buffers"].is_array())
            for (const Json& b : doc["buffers"])
                if (b.is_object() && b.contains("uri") && b["uri"].is_string() && !b["uri"].get<std::string>().starts_with("data:"))
                    files.push_back(resolvePath(parentDir(gltf), percentDecoded(b["uri"].get<std::string>())));
    } catch (const InputError&) {
    }
    return files;
}

std::vector<std::string> configInputFiles(const Json& config, const std::string& configFile) {
    namespace fs = std::filesystem;
    std::vector<std::string> inputs = {configFile};
    const fs::path folder = fs::absolute(configFile).parent_path();
    for (const std::string& g : gltfPathsOf(config.value("scene", Json())))
        for (const std::string& file : gltfFiles(fs::path(g).is_absolute() ? g : (folder / g).string())) inputs.push_back(file);
    return inputs;
}

} // namespace shadowlab
