#pragma once
// What the current GL context is: its implementation strings, the limits the algorithms depend on,
// its subgroup width and which of the extensions the shaders use it has. `shadowlab info` prints
// it and every experiment's summary.json records it (key `device`), so a result always says what
// it ran on.
#include "framework/core/JsonNode.h"

#include <string>
#include <vector>

namespace shadowlab {

/// An extension a shader of the project names in an `#extension` line, and which files do.
struct ExtensionUse {
    std::string name;               ///< e.g. "GL_ARB_shader_ballot"
    std::vector<std::string> files; ///< shader files relative to shaderDir(), sorted
};

/// Every extension named by an `#extension NAME : ...` line under shaderDir(), sorted by name.
std::vector<ExtensionUse> shaderExtensions();

/// The device record of the current context (`backend`: GlContext::backend()):
///   {"vendor", "renderer", "version", "glsl_version", "backend", "subgroup_size",
///    "limits": {"GL_MAX_...": n or [x, y, z], ...}, "extensions": {"GL_...": present, ...}}
/// subgroup_size is querySubgroupSize() (0: no ARB_shader_ballot).
Json deviceRecord(const std::string& backend);

/// Limits that are sizes in bytes (shown with their MiB / KiB by people-facing output).
bool isByteLimit(const std::string& name);

} // namespace shadowlab
