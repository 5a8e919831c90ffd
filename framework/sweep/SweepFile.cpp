#include "framework/sweep/SweepFile.h"

#include "framework/core/Text.h"
#include "framework/experiment/Compare.h"
#include "framework/experiment/Config.h"
#include "framework/scene/SceneConfig.h"
#include "framework/sweep/SweepText.h"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <fstream>
#include <set>

namespace shadowlab {

namespace {

/// Text a spreadsheet would read as a formula in a CSV cell: it starts with =, +, - or @ and is not
/// a plain decimal number (a numeric axis's "-0.5" stays as it is).
bool looksLikeFormula(const std::string& s) {
    if (s.empty() || std::string("=+-@").find(s[0]) == std::string::npos) return false;
    return !plainDecimal(s);
}

// A sweep beyond this is almost certainly a mistake (an axis of 1000 values times a few more), and
// expanding it would validate millions of configs before saying so.
constexpr size_t kMaxRuns = 100000;

// Column names of sweep.csv that an axis must not shadow (sweep_report.py reads rows by column name).
const std::set<std::string> kReservedNames = {"run", "index", "triangles", "pixels", "id", "algorithm", "measure", "kind", "value"};
// An axis name is a column header and a plot file name (sweep_AXIS.png).
constexpr size_t kMaxAxisNameChars = 64;

const std::vector<std::string> kScales = {"category", "value", "triangles", "pixels"};

std::string defaultName(const std::string& file) {
    std::string stem = std::filesystem::path(file).filename().string();
    for (const char* ext : {".sweep.json", ".json"}) {
        const std::string e = ext;
        if (stem.size() > e.size() && stem.compare(stem.size() - e.size(), e.size(), e) == 0) return stem.substr(0, stem.size() - e.size());
    }
    return stem;
}

bool isIdentifier(const std::string& s) {
    if (s.empty() || s.size() > kMaxAxisNameChars) return false;
    for (char c : s)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
    return true;
}

/// "scene.objects.1" → "/scene/objects/1" (the form JsonNode uses in its errors).
std::string slashPath(const std::string& dotted) {
    std::string s = "/" + dotted;
    for (char& c : s)
        if (c == '.') c = '/';
    return s;
}

bool overlaps(const std::string& a, const std::string& b) {
    auto under = [](const std::string& x, const std::string& root) {
        return x == root || (x.size() > root.size() && x.compare(0, root.size(), root) == 0 && x[root.size()] == '/');
    };
    return under(a, b) || under(b, a);
}

std::string axisWhere(size_t a, const SweepAxis& axis) { return "/axes/" + std::to_string(a) + " (axis \"" + axis.name + "\")"; }

/// Where a value set at the dotted `path` sits in the scene description, for absolutiseAxisValue.
enum class SceneSlot { None, Object, Objects, Gltf };

/// The slot of `path`, following absolutiseScenePaths's walk: the scene and every object may hold
/// `gltf`, an `object` and `objects`.
SceneSlot slotOf(const std::string& path) {
    SceneSlot slot = SceneSlot::None;
    size_t start = 0;
    for (bool first = true;; first = false) {
        const size_t dot = path.find('.', start);
        const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        if (first) slot = key == "scene" ? SceneSlot::Object : SceneSlot::None;
        else if (slot == SceneSlot::Objects) slot = SceneSlot::Object;
        else if (slot == SceneSlot::Object)
            slot = key == "objects" ? SceneSlot::Objects : key == "object" ? SceneSlot::Object : key == "gltf" ? SceneSlot::Gltf : SceneSlot::None;
        else slot = SceneSlot::None;
        if (slot == SceneSlot::None || dot == std::string::npos) return slot;
        start = dot + 1;
    }
}

/// An axis value's relative glTF paths resolved against the sweep file's folder, as the base's are
/// against theirs: a run's config is written under the output folder, where a relative path would
/// name another file.
void absolutiseAxisValue(Json& value, const std::string& path, const std::string& dir) {
    switch (slotOf(path)) {
    case SceneSlot::Object: absolutiseScenePaths(value, dir); break;
    case SceneSlot::Objects:
        if (value.is_array())
            for (Json& o : value) absolutiseScenePaths(o, dir);
        break;
    case SceneSlot::Gltf:
        if (value.is_string()) value = resolvePath(dir, value.get<std::string>());
        break;
    case SceneSlot::None: break;
    }
}

/// A label of a "value" axis is x of a plot: a positive number (JSON syntax, which every reader of
/// sweep.csv parses the same way).
bool isPositiveNumber(const std::string& label) {
    const Json j = Json::parse(label, nullptr, false);
    return !j.is_discarded() && j.is_number() && std::isfinite(j.get<double>()) && j.get<double>() > 0;
}

SweepAxis parseAxis(JsonNode node, size_t a, const std::set<std::string>& names, std::set<std::string>& allPaths,
                    const std::string& sweepDir) {
    SweepAxis axis;
    axis.name = node.requireString("name");
    if (!isIdentifier(axis.name))
        node.fail("name", "\"" + shortText(axis.name, 80) + "\" is not a name of 1 to " + std::to_string(kMaxAxisNameChars) +
                              " letters, digits and _ (it becomes a column name)");
    // Compared in lower case: names become plot files (sweep_NAME.png), and on a case-insensitive
    // file system "RES" and "res", or "STAGES" and the stages figure, are one file (twenty-second probe).
    const std::string lower = asciiLowerCase(axis.name);
    if (kReservedNames.count(lower)) node.fail("name", "\"" + axis.name + "\" is a column of sweep.csv already; choose another name");
    // Its plot would be sweep_stages.png, the stages figure's file (eleventh probe: one replaced the other).
    if (lower == "stages") node.fail("name", "\"" + axis.name + "\" would name its plot sweep_stages.png, the stages figure's file; choose another name");
    if (names.count(lower)) node.fail("name", "two axes are named \"" + axis.name + "\" (names that differ only in case name one plot file)");
    const std::string where = axisWhere(a, axis);

    if (!node.has("values")) node.fail("values", "required key is missing: {\"dotted.path\": [value, ...], ...}");
    const Json& values = node.raw()["values"];
    node.markRead("values");
    if (!values.is_object() || values.empty())
        throw InputError(node.file(), where + "/values", "expected an object of one or more dotted paths, each with a list of values");
    size_t count = 0;
    for (const auto& [path, list] : values.items()) {
        const std::string at = where + ", path " + shortText(path);
        if (path.empty() || path.front() == '.' || path.back() == '.' || path.find("..") != std::string::npos)
            throw InputError(node.file(), at, "not a dotted path like scene.objects.1.object.triangles");
        if (const std::string why = dottedPathProblem(path); !why.empty()) throw InputError(node.file(), at, "the path " + why);
        if (!list.is_array() || list.empty()) throw InputError(node.file(), at, "expected a non-empty list of values");
        if (!allPaths.insert(path).second) throw InputError(node.file(), at, "another axis sets this path already");
        for (const std::string& other : allPaths)
            if (other != path && overlaps(slashPath(other), slashPath(path)))
                throw InputError(node.file(), at, "overlaps the path " + other + " of an axis (one would overwrite the other)");
        if (count && list.size() != count)
            throw InputError(node.file(), at, "has " + std::to_string(list.size()) + " values but " + axis.paths.front() + " has " +
                                                  std::to_string(count) + " (the paths of one axis move together)");
        count = list.size();
        axis.paths.push_back(path);
        axis.values.push_back(std::vector<Json>(list.begin(), list.end()));
        for (Json& v : axis.values.back()) absolutiseAxisValue(v, path, sweepDir);
    }

    node.markRead("labels"); // accepted, given or not: an unknown key's error lists it
    if (node.has("labels")) {
        const Json& labels = node.raw()["labels"];
        if (!labels.is_array() || labels.size() != count)
            node.fail("labels", "expected a list of " + std::to_string(count) + " strings, one per value");
        for (size_t k = 0; k < labels.size(); ++k) {
            const Json& l = labels[k];
            if (!l.is_string() || l.get<std::string>().empty())
                node.fail("labels", "expected non-empty strings, got " + shortText(l.dump(), 80));
            // A label is a cell of the plan's TSV, of sweep.csv and of the report's tables, and part
            // of every progress line: one short line of text.
            if (const std::string why = userTextProblem(l.get<std::string>()); !why.empty())
                throw InputError(node.file(), node.childPath("labels") + "/" + std::to_string(k),
                                 "the label \"" + shortText(l.get<std::string>(), 60) + "\" " + why);
            // Seventh probe: "=HYPERLINK(...)" went into sweep.csv as typed, a formula to any
            // spreadsheet that opens it.
            if (looksLikeFormula(l.get<std::string>()))
                throw InputError(node.file(), node.childPath("labels") + "/" + std::to_string(k),
                                 "the label \"" + shortText(l.get<std::string>(), 60) +
                                     "\" starts with =, +, - or @ and is not a number: a spreadsheet opening sweep.csv would run it "
                                     "as a formula; start it otherwise");
            axis.labels.push_back(l.get<std::string>());
        }
    } else if (axis.paths.size() > 1) {
        node.fail("labels", "required when an axis sets several paths (name each of its " + std::to_string(count) + " points)");
    } else {
        for (size_t k = 0; k < axis.values.front().size(); ++k) {
            const Json& v = axis.values.front()[k];
            // A string that is not plain one-line text is shown as JSON text with every non-ASCII
            // character escaped: the label stays one visible cell.
            // So is a string a spreadsheet would read as a formula (it then starts with a quote).
            std::string label = v.is_string() && userTextProblem(v.get<std::string>()).empty() && !looksLikeFormula(v.get<std::string>())
                                    ? v.get<std::string>()
                                    : v.dump(-1, ' ', true);
            if (label.size() > kMaxLabelChars)
                node.fail("labels", "value " + std::to_string(k) + " (" + shortText(label, 60) + ") is longer than " +
                                        std::to_string(kMaxLabelChars) + " characters as a label: give the axis labels");
            axis.labels.push_back(std::move(label));
        }
    }
    std::set<std::string> seen;
    for (const auto& l : axis.labels)
        if (!seen.insert(l).second) throw InputError(node.file(), where, "the label \"" + shortText(l, 60) + "\" appears twice");

    const std::string scale = node.getEnum("scale", "category", kScales);
    axis.scale = AxisScale(std::find(kScales.begin(), kScales.end(), scale) - kScales.begin());
    if (axis.scale == AxisScale::Value)
        for (size_t p = 0; p < axis.paths.size(); ++p)
            for (const Json& v : axis.values[p])
                if (!v.is_number() || v.get<double>() <= 0)
                    node.fail("scale", "\"value\" needs positive numbers (x of a log-log plot), but " + shortText(axis.paths[p], 80) +
                                           " has " + shortText(v.dump(), 60));
    if (axis.scale == AxisScale::Value)
        for (const auto& l : axis.labels)
            if (!isPositiveNumber(l))
                node.fail("scale", "\"value\" plots each point at its label, which must be a positive number, but one is \"" +
                                       shortText(l, 60) + "\" (leave labels out, or use scale \"category\")");
    node.finish();
    return axis;
}

/// Validates one run's config as `shadowlab run` would, without generating or loading its scene,
/// and returns the resolved config (defaults filled in, scene included) that its id is made from.
Json resolveRun(const Json& config, const std::string& file) {
    ExperimentConfig c = parseConfig(config, file, false);
    Json resolved = c.resolved;
    resolved["scene"] = Json::object();
    checkScene(JsonNode(file, &config.at("scene"), "/scene", &resolved["scene"]));
    return resolved;
}

/// Rethrows a run's config error with the sweep's context: the axis whose path the error lies in
/// (or under), else the base config.
[[noreturn]] void rethrowRunError(const InputError& e, const Sweep& s, const SweepRun& run, const std::string& baseFile,
                                  const std::string& baseWhere) {
    for (size_t a = 0; a < s.axes.size(); ++a) {
        const SweepAxis& axis = s.axes[a];
        for (size_t p = 0; p < axis.paths.size(); ++p)
            if (overlaps(e.jsonPath(), slashPath(axis.paths[p])))
                throw InputError(s.file, axisWhere(a, axis) + ", path " + axis.paths[p] + " = " + shortText(axis.values[p][run.point[a]].dump(), 80),
                                 "at " + e.jsonPath() + ": " + e.cause());
    }
    // Not at an axis path, but the base alone is valid: the axes' values together caused it (probe
    // 26: an axis swapping the algorithms broke the base's expectations, and the base was blamed).
    if (!s.axes.empty()) {
        bool baseAloneValid = true;
        try {
            resolveRun(s.base, baseFile);
        } catch (const InputError&) {
            baseAloneValid = false;
        }
        if (baseAloneValid)
            throw InputError(s.file, "/axes", "run " + std::to_string(run.index) + " (" + runLabel(s, run) + "), its config at " +
                                                  e.jsonPath() + ": " + e.cause());
    }
    // The base config itself is wrong (in the sweep file at /base, or in its own file).
    throw InputError(baseWhere.empty() ? baseFile : s.file, baseWhere + e.jsonPath(),
                     e.cause() + " (run " + std::to_string(run.index) + ": " + runLabel(s, run) + ")");
}

std::string idList(const std::set<std::string>& ids) {
    std::string list;
    for (const std::string& id : ids) list += (list.empty() ? "" : ", ") + id;
    return shortText(list, 300);
}

/// merge.ratios and merge.paper name algorithm ids: each must be one that some run measures, and a
/// ratio's two ids must meet in some run, or the table it asks for would be empty (probe 26: an
/// axis that swaps one id for the other gave a ratio table of no rows, and no word).
void checkMergeIds(const Sweep& s, const std::vector<std::set<std::string>>& idsPerRun) {
    if (!s.merge.is_object()) return;
    std::set<std::string> ids; // in any run
    for (const auto& run : idsPerRun) ids.insert(run.begin(), run.end());
    const auto unknown = [&](const std::string& where, const std::string& id) {
        throw InputError(s.file, where, "\"" + shortText(id, 60) + "\" is not the id of an algorithm in any run (ids: " + idList(ids) + ")");
    };
    if (s.merge.contains("ratios"))
        for (size_t k = 0; k < s.merge["ratios"].size(); ++k) {
            const std::string ratio = s.merge["ratios"][k].get<std::string>();
            const size_t slash = ratio.find('/');
            const std::string where = "/merge/ratios/" + std::to_string(k);
            if (ratio.find('/', slash + 1) != std::string::npos)
                throw InputError(s.file, where, "\"" + shortText(ratio, 60) + "\" is not ID/ID (one slash: ids hold none)");
            const std::string a = ratio.substr(0, slash), b = ratio.substr(slash + 1);
            for (const std::string& id : {a, b})
                if (!ids.count(id)) unknown(where, id);
            if (std::none_of(idsPerRun.begin(), idsPerRun.end(), [&](const std::set<std::string>& run) { return run.count(a) && run.count(b); }))
                throw InputError(s.file, where, "no run holds both \"" + shortText(a, 60) + "\" and \"" + shortText(b, 60) +
                                                    "\", so the ratio would have no row");
        }
    if (s.merge.contains("paper"))
        for (const auto& [id, ms] : s.merge["paper"]["times_ms"].items())
            if (!ids.count(id)) unknown("/merge/paper/times_ms/" + id, id);
}
} // namespace

std::string toString(AxisScale scale) { return kScales[size_t(scale)]; }

namespace {
constexpr uint64_t kFnvBasis = 1469598103934665603ull, kFnvPrime = 1099511628211ull;

/// FNV-1a of a file's bytes, read in blocks; "missing" when it cannot be read (the run then fails
/// on it, with its own error). Cached by path, size and modification time: a sweep of many runs
/// over one model reads it once.
std::string fileFingerprint(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec) return "missing";
    const auto time = fs::last_write_time(path, ec).time_since_epoch().count();
    static std::map<std::string, std::pair<std::pair<uintmax_t, long long>, std::string>> cache;
    const auto key = std::pair<uintmax_t, long long>{size, (long long)time};
    if (auto it = cache.find(path); it != cache.end() && it->second.first == key) return it->second.second;
    std::ifstream in(path, std::ios::binary);
    if (!in) return "missing";
    uint64_t h = kFnvBasis;
    std::vector<char> block(1 << 20);
    while (in.read(block.data(), std::streamsize(block.size())) || in.gcount() > 0)
        for (std::streamsize i = 0; i < in.gcount(); ++i) h = (h ^ static_cast<unsigned char>(block[size_t(i)])) * kFnvPrime;
    char text[24];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
    cache[path] = {key, text};
    return text;
}

} // namespace

std::string runId(const Json& resolvedConfig) {
    Json j = resolvedConfig;
    if (j.contains("output") && j["output"].is_object()) j["output"].erase("dir");
    // FNV-1a over the canonical dump (nlohmann sorts object keys): stable across runs and machines.
    uint64_t h = kFnvBasis;
    for (unsigned char c : j.dump()) h = (h ^ c) * kFnvPrime;
    // And over the content of every glTF file the scene reads (sixth probe: a model edited between
    // two `sweep run`s kept its runs' ids, and the old geometry's results were skipped as complete).
    for (const std::string& file : gltfPathsOf(j.value("scene", Json())))
        for (const std::string& part : gltfFiles(file))
            for (unsigned char c : part + "=" + fileFingerprint(part) + "\n") h = (h ^ c) * kFnvPrime;
    char buf[17];
    std::snprintf(buf, sizeof buf, "%012llx", static_cast<unsigned long long>(h >> 16));
    return buf;
}

std::string runLabel(const Sweep& sweep, const SweepRun& run) {
    std::string s;
    for (size_t a = 0; a < sweep.axes.size() && s.size() <= 2 * kMaxEchoChars; ++a)
        s += (a ? " " : "") + sweep.axes[a].name + "=" + sweep.axes[a].labels[run.point[a]];
    return s.empty() ? "(base)" : shortText(s, 2 * kMaxEchoChars);
}

std::string absoluteFolder(const std::string& dir) {
    std::string s = std::filesystem::absolute(dir).lexically_normal().string();
    while (s.size() > 1 && s.back() == '/') s.pop_back();
    return s;
}

Json Sweep::runConfig(size_t k) const {
    const SweepRun& run = runs.at(k);
    Json config = base;
    for (size_t a = 0; a < axes.size(); ++a) {
        const SweepAxis& axis = axes[a];
        for (size_t p = 0; p < axis.paths.size(); ++p) {
            const Json& v = axis.values[p][run.point[a]];
            try {
                // The --set walker, so an axis path means exactly what --set PATH means.
                applyOverride(config, axis.paths[p] + "=" + v.dump());
            } catch (const InputError& e) {
                throw InputError(file, axisWhere(a, axis) + ", path " + axis.paths[p], e.cause() + " (at " + e.jsonPath() + ")");
            } catch (const std::exception& e) {
                throw InputError(file, axisWhere(a, axis) + ", path " + axis.paths[p], e.what());
            }
        }
    }
    return config;
}

Json planJson(const Sweep& sweep) {
    Json axes = Json::array(), runs = Json::array();
    for (const auto& a : sweep.axes) axes.push_back({{"name", a.name}, {"scale", toString(a.scale)}, {"labels", a.labels}, {"paths", a.paths}});
    for (const auto& r : sweep.runs) {
        Json labels = Json::object();
        for (size_t a = 0; a < sweep.axes.size(); ++a) labels[sweep.axes[a].name] = sweep.axes[a].labels[r.point[a]];
        runs.push_back({{"index", r.index}, {"id", r.id}, {"axes", labels}});
    }
    return {{"name", sweep.name}, {"file", sweep.file}, {"axes", axes}, {"merge", sweep.merge}, {"runs", runs}};
}

Json Sweep::snapshot(const std::string& dir) const {
    Json j = {{"name", name}, {"base", base}, {"axes", axesJson}, {"output", {{"dir", absoluteFolder(dir)}}}};
    if (!merge.empty()) j["merge"] = merge;
    return j;
}

Sweep parseSweep(const Json& json, const std::string& file) {
    Sweep s;
    s.file = file;
    // The file's name reaches plan.json and messages; its folder anchors every relative path.
    if (const std::string why = pathTextProblem(file); !why.empty()) throw InputError(shortText(file), "", "the file's path " + why);
    const std::string sweepDir = absoluteFolder(parentDir(file));
    if (!isValidUtf8(sweepDir)) throw InputError(file, "", "the absolute path of its folder is not valid UTF-8");
    JsonNode root(file, &json, "", nullptr);
    const bool named = root.has("name");
    s.name = root.getString("name", defaultName(file));
    // The name titles the report, names the Slurm job and the default output folder.
    if (const std::string why = userTextProblem(s.name); !why.empty()) {
        if (named) root.fail("name", "the name \"" + shortText(s.name, 60) + "\" " + why);
        throw InputError(file, "", "the file name, the sweep's default name, " + why + ": give the sweep a \"name\"");
    }
    if (s.name.empty()) root.fail("name", "must not be empty");

    // The base: a config inline, or the name of a config file (relative to the sweep file).
    if (!root.has("base")) root.fail("base", "required key is missing (an experiment config, inline or a file name)");
    const Json& base = root.raw()["base"];
    root.markRead("base");
    std::string baseFile = file, baseDir = sweepDir, baseWhere = "/base";
    if (base.is_string()) {
        // As written, before "a/\0/../b" folds (probe 26), and as resolved (the sweep's folder).
        if (const std::string why = pathTextProblem(base.get<std::string>()); !why.empty()) root.fail("base", "the file name " + why);
        baseFile = resolvePath(sweepDir, base.get<std::string>());
        if (const std::string why = pathTextProblem(baseFile); !why.empty()) root.fail("base", "the file name " + why);
        // A file that cannot be read as JSON is named from the sweep's /base (seventh probe: a
        // FIFO or a missing file named neither the sweep file nor /base).
        try {
            s.base = JsonNode::parseFile(baseFile);
        } catch (const InputError& e) {
            if (!e.jsonPath().empty()) throw;
            throw InputError(file, "/base", "the base config " + shortText(baseFile, 200) + ": " + e.cause());
        }
        baseDir = absoluteFolder(parentDir(baseFile));
        baseWhere = "";
    } else if (base.is_object()) {
        s.base = base;
    } else {
        root.fail("base", "expected an experiment config object or the file name of one");
    }
    // Run configs are written under the output folder: their glTF files must not depend on where.
    if (s.base.is_object() && s.base.contains("scene")) absolutiseScenePaths(s.base["scene"], baseDir);

    std::set<std::string> names, paths;
    s.axesJson = root.has("axes") ? root.raw()["axes"] : Json::array();
    std::vector<JsonNode> axisNodes = root.objectArray("axes");
    for (size_t a = 0; a < axisNodes.size(); ++a) {
        s.axes.push_back(parseAxis(axisNodes[a], a, names, paths, sweepDir));
        names.insert(asciiLowerCase(s.axes.back().name));
        // The snapshot carries the values as the runs use them (glTF paths absolute), so that
        // DIR/sweep.json, read from DIR, gives the same runs.
        Json& values = s.axesJson[a]["values"];
        for (size_t p = 0; p < s.axes.back().paths.size(); ++p) values[s.axes.back().paths[p]] = s.axes.back().values[p];
    }

    JsonNode merge = root.child("merge");
    // Every key merge takes is marked read, given or not, so an unknown one's error lists them all.
    for (const char* key : {"stages", "counters", "ratios", "paper"}) merge.markRead(key);
    for (const char* key : {"stages", "counters", "ratios"}) {
        if (!merge.has(key)) continue;
        const Json& list = merge.raw()[key];
        bool ok = list.is_array();
        for (const Json& v : list) ok = ok && v.is_string() && userTextProblem(v.get<std::string>()).empty();
        if (!ok) merge.fail(key, "expected a list of strings (one line each, at most " + std::to_string(kMaxLabelChars) + " characters)");
        if (std::string(key) == "ratios")
            for (size_t k = 0; k < list.size(); ++k) {
                const std::string ratio = list[k].get<std::string>();
                const size_t slash = ratio.find('/');
                // Each named at its index (seventh probe: "/merge/ratios" without one, "/" called an id over itself).
                const std::string where = std::string(key) + "/" + std::to_string(k);
                if (slash == std::string::npos)
                    merge.fail(where, "\"" + shortText(ratio, 60) + "\" is not ID/ID (the total time of one algorithm id over another's)");
                if (slash == 0 || slash + 1 == ratio.size())
                    merge.fail(where, "\"" + shortText(ratio, 60) + "\" has an empty id: name two ids, ID/ID");
                if (ratio.substr(0, slash) == ratio.substr(slash + 1))
                    merge.fail(where, "\"" + shortText(ratio, 60) + "\" is an id over itself (always 1): name two ids");
            }
        // A table row or column twice would show the same numbers twice under one name.
        std::set<std::string> seen;
        for (size_t k = 0; k < list.size(); ++k)
            if (!seen.insert(list[k].get<std::string>()).second)
                merge.fail(std::string(key) + "/" + std::to_string(k), "\"" + list[k].get<std::string>() + "\" is given twice");
    }
    // merge.paper: a paper's own times for some of the algorithm ids, so that sweep.md gives the
    // paper's ratio beside each measured one (its source named, e.g. "Sintorn et al. 2014, Fig. 1").
    if (merge.has("paper")) {
        JsonNode paper = merge.child("paper");
        const std::string source = paper.requireString("source");
        if (const std::string why = userTextProblem(source); !why.empty()) paper.fail("source", "the source " + why);
        if (source.find_first_not_of(' ') == std::string::npos) paper.fail("source", "must name the paper (it heads the paper's column)");
        JsonNode times = paper.child("times_ms");
        if (!paper.raw().contains("times_ms") || !paper.raw()["times_ms"].is_object() || paper.raw()["times_ms"].empty())
            paper.fail("times_ms", "expected an object of algorithm id: milliseconds");
        for (const auto& [id, value] : paper.raw()["times_ms"].items()) {
            if (const std::string why = userTextProblem(id); !why.empty()) times.fail(id, "the id " + why);
            times.getFloat(id, 0.0, 1e-9, 1e9);
        }
        times.finish();
        paper.finish();
    }
    merge.finish();
    s.merge = root.has("merge") ? root.raw()["merge"] : Json::object();
    JsonNode out = root.child("output");
    if (out.has("dir") && out.raw()["dir"].is_string() && out.raw()["dir"].get<std::string>().empty())
        out.fail("dir", "must not be empty (the sweep's folder: DIR/sweep.json, DIR/runs/)");
    if (!out.has("dir") && !isFileName(s.name))
        root.fail("name", "\"" + shortText(s.name, 60) + "\" cannot name the default output folder results/NAME (it holds '/' or "
                          "'\\', or is '.' or '..'): give output.dir");
    s.outputDir = out.getPath("dir", "results/" + s.name);
    if (const std::string why = pathTextProblem(s.outputDir); !why.empty()) out.fail("dir", "the folder's name " + why);
    out.finish();
    root.finish();

    size_t total = 1;
    for (const auto& axis : s.axes) {
        total *= axis.size();
        if (total > kMaxRuns) root.fail("axes", "more than " + std::to_string(kMaxRuns) + " runs");
    }

    // One run at a time: its config is made, validated and dropped before the next, so memory is
    // the base's a few times over, whatever the number of runs.
    std::map<std::string, size_t> ids;
    std::vector<std::set<std::string>> idsPerRun; // the ids of each run, for merge's ids and ratios
    s.runs.reserve(total);
    for (size_t index = 0; index < total; ++index) {
        SweepRun run;
        run.index = index;
        run.point.resize(s.axes.size());
        for (size_t a = s.axes.size(), rest = index; a-- > 0;) {
            run.point[a] = rest % s.axes[a].size();
            rest /= s.axes[a].size();
        }
        s.runs.push_back(run);
        try {
            Json resolved;
            {
                const Json config = s.runConfig(index);
                try {
                    resolved = resolveRun(config, baseFile);
                } catch (const InputError& e) {
                    if (e.file() != baseFile) throw; // a glTF file's own error names that file
                    rethrowRunError(e, s, run, baseFile, baseWhere);
                }
            }
            s.runs.back().id = runId(resolved);
            collectIds(resolved, idsPerRun.emplace_back());
        } catch (const Json::exception& e) {
            // Text that JSON cannot hold (a path that is not UTF-8) or a value of the wrong type
            // deep in a config: bad input, not a crash.
            throw InputError(file, "", "run " + std::to_string(index) + " (" + runLabel(s, run) + "): " + e.what());
        }
        if (auto [it, fresh] = ids.emplace(s.runs.back().id, index); !fresh)
            root.fail("axes", "runs " + std::to_string(it->second) + " (" + runLabel(s, s.runs[it->second]) + ") and " +
                                  std::to_string(index) + " (" + runLabel(s, run) +
                                  ") resolve to the same config (an axis repeats a value, or sets one to its default)");
    }
    checkMergeIds(s, idsPerRun);
    return s;
}

Sweep loadSweep(const std::string& file) { return parseSweep(JsonNode::parseFile(file), file); }

} // namespace shadowlab
