#pragma once
// Builds the scene from the config's "scene" object.
#include "framework/core/JsonNode.h"
#include "framework/scene/Scene.h"

namespace shadowlab {

/// The most triangles any scene may have (its max_triangles' ceiling): 32-bit vertex indices
/// (Embree's) and GLsizei draw counts stay far from overflow.
constexpr size_t kMaxSceneTriangles = 200'000'000;

/// Reads {"objects": [...]} (schema: docs/scene.md) and returns the world-space triangle soup.
/// Every error (unknown keys, bad values, unreadable or malformed glTF) is an InputError.
Scene buildScene(JsonNode sceneNode);

/// Every "gltf" path of a scene's JSON (its objects, a grid's object, nested), as written there:
/// the files a run reads besides its config.
std::vector<std::string> gltfPathsOf(const Json& scene);
/// The files a glTF file's geometry comes from: itself and, for a .gltf, the buffer files its
/// buffers name (relative, not data: URIs). A file that cannot be read names no buffers.
std::vector<std::string> gltfFiles(const std::string& gltf);
/// Every file a config read from `configFile` takes as input: the config itself and each glTF file
/// of its scene with its buffer files, relative paths resolved against the config's folder.
std::vector<std::string> configInputFiles(const Json& config, const std::string& configFile);
/// The same checks as buildScene (keys, values, glTF files present, triangle limits) without
/// generating or loading anything, so thousands of scenes can be checked in a moment. A malformed
/// glTF file is found only when it is loaded.
void checkScene(JsonNode sceneNode);
/// The scene's triangles, from the same checks plus each object's count, without making anything
/// big: generated objects are counted from the tessellation their generators use (minimums and
/// rounding included), grids multiply their object's count, and glTF files are loaded to be
/// counted. Exact, except that triangles a size or transform makes degenerate are dropped when
/// made. A scene (or grid) past max_triangles is refused here, as buildScene would refuse it.
struct ScenePrediction {
    size_t triangles = 0;
    bool moving = false; ///< some object has a path, an animation or node paths
    size_t materials = 0; ///< the materials its objects bring (a grid's copies each bring theirs)
    /// Upper bounds of the triangles in moving parts and of the parts (an object with a path moves
    /// whole; a glTF file's animated nodes as loaded; a grid's copies each move).
    size_t movingTriangles = 0, movingParts = 0;
};
ScenePrediction predictScene(JsonNode sceneNode);
/// Rewrites every "gltf" path of a scene (or of one object, and of grids' inner objects) against
/// `baseDir`, so the JSON keeps its meaning when written to another folder.
void absolutiseScenePaths(Json& sceneOrObject, const std::string& baseDir);

} // namespace shadowlab
