#include "framework/core/JsonNode.h"

#include "framework/core/FileIO.h"
#include "framework/core/JsonParse.h"
#include "framework/core/Text.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace shadowlab {

namespace fs = std::filesystem;

std::string parentDir(const std::string& file) {
    fs::path p = fs::path(file).parent_path();
    return p.empty() ? std::string(".") : p.string();
}

std::string resolvePath(const std::string& baseDir, const std::string& p) {
    if (p.empty() || fs::path(p).is_absolute()) return p;
    return (fs::path(baseDir) / p).lexically_normal().string();
}

JsonNode::JsonNode(std::string file, const Json* value, std::string path, Json* resolved)
    : file_(std::move(file)), value_(value), path_(std::move(path)), resolved_(resolved) {
    if (!value_) {
        emptyObject_ = std::make_shared<Json>(Json::object());
        value_ = emptyObject_.get();
    }
    if (!value_->is_object()) failHere("expected a JSON object, got " + std::string(value_->type_name()));
    if (resolved_ && !resolved_->is_object()) *resolved_ = Json::object();
}

Json parseJsonOrString(const std::string& text) {
    try {
        return parseJson(text, "--set");
    } catch (const InputError&) {
        // Text that starts as a list, an object, a quoted string or a number was meant as JSON: its
        // parse error is the cause (eleventh probe: a list holding 1e400 was taken as bare text and
        // reported as "expected a list").
        const size_t first = text.find_first_not_of(" \t");
        if (first != std::string::npos && std::string("[{\"-0123456789").find(text[first]) != std::string::npos) throw;
        return Json(text);  // bare text; whatever reads it checks its type
    }
}

Json JsonNode::parseFile(const std::string& file) { return parseJson(readInputFile(file), file); }

bool JsonNode::has(const std::string& key) const {
    // A key the parser asks about is one it accepts: an absent one joins the "accepted keys" an
    // unknown key's error lists (seventh probe: expect, repeats and time_range were left out of it
    // unless the file already used them). A present one is marked when it is read.
    const bool present = value_->contains(key);
    if (!present) read_->insert(key);
    return present;
}

std::string JsonNode::childPath(const std::string& key) const { return path_ + "/" + key; }

void JsonNode::fail(const std::string& key, const std::string& cause) const {
    throw InputError(file_, childPath(key), cause);
}

void JsonNode::failHere(const std::string& cause) const {
    throw InputError(file_, path_.empty() ? "/" : path_, cause);
}

const Json* JsonNode::lookup(const std::string& key) {
    read_->insert(key);
    auto it = value_->find(key);
    return it == value_->end() ? nullptr : &*it;
}

void JsonNode::record(const std::string& key, const Json& value) {
    if (resolved_) (*resolved_)[key] = value;
}

void JsonNode::markRead(const std::string& key) {
    read_->insert(key);
    if (auto it = value_->find(key); it != value_->end()) record(key, *it);
}

bool JsonNode::getBool(const std::string& key, bool def) {
    const Json* v = lookup(key);
    bool out = def;
    if (v) {
        if (!v->is_boolean()) fail(key, "expected true or false, got " + shortDump(*v));
        out = v->get<bool>();
    }
    record(key, out);
    return out;
}

int JsonNode::getInt(const std::string& key, int def, int minValue, int maxValue) {
    const Json* v = lookup(key);
    int out = def;
    if (v) {
        if (!v->is_number_integer() && !(v->is_number_float() && std::floor(v->get<double>()) == v->get<double>()))
            fail(key, "expected an integer, got " + shortDump(*v));
        double d = v->get<double>();
        if (d < minValue || d > maxValue)
            fail(key, "value " + shortDump(*v) + " is out of range [" + std::to_string(minValue) + ", " +
                          std::to_string(maxValue) + "]");
        out = static_cast<int>(d);
    }
    record(key, out);
    return out;
}

namespace {
/// Not 0, yet below the smallest normal float: it would read as 0 (a setting silently off, as a
/// fit_size of 1e-300 was) or lose its precision in the float it is stored in.
bool tooSmallForAFloat(double v) { return v != 0.0 && std::abs(v) < double(std::numeric_limits<float>::min()); }
constexpr const char* kTooSmallForAFloat = " is too small for a float (not 0, yet below 1.2e-38 in magnitude: it would read as 0)";
} // namespace

double JsonNode::getFloat(const std::string& key, double def, double minValue, double maxValue) {
    const Json* v = lookup(key);
    double out = def;
    if (v) {
        if (!v->is_number()) fail(key, "expected a number, got " + shortDump(*v));
        out = v->get<double>();
        if (!std::isfinite(out) || out < minValue || out > maxValue) {
            std::ostringstream os;
            os << "value " << shortDump(*v) << " is out of range [" << minValue << ", " << maxValue << "]";
            fail(key, os.str());
        }
        if (tooSmallForAFloat(out)) fail(key, "value " + shortDump(*v) + kTooSmallForAFloat);
    }
    record(key, out);
    return out;
}

std::string JsonNode::getString(const std::string& key, const std::string& def) {
    const Json* v = lookup(key);
    std::string out = def;
    if (v) {
        if (!v->is_string()) fail(key, "expected a string, got " + shortDump(*v));
        out = v->get<std::string>();
    }
    record(key, out);
    return out;
}

std::string JsonNode::requireString(const std::string& key) {
    if (!has(key)) fail(key, "required key is missing");
    return getString(key, "");
}

std::string JsonNode::getEnum(const std::string& key, const std::string& def, const std::vector<std::string>& choices) {
    std::string s = getString(key, def);
    for (const auto& c : choices)
        if (c == s) return s;
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
    fail(key, "unknown value \"" + s + "\"; accepted: " + list);
}

std::string JsonNode::getPath(const std::string& key, const std::string& def) {
    std::string s = getString(key, def);
    // The text as written, before "a/\0/../b" folds to "b" (probe 25: a NUL, a line break or a
    // bidi mark before a ".." passed every later check of the resolved path).
    if (const std::string why = pathTextProblem(s); !why.empty()) fail(key, "the path " + why);
    return resolvePath(parentDir(file_), s);
}

template <class T>
std::vector<T> JsonNode::numberArray(const std::string& key, size_t n, bool integral) {
    const Json* v = lookup(key);
    if (!v) return {};
    if (!v->is_array() || (n && v->size() != n))
        fail(key, "expected an array of " + (n ? std::to_string(n) + " " : std::string()) + "numbers, got " + shortDump(*v));
    std::vector<T> out;
    for (const auto& e : *v) {
        // An integer written as 1e2 or 100.0 is one, as getInt() takes it (seventh probe: frames
        // took 1.0, resolution refused [1e2, 32]).
        if (!e.is_number() || (integral && !e.is_number_integer() && std::floor(e.get<double>()) != e.get<double>()))
            fail(key, std::string("expected ") + (integral ? "integers" : "numbers") + ", got " + shortDump(*v));
        double d = e.get<double>();
        if (!std::isfinite(d)) fail(key, "non-finite number in " + shortDump(*v));
        if (!integral && std::abs(d) > kFloatMax) fail(key, "number too large for a float in " + shortDump(*v));
        if (!integral && tooSmallForAFloat(d)) fail(key, shortDump(e) + " in " + shortDump(*v) + kTooSmallForAFloat);
        if (integral && (d < INT32_MIN || d > INT32_MAX)) fail(key, "integer out of the 32-bit range in " + shortDump(*v));
        out.push_back(static_cast<T>(d));
    }
    return out;
}

glm::vec3 JsonNode::getVec3(const std::string& key, glm::vec3 def) {
    auto a = numberArray<float>(key, 3, false);
    glm::vec3 out = a.empty() ? def : glm::vec3(a[0], a[1], a[2]);
    record(key, Json::array({out.x, out.y, out.z}));
    return out;
}

glm::vec3 JsonNode::getPoint(const std::string& key, glm::vec3 def) {
    glm::vec3 p = getVec3(key, def);
    for (int i = 0; i < 3; ++i)
        if (std::abs(double(p[i])) > kMaxCoordinate)
            fail(key, "coordinates must lie within ±1e15 (squared distances must stay finite as floats), got " +
                          shortDump(Json::array({p.x, p.y, p.z})));
    return p;
}

glm::vec2 JsonNode::getVec2(const std::string& key, glm::vec2 def) {
    auto a = numberArray<float>(key, 2, false);
    glm::vec2 out = a.empty() ? def : glm::vec2(a[0], a[1]);
    record(key, Json::array({out.x, out.y}));
    return out;
}

namespace {
/// Reads each element of the array `v` (at `path`) through `read`, as the value of a one-key object
/// whose key is its index: the element gets the single-value readers' checks and its path in errors.
template <class T, class Read>
std::vector<T> readElements(const JsonNode& owner, const std::string& key, const Json& v, Read read) {
    if (!v.is_array()) owner.fail(key, "expected an array, got " + std::string(v.type_name()));
    std::vector<T> out;
    out.reserve(v.size());
    for (size_t i = 0; i < v.size(); ++i) {
        const std::string index = std::to_string(i);
        const Json holder = {{index, v[i]}};
        JsonNode element(owner.file(), &holder, owner.childPath(key), nullptr);
        out.push_back(read(element, index));
    }
    return out;
}
} // namespace

std::vector<glm::vec3> JsonNode::getPointList(const std::string& key) {
    const Json* v = lookup(key);
    if (!v) return {};
    auto out = readElements<glm::vec3>(*this, key, *v, [](JsonNode& e, const std::string& i) { return e.getPoint(i, glm::vec3(0.0f)); });
    Json used = Json::array(); // the floats used, as every other vector records them
    for (const glm::vec3& p : out) used.push_back({p.x, p.y, p.z});
    record(key, used);
    return out;
}

std::vector<glm::ivec3> JsonNode::getIndexTriples(const std::string& key, int count) {
    const Json* v = lookup(key);
    if (!v) return {};
    auto out = readElements<glm::ivec3>(*this, key, *v, [count](JsonNode& e, const std::string& i) {
        return e.getIVec3(i, glm::ivec3(0), 0, count - 1);
    });
    record(key, *v);
    return out;
}

glm::ivec2 JsonNode::getIVec2(const std::string& key, glm::ivec2 def, int minValue, int maxValue) {
    auto a = numberArray<int>(key, 2, true);
    glm::ivec2 out = a.empty() ? def : glm::ivec2(a[0], a[1]);
    if (out.x < minValue || out.y < minValue || out.x > maxValue || out.y > maxValue)
        fail(key, "values must lie in [" + std::to_string(minValue) + ", " + std::to_string(maxValue) + "]");
    record(key, Json::array({out.x, out.y}));
    return out;
}

glm::ivec3 JsonNode::getIVec3(const std::string& key, glm::ivec3 def, int minValue, int maxValue) {
    auto a = numberArray<int>(key, 3, true);
    glm::ivec3 out = a.empty() ? def : glm::ivec3(a[0], a[1], a[2]);
    for (int i = 0; i < 3; ++i)
        if (out[i] < minValue || out[i] > maxValue)
            fail(key, "values must lie in [" + std::to_string(minValue) + ", " + std::to_string(maxValue) + "]");
    record(key, Json::array({out.x, out.y, out.z}));
    return out;
}

std::vector<int> JsonNode::getIntList(const std::string& key, const std::vector<int>& def) {
    bool present = has(key);
    auto a = numberArray<int>(key, 0, true);
    std::vector<int> out = present ? a : def;
    record(key, out);
    return out;
}

JsonNode JsonNode::child(const std::string& key) {
    const Json* v = lookup(key);
    if (v && !v->is_object()) fail(key, "expected a JSON object, got " + std::string(v->type_name()));
    Json* res = nullptr;
    if (resolved_) {
        (*resolved_)[key] = Json::object();
        res = &(*resolved_)[key];
    }
    return JsonNode(file_, v, childPath(key), res);
}

std::vector<JsonNode> JsonNode::objectArray(const std::string& key) {
    const Json* v = lookup(key);
    std::vector<JsonNode> out;
    if (!v) {
        record(key, Json::array());
        return out;
    }
    if (!v->is_array()) fail(key, "expected an array of objects, got " + std::string(v->type_name()));
    Json* res = nullptr;
    if (resolved_) {
        (*resolved_)[key] = Json::array();
        res = &(*resolved_)[key];
        for (size_t i = 0; i < v->size(); ++i) res->push_back(Json::object());
    }
    for (size_t i = 0; i < v->size(); ++i)
        out.emplace_back(file_, &(*v)[i], childPath(key) + "/" + std::to_string(i), res ? &(*res)[i] : nullptr);
    return out;
}

void JsonNode::finish() const {
    for (auto it = value_->begin(); it != value_->end(); ++it) {
        if (read_->count(it.key())) continue;
        std::string accepted;
        for (const auto& k : *read_) accepted += (accepted.empty() ? "" : ", ") + k;
        fail(it.key(), "unknown key \"" + it.key() + "\"; accepted keys: " + (accepted.empty() ? "(none)" : accepted));
    }
}

} // namespace shadowlab
