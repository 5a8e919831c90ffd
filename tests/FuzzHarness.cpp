#include "tests/FuzzHarness.h"

#include "framework/core/JsonParse.h"
#include "framework/experiment/Config.h"
#include "framework/scene/GltfLoader.h"

namespace shadowlab::fuzz {

size_t loadConfigText(const std::string& text, const std::string& file) {
    Json j = parseJson(text, file);
    // Lower the budget unless the input already asks for less (it is part of what is fuzzed).
    if (j.is_object() && j.contains("scene") && j["scene"].is_object()) {
        const Json& given = j["scene"].contains("max_triangles") ? j["scene"]["max_triangles"] : Json();
        if (!(given.is_number() && given.get<double>() < kMaxTriangles)) j["scene"]["max_triangles"] = kMaxTriangles;
    }
    ExperimentConfig cfg = parseConfig(j, file, true);
    return cfg.scene ? cfg.scene->triangleCount() : 0;
}

size_t loadSceneFile(const std::string& path) { return loadGltf(path, nullptr, kMaxTriangles).triangleCount(); }

} // namespace shadowlab::fuzz
