#pragma once
// Builds the scene from the config's "scene" object.
#include "framework/core/JsonNode.h"
#include "framework/scene/Scene.h"

namespace shadowlab {

/// Reads {"objects": [...]} (schema: docs/scene.md) and returns the world-space triangle soup.
/// Every error (unknown keys, bad values, unreadable or malformed glTF) is an InputError.
Scene buildScene(JsonNode sceneNode);
/// The same checks as buildScene (keys, values, glTF files present, triangle limits) without
/// generating or loading anything, so thousands of scenes can be checked in a moment. A malformed
/// glTF file is found only when it is loaded.
void checkScene(JsonNode sceneNode);
/// An upper bound of the scene's triangles, from the same checks plus each object's count, without
/// making anything big: generated objects are counted from their keys (within the 5 % they may
/// differ by), grids multiply their object's count, and glTF files are loaded to be counted.
struct ScenePrediction {
    size_t triangles = 0;
    bool moving = false; ///< some object has a path, an animation or node paths
};
ScenePrediction predictScene(JsonNode sceneNode);
/// Rewrites every "gltf" path of a scene (or of one object, and of grids' inner objects) against
/// `baseDir`, so the JSON keeps its meaning when written to another folder.
void absolutiseScenePaths(Json& sceneOrObject, const std::string& baseDir);

} // namespace shadowlab
