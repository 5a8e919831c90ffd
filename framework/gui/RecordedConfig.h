#pragma once
// Saves what is on screen as an experiment config that `shadowlab run` accepts unchanged: the
// viewer's scene, a recorded camera path, the current light and the active algorithm's settings.
#include "framework/core/JsonNode.h"
#include "framework/view/Path.h"

#include <string>

namespace shadowlab {

class Viewer;

/// The config as JSON, with the keys of docs/config.md. glTF paths are made absolute so the file
/// can live in any folder. `cameraPath` may be empty (the current camera pose is saved then).
Json recordedConfigJson(const Viewer& viewer, const Path& cameraPath, const std::string& name);

/// Builds the config, parses it back with parseConfig (InputError, nothing written, when it does
/// not validate: e.g. the algorithm does not support the light) and writes it to `file`.
void saveRecordedConfig(const Viewer& viewer, const Path& cameraPath, const std::string& name, const std::string& file);

} // namespace shadowlab
