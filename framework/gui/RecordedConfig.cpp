#include "framework/gui/RecordedConfig.h"

#include "framework/experiment/Config.h"
#include "framework/experiment/Results.h"
#include "framework/gui/Viewer.h"
#include "framework/scene/SceneConfig.h"

#include <filesystem>

namespace shadowlab {

namespace {

Json vec(glm::vec3 v) { return Json::array({v.x, v.y, v.z}); }

Json lightJson(const Viewer& viewer) {
    const Light& l = viewer.light;
    Json j = {{"type", toString(l.type)}, {"position", vec(l.position)}, {"target", vec(l.target)}};
    if (l.type == LightType::Spot) j["cone_deg"] = l.coneDeg;
    if (l.type == LightType::Area) {
        j["size"] = {l.size.x, l.size.y};
        j["samples"] = l.samples;
        j["pattern"] = l.pattern;
        j["seed"] = l.seed;
    }
    // The light keeps moving along its path only if the viewer was following it.
    if (viewer.playback.followLight && !viewer.config().lightPath.empty()) j["path"] = viewer.config().lightPath.toJson();
    return j;
}

} // namespace

Json recordedConfigJson(const Viewer& viewer, const Path& cameraPath, const std::string& name) {
    const ExperimentConfig& cfg = viewer.config();
    Json scene = viewer.source().at("scene");
    if (scene.contains("objects") && scene["objects"].is_array())
        // Absolute: the saved config may go to another folder, and a config given as a relative path
        // has a relative folder (fifteenth probe: "cfg/b.gltf" was read back as saved/cfg/b.gltf).
        for (Json& o : scene["objects"]) absolutiseScenePaths(o, std::filesystem::absolute(parentDir(cfg.file)).string());

    const Camera& cam = viewer.camera;
    Json camera = {{"fov_y_deg", cam.fovYDeg}, {"near", cam.nearPlane}, {"far", cam.farPlane},
                   {"position", vec(cam.position)}, {"target", vec(cam.target)}};
    if (!cameraPath.empty()) camera["path"] = cameraPath.toJson();

    const AlgorithmChoice& active = viewer.active();
    Json algorithms = Json::array();
    Json reference;
    if (active.info == cfg.referenceEntry.info) {
        // The reference is not an ordinary entry (its id is reserved): save its settings as "reference".
        reference = {{"params", active.params.toJson()}};
    } else {
        algorithms.push_back({{"id", active.label}, {"algorithm", active.info->name}, {"params", active.params.toJson()}});
        reference = cfg.reference ? Json{{"params", cfg.referenceEntry.params.toJson()}} : Json(false);
    }
    return {{"name", name},
            {"resolution", {cfg.resolution.x, cfg.resolution.y}},
            {"frames", cfg.frames},
            {"warmup_frames", cfg.warmupFrames},
            {"scene", scene},
            {"camera", camera},
            {"light", lightJson(viewer)},
            {"reference", reference},
            {"algorithms", algorithms}};
}

void saveRecordedConfig(const Viewer& viewer, const Path& cameraPath, const std::string& name, const std::string& file) {
    Json json = recordedConfigJson(viewer, cameraPath, name);
    // Parsed without loading the scene: it is the scene already on screen, and a large glTF would
    // be read a second time for nothing. Everything else goes through the runner's own parser.
    parseConfig(json, file, false);
    writeFileAtomic(file, json.dump(2) + "\n");
}

} // namespace shadowlab
