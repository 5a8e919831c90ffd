// Scene building on the CPU: the glTF loader against real and deliberately broken files, the
// procedural generators (counts, watertightness, winding) and the "scene" config object.
#include "framework/scene/GltfLoader.h"
#include "framework/scene/Procedural.h"
#include "framework/scene/SceneConfig.h"
#include "tests/HostileInputs.h"
#include "tests/TestSupport.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

namespace shadowlab {
namespace {

using test::kAssimpGltf;
using test::kEngineGlb;

/// The InputError a call throws (fails the test when it throws nothing or something else).
template <class F> std::string inputErrorOf(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
        return {};
    }
    ADD_FAILURE() << "expected InputError, nothing was thrown";
    return {};
}

void writeFile(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// ------------------------------------------------------------------------------------------------
// glTF

TEST(GltfTest, EngineLoadsWithTheFilesTriangleCount) {
    GltfStats stats;
    Scene s = loadGltf(kEngineGlb, &stats);
    // 75,730 triangles in its 29 meshes; nodes instance some meshes several times (one bolt mesh is used
    // 20 times), giving 121,496; 11,160 of those are degenerate (repeated indices) and are dropped.
    EXPECT_EQ(stats.meshTriangles, 75'730u);
    EXPECT_EQ(stats.instanceTriangles, 121'496u);
    EXPECT_EQ(s.triangleCount(), 110'336u);
    ASSERT_EQ(s.positions.size(), 3 * s.triangleCount());
    ASSERT_EQ(s.materialIds.size(), s.triangleCount());
    for (uint32_t id : s.materialIds) ASSERT_LT(id, s.materials.size());
    for (const auto& n : s.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
    EXPECT_FALSE(s.bounds.empty());
    EXPECT_GT(s.bounds.extent().x, 100.0f);  // the engine is modelled in millimetres
}

struct MalformedCase {
    const char* file;      ///< relative to kAssimpGltf
    const char* fragment;  ///< expected in the message: the JSON path or cause that explains the rejection
};

// Why each one is rejected. The wrongTypes files all load "successfully" in tinygltf 2.7, which ignores
// wrongly typed properties; they violate the glTF JSON schema, so the loader's type check rejects them.
const MalformedCase kMalformed[] = {
    {"IndexOutOfRange/IndexOutOfRange.gltf", "/meshes/0/primitives/0/indices"},       // index 255 ≥ 24 vertices
    {"IndexOutOfRange/AllIndicesOutOfRange.gltf", "/meshes/0/primitives/0/indices"},  // every index too large
    {"wrongTypes/badArray.gltf", "/meshes/0/primitives"},                            // an object, not an array
    {"wrongTypes/badExtension.gltf", "KHR_texture_transform"},                       // extension value is a string
    {"wrongTypes/badNumber.gltf", "/materials/0/normalTexture/scale"},               // a string
    {"wrongTypes/badObject.gltf", "/materials/0/pbrMetallicRoughness"},              // an array
    {"wrongTypes/badString.gltf", "/scenes/0/name"},                                 // the number 42
    {"wrongTypes/badUint.gltf", "/materials/0/pbrMetallicRoughness/baseColorTexture/index"},  // -1
    {"MissingBin/BoxTextured.gltf", "BoxTextured0.bin"},                             // tinygltf: file not found
    {"SchemaFailures/sceneWrongType.gltf", "at /scene:"},                            // "scene": "hello"
    {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "not finite"},             // inf in POSITION
    {"IncorrectVertexArrays/Cube.gltf", "/bufferViews/2"},                           // views past the 514-byte buffer
    {"RecursiveNodes/RecursiveNodes.gltf", "cycle"},                                 // node 0 ↔ node 1
};

// Twenty-fourth probe: a node rotation of [1e-300, 0, 0, 0] (a half turn about x once normalised)
// was refused with vertices "at -nan": its squared length underflowed to 0 in double.
TEST(GltfTest, ATinyButValidRotationIsAHalfTurn) {
    const std::string dir = test::makeTempDir("gltf-tiny-rotation");
    std::ofstream(dir + "/m.gltf") << test::triangleGltf({{"nodes", R"([{"mesh": 0, "rotation": [1e-300, 0, 0, 0]}])"}});
    const Scene s = loadGltf(dir + "/m.gltf");
    ASSERT_EQ(s.triangleCount(), 1u);
    bool turned = false;
    for (const glm::vec3& v : s.positions) turned = turned || v.y < -0.5f; // (0, 1, 0) goes to (0, -1, 0)
    EXPECT_TRUE(turned);
}

class GltfMalformedTest : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(GltfMalformedTest, ThrowsOneLineInputErrorNamingTheFile) {
    std::string file = kAssimpGltf + "/" + GetParam().file;
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    std::string msg = inputErrorOf([&] { loadGltf(file); });
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find(GetParam().fragment), std::string::npos) << msg;
}

INSTANTIATE_TEST_SUITE_P(GltfAssimpModels, GltfMalformedTest, ::testing::ValuesIn(kMalformed),
                         [](const ::testing::TestParamInfo<MalformedCase>& info) {
                             std::string name;
                             for (const char* c = info.param.file; *c && *c != '.'; ++c)
                                 name += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
                             return name;
                         });

TEST(GltfTest, MissingFileIsAnInputError) {
    std::string msg = inputErrorOf([] { loadGltf("/nonexistent/dir/model.glb"); });
    EXPECT_NE(msg.find("/nonexistent/dir/model.glb"), std::string::npos) << msg;
}

TEST(GltfTest, NonGltfFilesAreInputErrors) {
    using namespace std::string_literals;  // keeps the embedded NULs
    std::string dir = test::makeTempDir("gltf-junk");
    const std::pair<const char*, std::string> files[] = {
        {"text.gltf", "hello, not JSON\nsecond line\n"},
        {"array.gltf", "[1, 2, 3]"},
        {"truncated.glb", "glTF\x02\0\0\0"s},                               // header cut short
        {"badchunk.glb", "glTF\x02\0\0\0\x40\0\0\0\xff\0\0\0JSON{}"s},  // declares more than it has
        {"notglb.glb", R"({"asset": {"version": "2.0"}})"},                // JSON behind a .glb name
        {"noasset.gltf", R"({"meshes": []})"},
    };
    for (const auto& [name, bytes] : files) {
        std::string path = dir + "/" + name;
        writeFile(path, bytes);
        std::string msg = inputErrorOf([&] { loadGltf(path); });
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
}

/// A small glTF in `dir`: a unit quad (4 vertices) drawn as a strip by a child node under a parent.
std::string writeStripGltf(const std::string& dir, const std::string& nodes) {
    const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    writeFile(dir + "/quad.bin", std::string(reinterpret_cast<const char*>(pos), sizeof pos));
    std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": )" + nodes + R"(,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 5, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 0.5]}, "alphaMode": "BLEND"}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}],
        "bufferViews": [{"buffer": 0, "byteLength": 48}], "buffers": [{"uri": "quad.bin", "byteLength": 48}]})";
    writeFile(dir + "/quad.gltf", json);
    return dir + "/quad.gltf";
}

TEST(GltfTest, StripsAndNodeTransformsCompose) {
    std::string dir = test::makeTempDir("gltf-strip");
    // Parent moves by +10 X; child scales by 2 then turns 90° about Y (quaternion xyzw = 0, sin45, 0, cos45).
    std::string file = writeStripGltf(dir, R"([{"translation": [10, 0, 0], "children": [1]},
        {"mesh": 0, "scale": [2, 2, 2], "rotation": [0, 0.70710678, 0, 0.70710678]}])");
    Scene s = loadGltf(file);
    ASSERT_EQ(s.triangleCount(), 2u);
    // Both strip triangles keep one winding: the quad faced +Z, after the turn it faces +X.
    for (const auto& n : s.normals) EXPECT_NEAR(n.x, 1.0f, 1e-5f);
    // x = 10 (rotation maps the quad's X onto −Z), y in [0, 2], z in [−2, 0].
    EXPECT_NEAR(s.bounds.min.x, 10.0f, 1e-5f);
    EXPECT_NEAR(s.bounds.max.x, 10.0f, 1e-5f);
    EXPECT_NEAR(s.bounds.max.y, 2.0f, 1e-5f);
    EXPECT_NEAR(s.bounds.min.z, -2.0f, 1e-5f);
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_NEAR(s.materials[0].albedo.y, 0.4f, 1e-6f);
    EXPECT_NEAR(s.materials[0].opacity, 0.5f, 1e-6f);  // BLEND: alpha is opacity
}

TEST(GltfTest, SharedChildrenAndBadNodeIndicesAreRejected) {
    std::string dir = test::makeTempDir("gltf-nodes");
    std::string shared = writeStripGltf(dir, R"([{"children": [1, 2]}, {"children": [2]}, {"mesh": 0}])");
    EXPECT_NE(inputErrorOf([&] { loadGltf(shared); }).find("two parents"), std::string::npos);
    std::string badChild = writeStripGltf(dir, R"([{"children": [7], "mesh": 0}])");
    EXPECT_NE(inputErrorOf([&] { loadGltf(badChild); }).find("/nodes/0/children/0"), std::string::npos);
    std::string badMesh = writeStripGltf(dir, R"([{"mesh": 3}])");
    EXPECT_NE(inputErrorOf([&] { loadGltf(badMesh); }).find("/nodes/0/mesh"), std::string::npos);
}

// ------------------------------------------------------------------------------------------------
// Procedural generators

/// Every directed edge appears exactly once and its reverse exists: a closed, consistently wound surface.
::testing::AssertionResult isClosed(const Scene& s) {
    using Key = std::tuple<float, float, float>;
    auto key = [](const glm::vec3& v) { return Key{v.x, v.y, v.z}; };
    std::map<std::pair<Key, Key>, int> edges;
    for (size_t t = 0; t < s.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k) ++edges[{key(s.positions[3 * t + size_t(k)]), key(s.positions[3 * t + size_t(k + 1) % 3])}];
    for (const auto& [e, n] : edges) {
        if (n != 1) return ::testing::AssertionFailure() << "a directed edge is used " << n << " times";
        if (!edges.count({e.second, e.first})) return ::testing::AssertionFailure() << "an edge has only one triangle";
    }
    return ::testing::AssertionSuccess();
}

/// Normals point away from `centerOf(centroid)`, the nearest point of the shape's core.
template <class F> ::testing::AssertionResult pointsOutward(const Scene& s, F centerOf) {
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        glm::vec3 c = (s.positions[3 * t] + s.positions[3 * t + 1] + s.positions[3 * t + 2]) / 3.0f;
        if (glm::dot(s.normals[t], c - centerOf(c)) <= 0.0f)
            return ::testing::AssertionFailure() << "triangle " << t << " faces inwards";
    }
    return ::testing::AssertionSuccess();
}

void expectWithin5Percent(size_t actual, int requested) {
    EXPECT_NEAR(double(actual), double(requested), 0.05 * requested) << "requested " << requested;
}

TEST(ProceduralTest, SphereTorusCylinderHitRequestsClosedAndOutward) {
    Material m;
    for (int req : {1000, 20000}) {
        SCOPED_TRACE(req);
        Scene sphere = makeSphere(2.0f, req, m);
        expectWithin5Percent(sphere.triangleCount(), req);
        EXPECT_TRUE(isClosed(sphere));
        EXPECT_TRUE(pointsOutward(sphere, [](glm::vec3) { return glm::vec3(0.0f); }));
        EXPECT_NEAR(sphere.bounds.max.y, 2.0f, 1e-5f);

        Scene torus = makeTorus(1.0f, 0.3f, req, m);
        expectWithin5Percent(torus.triangleCount(), req);
        EXPECT_TRUE(isClosed(torus));
        EXPECT_TRUE(pointsOutward(torus, [](glm::vec3 c) { return glm::normalize(glm::vec3(c.x, 0.0f, c.z)); }));

        Scene cylinder = makeCylinder(0.5f, 1.0f, req, m);
        expectWithin5Percent(cylinder.triangleCount(), req);
        EXPECT_TRUE(isClosed(cylinder));
        EXPECT_TRUE(pointsOutward(cylinder, [](glm::vec3) { return glm::vec3(0.0f, 0.5f, 0.0f); }));
        EXPECT_NEAR(cylinder.bounds.min.y, 0.0f, 1e-6f);
        EXPECT_NEAR(cylinder.bounds.max.y, 1.0f, 1e-6f);
    }
    // Thin and long cylinders (fence parts) still hit the request.
    expectWithin5Percent(makeCylinder(0.03f, 5.0f, 1000, m).triangleCount(), 1000);
}

TEST(ProceduralTest, TinyRequestsGiveSaneClosedMinimums) {
    Material m;
    for (int req : {1, 10, 50}) {
        EXPECT_GE(makeSphere(1.0f, req, m).triangleCount(), 16u);
        EXPECT_GE(makeTorus(1.0f, 0.3f, req, m).triangleCount(), 18u);
        EXPECT_GE(makeCylinder(1.0f, 1.0f, req, m).triangleCount(), 12u);
        EXPECT_TRUE(isClosed(makeSphere(1.0f, req, m)));
        EXPECT_TRUE(isClosed(makeCylinder(1.0f, 1.0f, req, m)));
    }
}

TEST(ProceduralTest, SphereReachesTenMillionTriangles) {
    Scene s = makeSphere(1.0f, 10'000'000, Material{});
    expectWithin5Percent(s.triangleCount(), 10'000'000);
    EXPECT_EQ(s.positions.size(), 3 * s.triangleCount());
    EXPECT_NEAR(s.bounds.max.x, 1.0f, 1e-4f);
}

TEST(ProceduralTest, PlaneIsExactAndFacesUp) {
    for (int sub : {1, 3, 64}) {
        Scene p = makePlane({4.0f, 2.0f}, sub, Material{});
        EXPECT_EQ(p.triangleCount(), size_t(2 * sub * sub));
        for (const auto& n : p.normals) ASSERT_NEAR(n.y, 1.0f, 1e-6f);
        EXPECT_NEAR(p.bounds.min.x, -2.0f, 1e-6f);
        EXPECT_NEAR(p.bounds.max.z, 1.0f, 1e-6f);
    }
}

TEST(ProceduralTest, FenceIsPostsPlusRails) {
    Material m;
    for (int req : {64, 1000, 20000}) {
        Scene fence = makeFence(10, 0.5f, 1.5f, 0.03f, 2, req, m);
        size_t post = makeCylinder(0.03f, 1.5f, req, m).triangleCount();
        size_t rail = makeCylinder(0.03f, 4.5f, req, m).triangleCount();
        EXPECT_EQ(fence.triangleCount(), 10 * post + 2 * rail);
        EXPECT_EQ(fence.materials.size(), 1u);
        // Outer posts at x = ±2.25; their polygonal outline reaches at most `radius` further.
        EXPECT_LE(fence.bounds.min.x, -2.25f);
        EXPECT_GE(fence.bounds.min.x, -2.25f - 0.03f - 1e-6f);
        EXPECT_NEAR(fence.bounds.max.x, -fence.bounds.min.x, 0.03f);
        EXPECT_NEAR(fence.bounds.max.y, 1.5f, 1e-5f);
    }
    EXPECT_EQ(makeFence(1, 0.5f, 1.0f, 0.1f, 3, 100, m).triangleCount(), makeCylinder(0.1f, 1.0f, 100, m).triangleCount());
}

TEST(ProceduralTest, SoupIsExactDeterministicAndInsideTheBox) {
    Material m;
    for (int req : {1000, 20000}) {
        Scene a = makeTriangleSoup(req, {4, 2, 4}, 0.2f, 7, m);
        EXPECT_EQ(a.triangleCount(), size_t(req));
        EXPECT_TRUE(glm::all(glm::greaterThanEqual(a.bounds.min, glm::vec3(-2, -1, -2))));
        EXPECT_TRUE(glm::all(glm::lessThanEqual(a.bounds.max, glm::vec3(2, 1, 2))));
        EXPECT_EQ(a.contentHash(), makeTriangleSoup(req, {4, 2, 4}, 0.2f, 7, m).contentHash());
        EXPECT_NE(a.contentHash(), makeTriangleSoup(req, {4, 2, 4}, 0.2f, 8, m).contentHash());
    }
}

TEST(ProceduralTest, GridCopiesTheObject) {
    Material m;
    Scene sphere = makeSphere(0.5f, 1000, m);
    Scene grid = makeGrid(sphere, {3, 2, 4}, {2, 3, 2});
    EXPECT_EQ(grid.triangleCount(), 24 * sphere.triangleCount());
    EXPECT_EQ(grid.materials.size(), sphere.materials.size());
    EXPECT_NEAR(grid.bounds.min.x, sphere.bounds.min.x - 2.0f, 1e-5f);  // centred in X: copies at -2, 0, 2
    EXPECT_NEAR(grid.bounds.max.z, sphere.bounds.max.z + 3.0f, 1e-5f);  // centred in Z: copies at -3 .. 3
    EXPECT_NEAR(grid.bounds.max.y, sphere.bounds.max.y + 3.0f, 1e-5f);  // stacked up from the object's own y
}

// ------------------------------------------------------------------------------------------------
// The "scene" config object

Scene build(const std::string& text, Json* resolvedOut = nullptr) {
    Json j = Json::parse(text);
    Json resolved;
    Scene s = buildScene(JsonNode("test.json", &j, "/scene", &resolved));
    if (resolvedOut) *resolvedOut = resolved;
    return s;
}

TEST(SceneConfigTest, FitSizePutsTheEngineOnTheGround) {
    Scene s = build(R"({"objects": [{"gltf": ")" + kEngineGlb + R"(", "transform": {"fit_size": 3}}]})");
    glm::vec3 e = s.bounds.extent();
    EXPECT_NEAR(std::max({e.x, e.y, e.z}), 3.0f, 1e-4f);
    EXPECT_NEAR(s.bounds.min.y, 0.0f, 1e-4f);
    EXPECT_NEAR(s.bounds.center().x, 0.0f, 1e-4f);
    EXPECT_NEAR(s.bounds.center().z, 0.0f, 1e-4f);
    EXPECT_EQ(s.triangleCount(), 110'336u);
}

TEST(SceneConfigTest, DefaultsAreResolvedAndObjectsCombine) {
    Json resolved;
    Scene s = build(R"({"objects": [{"procedural": "plane"}, {"procedural": "sphere", "transform": {"translate": [0, 1, 0]}}]})",
                    &resolved);
    EXPECT_EQ(s.triangleCount(), 2 + makeSphere(1.0f, 2000, Material{}).triangleCount());
    EXPECT_EQ(resolved["objects"][1]["radius"], 1.0);
    EXPECT_EQ(resolved["objects"][1]["triangles"], 2000);
    EXPECT_EQ(resolved["objects"][0]["size"], Json::array({10.0, 10.0}));
    EXPECT_NEAR(s.bounds.max.y, 2.0f, 1e-5f);
    EXPECT_NEAR(s.bounds.min.x, -5.0f, 1e-5f);
}

TEST(SceneConfigTest, RotationIsXThenYThenZ) {
    // A long thin cylinder along Y: X by 90° lays it along Z, then Y by 90° turns it along X.
    Scene s = build(R"({"objects": [{"procedural": "cylinder", "radius": 0.01, "height": 4,
                      "transform": {"rotate_deg": [90, 90, 0]}}]})");
    EXPECT_NEAR(s.bounds.extent().x, 4.0f, 1e-4f);
    EXPECT_LT(s.bounds.extent().z, 0.05f);
}

TEST(SceneConfigTest, ScaleMaterialAndGrid) {
    Scene s = build(R"({"objects": [{"procedural": "grid", "count": [2, 1, 1], "spacing": [10, 0, 0],
        "material": {"albedo": [1, 0, 0], "opacity": 0.25},
        "object": {"procedural": "grid", "count": [1, 1, 3], "object": {"procedural": "sphere", "triangles": 500,
                   "transform": {"scale": [1, 2, 1]}}}}]})");
    EXPECT_EQ(s.triangleCount(), 6 * makeSphere(1.0f, 500, Material{}).triangleCount());
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].albedo, glm::vec3(1, 0, 0));
    EXPECT_FLOAT_EQ(s.materials[0].opacity, 0.25f);
    EXPECT_NEAR(s.bounds.extent().y, 4.0f, 1e-4f);
    EXPECT_NEAR(build(R"({"objects": [{"procedural": "sphere", "transform": {"scale": 3}}]})").bounds.max.y, 3.0f, 1e-4f);
}

TEST(SceneConfigTest, MeshTakesItsTrianglesAsWritten) {
    // Three by three without indices; through index triples with them. The coordinates are kept
    // bit for bit (the exactness fuzzer's shrunk cases depend on it), the winding gives the normal.
    Json resolved;
    Scene s = build(R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 0.1, -1e-3]]},
        {"procedural": "mesh", "vertices": [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]], "indices": [[0, 1, 2], [0, 2, 3]],
         "material": {"albedo": [0.5, 0.5, 0.5]}}]})", &resolved);
    ASSERT_EQ(s.triangleCount(), 3u);
    EXPECT_EQ(s.positions[2], glm::vec3(0.0f, 0.1f, -1e-3f));
    EXPECT_EQ(s.positions[5], glm::vec3(1, 1, 1));
    EXPECT_EQ(s.positions[8], glm::vec3(1, 1, 0));
    EXPECT_GT(s.normals[1].y, 0.99f);  // (0,1,0)-(0,1,1)-(1,1,1) is counter-clockwise seen from +Y
    EXPECT_EQ(resolved["objects"][1]["indices"], Json::parse("[[0, 1, 2], [0, 2, 3]]"));
    // The resolved config holds the floats used, as for every other vector (0.1 is not one).
    EXPECT_EQ(resolved["objects"][0]["vertices"][2][1].get<double>(), double(0.1f));
}

TEST(SceneConfigTest, MeshRefusesWhatItWouldHaveToChange) {
    const std::pair<const char*, std::vector<const char*>> cases[] = {
        {R"({"objects": [{"procedural": "mesh"}]})", {"/scene/objects/0/vertices", "needs"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0]]}]})", {"/scene/objects/0/vertices", "multiple of 3"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [2, 0, 0]]}]})",
         {"/scene/objects/0/vertices/0", "no area"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1e-50, 0]]}]})",
         {"/scene/objects/0/vertices/2", "float"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 3]]}]})",
         {"/scene/objects/0/indices/0", "[0, 2]"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 1]]}]})",
         {"/scene/objects/0/indices/0", "no area"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": []}]})",
         {"/scene/objects/0/indices", "at least one triangle"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 2e15, 0]]}]})",
         {"/scene/objects/0/vertices/2", "1e15"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": [[0, 0, 0], [1, 0, "x"], [0, 1, 0]]}]})", {"/scene/objects/0/vertices/1"}},
        {R"({"objects": [{"procedural": "mesh", "vertices": {"a": 1}}]})", {"/scene/objects/0/vertices", "array"}},
        // One large triangle beside a small one that float rounding changes by half its size: each
        // triangle is held to the 1 % rule (eighth probe).
        {R"({"objects": [{"procedural": "mesh", "vertices": [[-2e6, 0.5, -1], [0, 0.5, 2e6], [2e6, 0.5, -1],
            [1000000, 1, 0], [1000000, 1, 0.04], [1000000.04, 1, 0]]}]})", {"/scene/objects/0/vertices/3", "triangle 1"}},
        // A sliver 0.004 wide and 4 long at x = 1e5, where a float's spacing is 0.0078: its length
        // keeps 1 %, its width doubles (ninth probe).
        {R"({"objects": [{"procedural": "mesh", "vertices": [[1e5, 1, -2], [100000.004, 1, 2], [100000.004, 1, -2]]}]})",
         {"/scene/objects/0/vertices/0", "triangle 0", "change its shape"}},
    };
    for (const auto& [text, fragments] : cases) {
        std::string msg = inputErrorOf([&] { build(text); });
        for (const char* f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << "config " << text << "\nmessage: " << msg;
    }
}

TEST(SceneConfigTest, BadInputsAreInputErrorsWithPaths) {
    const std::pair<const char*, std::vector<const char*>> cases[] = {
        {R"({"objects": [{"procedural": "sphere", "radiuss": 2}]})", {"test.json", "/scene/objects/0/radiuss", "accepted keys"}},
        {R"({"objects": [{"procedural": "cube"}]})", {"/scene/objects/0/procedural", "accepted: plane, sphere, torus"}},
        {R"({"objects": []})", {"/scene/objects", "scene has no objects"}},
        {R"({})", {"scene has no objects"}},
        {R"({"objects": [{"procedural": "plane"}], "extra": 1})", {"/scene/extra"}},
        {R"({"objects": [{"procedural": "plane", "transform": {"scale": "big"}}]})", {"/scene/objects/0/transform/scale"}},
        {R"({"objects": [{"procedural": "plane", "material": {"albedo": [2, 0, 0]}}]})", {"/scene/objects/0/material/albedo"}},
        {R"({"objects": [{"procedural": "plane", "material": {"opacity": -1}}]})", {"/scene/objects/0/material/opacity"}},
        {R"({"objects": [{"procedural": "torus", "minor_radius": 0}]})", {"/scene/objects/0/minor_radius"}},
        {R"({"objects": [{"procedural": "torus", "minor_radius": 1}]})", {"/scene/objects/0/minor_radius", "smaller"}},
        {R"({"objects": [{"procedural": "grid", "object": {"procedural": "plane", "typo": 1}}]})",
         {"/scene/objects/0/object/typo"}},
        {R"({"objects": [{"procedural": "plane", "gltf": "x.glb"}]})", {"/scene/objects/0", "not both"}},
        {R"({"objects": [{"transform": {}}]})", {"/scene/objects/0", "needs"}},
        {R"({"objects": [{"gltf": "models/nothere.glb"}]})", {"nothere.glb", "/scene/objects/0/gltf"}},
        // A typo in a later object fails before the (big) first object is built.
        {R"({"objects": [{"procedural": "sphere", "triangles": 15000000}, {"procedural": "plane", "sise": 1}]})",
         {"/scene/objects/1/sise"}},
    };
    for (const auto& [text, fragments] : cases) {
        std::string msg = inputErrorOf([&] { build(text); });
        for (const char* f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << "config " << text << "\nmessage: " << msg;
    }
}

TEST(SceneConfigTest, MalformedGltfErrorNamesTheGltfFile) {
    std::string file = kAssimpGltf + "/IndexOutOfRange/IndexOutOfRange.gltf";
    std::string msg = inputErrorOf([&] { build(R"({"objects": [{"gltf": ")" + file + R"("}]})"); });
    EXPECT_EQ(msg.rfind(file, 0), 0u) << msg;  // the glTF file leads the message
    EXPECT_NE(msg.find("/meshes/0/primitives/0/indices"), std::string::npos) << msg;
    EXPECT_NE(msg.find("test.json"), std::string::npos) << msg;  // and the config entry that loaded it
}

} // namespace
} // namespace shadowlab
