#pragma once
// Builds the scene from the config's "scene" object.
#include "framework/core/JsonNode.h"
#include "framework/scene/Scene.h"

namespace shadowlab {

/// Reads {"objects": [...]} (schema: docs/scene.md) and returns the world-space triangle soup.
/// Every error (unknown keys, bad values, unreadable or malformed glTF) is an InputError.
Scene buildScene(JsonNode sceneNode);

} // namespace shadowlab
