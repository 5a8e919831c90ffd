#include "framework/experiment/Config.h"
#include "framework/experiment/LightClearance.h"

#include "framework/core/Text.h"
#include "framework/scene/Scene.h"
#include "framework/scene/SceneConfig.h"
#include "framework/scene/TriangleNormal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <map>
#include <set>
#include <unordered_set>

namespace shadowlab {

namespace {

const std::vector<std::string> kLightTypes = {"point", "spot", "directional", "area"};

LightType lightTypeFromString(const std::string& s) {
    for (size_t i = 0; i < kLightTypes.size(); ++i)
        if (kLightTypes[i] == s) return LightType(i);
    return LightType::Point;
}

void parseCamera(JsonNode node, ExperimentConfig& c) {
    c.camera.fovYDeg = float(node.getFloat("fov_y_deg", 60.0, configlimits::kFovMinDeg, configlimits::kFovMaxDeg));
    c.camera.nearPlane = float(node.getFloat("near", 0.05, 1e-6, 1e6));
    c.camera.farPlane = float(node.getFloat("far", 100.0, 1e-6, 1e9));
    if (c.camera.farPlane <= c.camera.nearPlane) node.fail("far", "must be greater than near");
    c.camera.position = node.getPoint("position", {0, 2, 6});
    c.camera.target = node.getPoint("target", {0, 0, 0});
    if (node.has("path")) c.cameraPath = Path::parse(node.child("path"), c.camera.target);
    node.finish();
}

void parseLight(JsonNode node, ExperimentConfig& c) {
    Light& l = c.light;
    l.type = lightTypeFromString(node.getEnum("type", "point", kLightTypes));
    l.position = node.getPoint("position", {2, 4, 2});
    l.target = node.getPoint("target", {0, 0, 0});
    if (l.type == LightType::Spot) l.coneDeg = float(node.getFloat("cone_deg", 45.0, configlimits::kConeMinDeg, configlimits::kConeMaxDeg));
    if (l.type == LightType::Area) {
        l.size = node.getVec2("size", {1, 1});
        if (l.size.x <= 0 || l.size.y <= 0) node.fail("size", "both sides must be positive");
        // Its sample points lie half a side from the centre: within the coordinates' bound too.
        if (double(l.size.x) > kMaxCoordinate || double(l.size.y) > kMaxCoordinate)
            node.fail("size", "a side exceeds 1e15 scene units (the light's sample points must lie within ±1e15, as every position)");
        l.samples = node.getInt("samples", 16, configlimits::kAreaSamplesMin, configlimits::kAreaSamplesMax);
        l.pattern = node.getEnum("pattern", "stratified", {"stratified", "grid", "random"});
        l.seed = uint32_t(node.getInt("seed", 1, 0, INT32_MAX));
    }
    if (node.has("path")) c.lightPath = Path::parse(node.child("path"), l.target);
    node.finish();
}

/// A view needs a direction on every frame: a camera at its target, or a spot, area or directional
/// light whose target meets its position, gives NaN matrices and rays (and Embree asserts on them).
/// Paths are checked at the frames the experiment samples, where interpolation can also degenerate.
void checkViews(const ExperimentConfig& c, JsonNode& camera, JsonNode& light) {
    auto degenerate = [](glm::vec3 from, glm::vec3 to) {
        glm::vec3 d = to - from;
        float len = glm::length(d);
        return !(len > 0.0f) || !std::isfinite(len) || !std::isfinite(glm::length(d / len));
    };
    auto beyond = [](glm::vec3 p) {
        for (int a = 0; a < 3; ++a)
            if (!(std::abs(double(p[a])) <= kMaxCoordinate)) return true; // NaN too
        return false;
    };
    auto where = [&](const Path& path, int frame) {
        return path.empty() ? std::string() : " at frame " + std::to_string(frame) + " of its path";
    };
    for (int f = 0; f < c.frames; ++f) {
        Camera cam = c.cameraAt(f);
        if (degenerate(cam.position, cam.target))
            (c.cameraPath.empty() ? camera.fail("target", "the camera's target equals its position")
                                  : camera.fail("path", "the camera's target equals its position" + where(c.cameraPath, f)));
        // A spline between keyframes within ±1e15 can overshoot them (twenty-first probe: keys 0,
        // 1e15, 1e15, -1e15 put the light at 1.19e15): held to the same bound at every frame.
        if (!c.cameraPath.empty() && (beyond(cam.position) || beyond(cam.target)))
            camera.fail("path", "the camera's path reaches beyond ±1e15 scene units" + where(c.cameraPath, f) +
                                    " (its spline overshoots the keyframes there)");
        Light l = c.lightAt(f);
        if (!c.lightPath.empty() && (beyond(l.position) || beyond(l.target)))
            light.fail("path", "the light's path reaches beyond ±1e15 scene units" + where(c.lightPath, f) +
                                   " (its spline overshoots the keyframes there)");
        if (l.type != LightType::Point && degenerate(l.position, l.target))
            (c.lightPath.empty()
                 ? light.fail("target", "must differ from position (it sets the light's direction)")
                 : light.fail("path", "the light's target equals its position" + where(c.lightPath, f) +
                                          " (it sets the light's direction)"));
        if (c.cameraPath.empty() && c.lightPath.empty()) break;  // every frame is the same
    }
}

AlgorithmEntry parseEntry(JsonNode node, const std::string& defaultName) {
    AlgorithmEntry e;
    e.jsonPath = node.path();
    std::string name = defaultName.empty() ? node.requireString("algorithm") : defaultName;
    if (defaultName.empty()) {
        e.info = findAlgorithm(name);
        if (!e.info) {
            std::string list;
            for (const auto& a : algorithmRegistry()) list += (list.empty() ? "" : ", ") + a.name;
            node.fail("algorithm", "unknown algorithm \"" + name + "\"; registered: " + list);
        }
        e.id = node.getString("id", name);
        // Ids name result files (images/ID_f0000_shaded.png) and columns: no separators or spaces.
        if (!isAlgorithmId(e.id))
            node.fail("id", "an id is 1 to 64 letters, digits, '_', '-' or '.', starting with a letter or digit, got \"" +
                                (e.id.size() > 40 ? e.id.substr(0, 37) + "..." : e.id) + "\"");
    } else {
        e.info = findAlgorithm(name);
        e.id = name;
    }
    e.params = ParamValues::parse(e.info->schema(), node.child("params"));
    node.finish();
    return e;
}

} // namespace

/// Moves (position, target) along `path` to frame `frame` of `frames`; a missing path keeps them.
static void followPath(const Path& path, int frame, int frames, glm::vec3& position, glm::vec3& target) {
    if (path.empty()) return;
    PathSample s = path.at(path.frameTime(frame, frames));
    position = s.position;
    target = s.target;
}

/// Whether a box lies within ±kMaxCoordinate. Written as !(|x| <= limit) so that a NaN, for which
/// every comparison is false, fails it too.
static bool withinCoordinates(const Bounds& b) {
    for (int a = 0; a < 3; ++a)
        if (!(std::abs(double(b.min[a])) <= kMaxCoordinate && std::abs(double(b.max[a])) <= kMaxCoordinate)) return false;
    return true;
}

bool isAlgorithmId(const std::string& id) {
    return !id.empty() && id.size() <= 64 && std::isalnum(static_cast<unsigned char>(id[0])) &&
           id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") == std::string::npos;
}

std::string frameText(const ExperimentConfig& c, int frame) {
    char time[32];
    std::snprintf(time, sizeof time, "%.6g", c.sceneTimeAt(frame));
    return "frame " + std::to_string(frame) + " (time " + time + " s)";
}

/// Moving parts stay within the coordinates every other input is held to (±kMaxCoordinate) on every
/// frame the experiment samples: paths and animations compose, so a part checked at rest can still
/// leave float range (or reach infinity or NaN) at another time.
void checkPoseBounds(const ExperimentConfig& c, int frame, const Bounds& b) {
    if (!withinCoordinates(b))
        throw InputError(c.file, "/scene", "moving objects reach beyond ±1e15 scene units (or a non-finite position) at " +
                                               frameText(c, frame) + " (check the paths' translate and scale)");
}

/// A moving part's triangles posed by `m` keep an area: a triangle that float rounding collapses
/// there is an error, as it is where a static object is placed (ninth probe: a 0.001-unit triangle
/// moved to x = 1e5 lost its area at that frame and the run went on without it). A mesh's triangles
/// keep their shape within 1 % of the pose in double, as where they are placed statically.
static void checkPosedTriangles(const MovingPart& part, const glm::mat4& m, const std::string& file, const std::string& path,
                                const ExperimentConfig& c, int frame) {
    const glm::dmat4 dm(m);
    for (size_t i = 0; i < part.triangleCount; ++i) {
        glm::vec3 v[3], n;
        poseTriangle(m, &part.local[3 * i], v, n);
        Bounds b;
        for (const glm::vec3& p : v) b.extend(p);
        if (!unitNormal(v[0], v[1], v[2], n))
            throw InputError(file, path, "triangle " + std::to_string(i) + " of the moving object has no area in float at " +
                                             frameText(c, frame) + " (" + floatPrecisionAt(b) +
                                             "): keep its path nearer the origin or make the object larger");
        if (!part.heldEachTriangle) continue;
        glm::dvec3 exact[3];
        for (size_t k = 0; k < 3; ++k) exact[k] = glm::dvec3(dm * glm::dvec4(glm::dvec3(part.local[3 * i + k]), 1.0));
        if (const double change = shapeChange(v, exact); !(change <= 0.01)) {
            char text[96];
            std::snprintf(text, sizeof text, "%.3g %%", 100.0 * change);
            throw InputError(file, path, "triangle " + std::to_string(i) + " of the moving mesh changes its shape by " + text +
                                             " (at most 1 %) in float at " + frameText(c, frame) + " (" + floatPrecisionAt(b) +
                                             "): keep its path nearer the origin or make the mesh larger");
        }
    }
}

/// Every frame's pose, before anything is rendered: a pose that is not finite, or a part that leaves
/// the coordinate range, is an error naming where its motion was given (the config's path, or the
/// glTF file's node or animation channel) and the frame, instead of a part that silently vanishes.
static void checkPoses(const ExperimentConfig& c) {
    // Every frame (eighteenth probe: a million-frame config was checked at 10,000 frames spread
    // over it, and a sphere moved far away, or onto the light, on a frame between them ran; the
    // bounds and rules of a million frames take a few seconds).
    const Scene& scene = *c.scene;
    // Each moving triangle posed at every frame, while that stays under 2e7 triangle poses (a
    // second or two); beyond, the bounds and the copies above are still checked at every frame.
    const double visits = double(c.frames) * double(scene.movingTriangleCount());
    const bool checkTriangles = visits <= 2e7;
    for (int f = 0;; ++f) {
        std::vector<glm::mat4> pose;
        try {
            pose = scene.poseAt(c.sceneTimeAt(f));
        } catch (const InputError& e) {
            throw InputError(e.file(), e.jsonPath(), e.cause() + ", " + frameText(c, f));
        }
        for (size_t p = 0; p < scene.moving.size(); ++p) {
            const MovingPart& part = scene.moving[p];
            const Bounds b = partBoundsAt(part, pose[p]);
            const std::string file = part.sourceFile.empty() ? c.file : part.sourceFile;
            const std::string path = part.sourcePath.empty() ? "/scene" : part.sourcePath;
            if (!withinCoordinates(b))
                throw InputError(file, path, "the moving object reaches beyond ±1e15 scene units (or a non-finite position) at " +
                                                 frameText(c, f) + " (check its translate and scale)");
            // As a static object is held to (seventh probe: a sphere moved to 1e8 ran, where it sat
            // static was refused).
            if (const std::string why = floatDistortion(b); !why.empty())
                throw InputError(file, path, "the moving object, " + why + ", at " + frameText(c, f) +
                                                 ": keep its path nearer the origin or make the object larger");
            // Each copy of a moving grid too (sixteenth probe: 0.1-unit spheres 2000 apart moved to
            // 1e5 ran, where the same grid placed there, or one sphere moved there, was refused).
            if (const std::string why = copyDistortion(part, pose[p]); !why.empty())
                throw InputError(file, path, "the moving grid's " + why + ", at " + frameText(c, f) +
                                                 ": keep its path nearer the origin or make the object larger");
            if (checkTriangles) checkPosedTriangles(part, pose[p], file, path, c, f);
        }
        checkPoseBounds(c, f, scene.boundsAt(pose));
        if (f == c.frames - 1) break;
    }
}

Camera ExperimentConfig::cameraAt(int frame) const {
    Camera cam = camera;
    followPath(cameraPath, frame, frames, cam.position, cam.target);
    return cam;
}

double ExperimentConfig::sceneTimeAt(int frame) const {
    glm::dvec2 range(0.0);
    if (scene && scene->hasTimeRange) range = scene->timeRange;
    else if (cameraPath.keyframes().size() >= 2) range = {cameraPath.startTime(), cameraPath.endTime()};
    else if (lightPath.keyframes().size() >= 2) range = {lightPath.startTime(), lightPath.endTime()};
    else if (scene) range = scene->motionTimeRange();
    if (frames <= 1) return range.x;
    return range.x + (range.y - range.x) * double(frame) / double(frames - 1);
}

const char* toString(ExperimentConfig::Statistics s) {
    switch (s) {
    case ExperimentConfig::Statistics::All: return "all";
    case ExperimentConfig::Statistics::None: return "none";
    default: return "images";
    }
}

ExpectationIds ExperimentConfig::expectationIds() const {
    ExpectationIds ids;
    ids.reference = reference;
    for (const AlgorithmEntry& e : algorithms) {
        ids.all.push_back(e.id);
        if (e.info->exact) ids.exact.insert(e.id);
    }
    return ids;
}

std::vector<int> ExperimentConfig::statisticsFrames() const {
    std::vector<int> out;
    if (statistics == Statistics::All)
        for (int f = 0; f < frames; ++f) out.push_back(f);
    else if (statistics == Statistics::Images)
        out = imagesAtFrames;
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

Light ExperimentConfig::lightAt(int frame) const {
    Light l = light;
    followPath(lightPath, frame, frames, l.position, l.target);
    return l;
}

ExperimentConfig parseConfig(const Json& json, const std::string& file, bool loadScene) {
    ExperimentConfig c;
    c.file = file;
    // The file's path reaches summary.json and the report (UTF-8 text): refused here, as validate
    // runs it, not after a whole run has rendered.
    if (const std::string why = pathTextProblem(file); !why.empty()) throw InputError(shortText(file), "", "the file's path " + why);
    c.resolved = Json::object();
    JsonNode root(file, &json, "", &c.resolved);
    c.name = root.getString("name", "experiment");
    // The name titles the report and every progress line: plain text of one line (Text.h's rule).
    if (const std::string why = userTextProblem(c.name); !why.empty()) root.fail("name", "the name \"" + shortText(c.name, 60) + "\" " + why);
    if (c.name.empty()) root.fail("name", "must not be empty (it titles the report)");
    c.resolution = root.getIVec2("resolution", {256, 256}, configlimits::kResolutionMin, configlimits::kResolutionMax);
    c.frames = root.getInt("frames", 30, 1, 1000000);
    c.warmupFrames = root.getInt("warmup_frames", 3, 0, 1000);
    // Read only when given: a resolved config without it stays what it was (sweeps' run ids).
    if (root.has("repeats")) c.repeats = root.getInt("repeats", 1, 1, 1000);
    // Timing is honest by construction: the timed frames never carry statistics, so the
    // former switch between instrumented and uninstrumented timing is gone, not ignored.
    if (root.has("timing_mode"))
        root.fail("timing_mode", "was removed: timed frames always run with statistics compiled out; counters and heat maps "
                                 "come from an untimed pass chosen by \"statistics\": \"images\" (default), \"all\" or \"none\"");
    const std::string stats = root.getEnum("statistics", "images", {"images", "all", "none"});
    c.statistics = stats == "all" ? ExperimentConfig::Statistics::All
                 : stats == "none" ? ExperimentConfig::Statistics::None : ExperimentConfig::Statistics::Images;

    if (!root.has("scene")) root.fail("scene", "required key is missing");
    JsonNode sceneNode = root.child("scene");
    if (loadScene) c.scene = std::make_shared<Scene>(buildScene(sceneNode));
    else root.markRead("scene");

    JsonNode cameraNode = root.child("camera"), lightNode = root.child("light");
    parseCamera(cameraNode, c);
    parseLight(lightNode, c);
    checkViews(c, cameraNode, lightNode);
    if (c.scene && c.scene->dynamic()) checkPoses(c);

    // "reference": true | false | {"params": {...}}
    if (root.has("reference") && root.raw()["reference"].is_object()) {
        c.reference = true;
        c.referenceEntry = parseEntry(root.child("reference"), "reference");
    } else {
        c.reference = root.getBool("reference", true);
        c.referenceEntry.id = "reference";
        c.referenceEntry.info = findAlgorithm("reference");
        c.referenceEntry.params = ParamValues(c.referenceEntry.info->schema());
    }

    std::set<std::string> ids = {"reference"};
    std::map<std::string, std::string> folded = {{"reference", "reference"}};  // ids in lower case → as given
    auto entries = root.objectArray("algorithms");
    for (auto& node : entries) {
        AlgorithmEntry e = parseEntry(node, "");
        // The memory tables list the scene's own parts beside the algorithms by name (nineteenth
        // probe: an id "scene" replaced the scene's bytes in summary.json and the report).
        // Ids name files (images, plots): two that differ only in case are one file on a
        // case-insensitive file system (macOS, Windows shares), and one algorithm's images would
        // overwrite the other's.
        const std::string lower = asciiLowerCase(e.id);
        if (lower == "scene" || lower == "scene_gpu") // in any case (twenty-second probe: "SCENE" beside "scene")
            throw InputError(file, node.childPath("id"), "the id \"" + e.id + "\" names the scene's own entry in the memory tables; choose another");
        if (!ids.insert(e.id).second)
            throw InputError(file, node.childPath("id"), "duplicate id \"" + e.id + "\" (ids label results, so each must be unique)");
        if (auto [it, fresh] = folded.emplace(lower, e.id); !fresh)
            throw InputError(file, node.childPath("id"), "id \"" + e.id + "\" differs from \"" + it->second +
                                                           "\" only in case (ids name files, and case-insensitive file systems would take them for one)");
        if (!e.info->supports(c.light.type))
            throw InputError(file, node.childPath("algorithm"),
                             e.info->name + " does not support " + toString(c.light.type) + " lights");
        if (c.scene && c.scene->dynamic())
            if (std::string why = e.info->motionRefusal(e.params); !why.empty())
                throw InputError(file, node.childPath("algorithm"), why + " (objects with a \"path\" or an \"animation\")");
        c.algorithms.push_back(std::move(e));
    }
    if (c.algorithms.empty() && !c.reference) root.fail("algorithms", "nothing to run: no algorithms and no reference");

    checkLightClearance(c);
    c.expectations = parseExpectations(root, c.expectationIds());

    JsonNode out = root.child("output");
    if (out.has("dir") && out.raw()["dir"].is_string() && out.raw()["dir"].get<std::string>().empty())
        out.fail("dir", "must not be empty (it names the output directory)");
    if (!out.has("dir") && !isFileName(c.name))
        c.defaultOutputProblem = "\"" + shortText(c.name, 60) + "\" cannot name the default output folder results/NAME (it holds '/' or "
                                 "'\\', or is '.' or '..'): give output.dir or --out";
    c.outputDir = out.getPath("dir", "results/" + c.name);
    if (const std::string why = pathTextProblem(c.outputDir); !why.empty()) out.fail("dir", "the folder's name " + why);
    c.imagesAtFrames = out.getIntList("images_at_frames", {0});
    std::unordered_set<int> listed;
    for (size_t k = 0; k < c.imagesAtFrames.size(); ++k) {
        const int f = c.imagesAtFrames[k];
        // At the element (probe 26: the list was named, not which of its frames).
        const std::string at = "images_at_frames/" + std::to_string(k);
        if (f < 0 || f >= c.frames) out.fail(at, "frame " + std::to_string(f) + " is outside [0, " + std::to_string(c.frames - 1) + "]");
        if (!listed.insert(f).second) // a set, not a scan of the list so far (twenty-third probe: 1 M frames took minutes)
            out.fail(at, "frame " + std::to_string(f) + " is listed twice");
    }
    c.plots = out.getBool("plots", true);
    out.finish();
    root.finish();
    return c;
}

void applyOverride(Json& config, const std::string& assignment) {
    const size_t eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
        throw InputError("--set", assignment, "expected PATH=VALUE, e.g. resolution=[64,64] or algorithms.0.params.pcf=0");
    const std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
    Json value;
    try {
        value = parseJsonOrString(text); // e.g. resolution=[64,64], light.type=directional
    } catch (const InputError& e) {
        throw InputError("--set", path, e.cause());
    }
    Json* node = &config;
    std::string walked;
    size_t start = 0;
    while (true) {
        const size_t dot = path.find('.', start);
        const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        walked += (walked.empty() ? "" : ".") + key;
        if (key.empty()) throw InputError("--set", path, "empty path component");
        Json* next = nullptr;
        if (node->is_array()) {
            // Digits only, and no more of them than an index into this array can have: "-1", "1e3"
            // and 10^20 are a bad path, not an exception from the number parser.
            // No leading zero either (probe 26: "01" and "1" were one element but two paths, so a
            // --set given twice, or two sweep axes on one path, went unnoticed).
            const bool numeric = !key.empty() && key.size() <= 18 && key.find_first_not_of("0123456789") == std::string::npos &&
                                 (key.size() == 1 || key[0] != '0');
            const size_t index = numeric ? size_t(std::strtoull(key.c_str(), nullptr, 10)) : 0;
            if (!numeric || index >= node->size())
                throw InputError("--set", walked, "no element " + key + " in an array of " + std::to_string(node->size()));
            next = &(*node)[index];
        } else if (node->is_object() || node->is_null()) {
            next = &(*node)[key];
        } else {
            throw InputError("--set", walked, "cannot descend into a " + std::string(node->type_name()));
        }
        node = next;
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    *node = value;
}

namespace {

/// Whether the config file itself holds a value at JSON pointer `at`.
bool fileHolds(const Json& file, const std::string& at) {
    try {
        return file.contains(Json::json_pointer(at));
    } catch (const std::exception&) {
        return false;
    }
}

/// A config error at or under a value a --set gave names that --set too: the file holds another
/// value there (probe 25: `--set frames=` read as "base.json: at /frames: expected an integer"),
/// and so does one at a key a --set made (probe 26: `--set light.foo.bar=1` at /light/foo, a key
/// the file does not hold). The last --set of a path is the one that took effect.
[[noreturn]] void blameOverride(const InputError& e, const Json& file, const std::vector<std::string>& overrides) {
    const std::string& at = e.jsonPath();
    for (auto o = overrides.rbegin(); o != overrides.rend(); ++o) {
        std::string pointer = "/" + o->substr(0, o->find('='));
        std::replace(pointer.begin(), pointer.end(), '.', '/');
        const bool under = at == pointer || (at.starts_with(pointer) && at[pointer.size()] == '/');
        const bool made = !at.empty() && pointer.starts_with(at + "/") && !fileHolds(file, at);
        if (under || made) throw InputError(e.file(), at, "from --set " + shortText(*o, 80) + ": " + e.cause());
    }
    throw e;
}

} // namespace

ExperimentConfig loadConfig(const std::string& file, bool loadScene, const std::vector<std::string>& overrides) {
    const Json written = JsonNode::parseFile(file);
    Json j = written;
    for (const auto& o : overrides) applyOverride(j, o);
    try {
        return parseConfig(j, file, loadScene);
    } catch (const InputError& e) {
        blameOverride(e, written, overrides);
    }
}

ScenePrediction predictConfigScene(const std::string& file, const std::vector<std::string>& overrides) {
    const Json written = JsonNode::parseFile(file);
    Json j = written;
    for (const auto& o : overrides) applyOverride(j, o);
    try {
        return predictConfigScene(j, file);
    } catch (const InputError& e) {
        blameOverride(e, written, overrides);
    }
}

ScenePrediction predictConfigScene(const Json& config, const std::string& file) {
    Json j = config;
    Json resolved = Json::object();
    JsonNode root(file, &j, "", &resolved);
    if (!root.has("scene")) root.fail("scene", "required key is missing");
    return predictScene(root.child("scene"));
}

} // namespace shadowlab
