#pragma once
// Strict, path-aware reading of JSON config objects.
//
// Every read names its key, so a missing key takes its default and the value actually used is
// copied into a "resolved" JSON tree beside the input (written out as config.resolved.json).
// finish() turns every key that nobody read into an InputError naming its JSON path and the
// accepted keys: a typo fails loudly instead of being ignored.
#include "framework/core/Error.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <memory>
#include <set>
#include <string>
#include <vector>

namespace shadowlab {

using Json = nlohmann::json;

/// A command-line value ("[64,64]", "3", "true", "\"x\"", or bare text): JSON when it parses as
/// JSON, else the text as a JSON string. Text starting with [ { " - or a digit must parse (its
/// InputError is thrown). Shared by every --set, so they all accept the same input.
Json parseJsonOrString(const std::string& text);

/// The largest finite float.
constexpr double kFloatMax = 3.4028234663852886e38;
/// The largest coordinate a position may have: squared distances (3·1e30) must stay finite in the
/// float arithmetic of the shaders and of Embree; anything farther is a typo, not a scene.
constexpr double kMaxCoordinate = 1e15;

class JsonNode {
public:
    /// `file` names the source in errors and anchors relative paths; `resolved` receives the values used.
    JsonNode(std::string file, const Json* value, std::string path, Json* resolved);

    /// Parses a whole file; throws InputError (with the parser's message) when it is not valid JSON.
    static Json parseFile(const std::string& file);

    const std::string& file() const { return file_; }
    const std::string& path() const { return path_; }
    const Json& raw() const { return *value_; }
    bool has(const std::string& key) const;
    std::string childPath(const std::string& key) const;

    // Typed reads. get() returns `def` when the key is absent; require() fails when absent.
    bool getBool(const std::string& key, bool def);
    int getInt(const std::string& key, int def, int minValue = INT32_MIN, int maxValue = INT32_MAX);
    /// Every number read here may reach the GPU as a float, so the default range is the float's.
    double getFloat(const std::string& key, double def, double minValue = -kFloatMax, double maxValue = kFloatMax);
    std::string getString(const std::string& key, const std::string& def);
    std::string getEnum(const std::string& key, const std::string& def, const std::vector<std::string>& choices);
    /// Each component must be finite as a float (1e39 is a finite double but an infinite float).
    glm::vec3 getVec3(const std::string& key, glm::vec3 def);
    /// A position in world units: a vec3 whose components lie within ±kMaxCoordinate.
    glm::vec3 getPoint(const std::string& key, glm::vec3 def);
    glm::vec2 getVec2(const std::string& key, glm::vec2 def);
    /// An array of positions ([[x, y, z], ...], each held to getPoint's rules); an error names the
    /// element (KEY/i). Empty when absent.
    std::vector<glm::vec3> getPointList(const std::string& key);
    /// An array of integer triples ([[a, b, c], ...]), each value in [0, count); empty when absent.
    std::vector<glm::ivec3> getIndexTriples(const std::string& key, int count);
    glm::ivec2 getIVec2(const std::string& key, glm::ivec2 def, int minValue, int maxValue);
    glm::ivec3 getIVec3(const std::string& key, glm::ivec3 def, int minValue, int maxValue);
    std::vector<int> getIntList(const std::string& key, const std::vector<int>& def);
    std::string requireString(const std::string& key);
    /// A path string resolved against the folder of this node's file (absolute paths kept).
    std::string getPath(const std::string& key, const std::string& def);

    /// An optional object child: an empty object when absent (so its defaults still resolve).
    JsonNode child(const std::string& key);
    /// An optional array of objects (empty when absent).
    std::vector<JsonNode> objectArray(const std::string& key);
    /// Marks a key as read without reading it (e.g. a discriminator handled elsewhere).
    void markRead(const std::string& key);

    /// Fails on any key of this object that was never read.
    void finish() const;

    [[noreturn]] void fail(const std::string& key, const std::string& cause) const;
    [[noreturn]] void failHere(const std::string& cause) const;

private:
    const Json* lookup(const std::string& key);
    void record(const std::string& key, const Json& value);
    template <class T> std::vector<T> numberArray(const std::string& key, size_t n, bool integral);

    std::string file_;
    const Json* value_;
    std::string path_;
    Json* resolved_;
    std::shared_ptr<std::set<std::string>> read_ = std::make_shared<std::set<std::string>>();
    std::shared_ptr<Json> emptyObject_;
};

/// The folder of a file path ("" → ".").
std::string parentDir(const std::string& file);
/// `p` resolved against `baseDir` unless it is absolute.
std::string resolvePath(const std::string& baseDir, const std::string& p);

} // namespace shadowlab
