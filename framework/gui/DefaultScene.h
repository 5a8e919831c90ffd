#pragma once
// The scene shadowlab-gui opens without a config: a ground plane, a sphere and a torus under a
// point light, written as a config so it goes through the same parser as any file.
#include "framework/core/JsonNode.h"

namespace shadowlab {

/// A complete experiment config (docs/config.md) for the built-in scene.
Json defaultGuiConfig();

} // namespace shadowlab
