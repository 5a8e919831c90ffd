#pragma once
// One parameter schema per algorithm. The schema is the single place a parameter is declared:
// config validation, `shadowlab list`, results metadata, docs and the GUI panel all read it.
#include "framework/core/JsonNode.h"

#include <map>
#include <string>
#include <variant>
#include <vector>

namespace shadowlab {

enum class ParamType { Bool, Int, Float, Enum };

/// What a change of the parameter costs: re-running setScene()/resources, or only new uniforms.
enum class ParamChange { Rebuild, Update };

using ParamValue = std::variant<bool, int, double, std::string>;

struct ParamSpec {
    std::string key;                  ///< JSON key, also the results label and UI label
    ParamType type = ParamType::Float;
    ParamValue def;                   ///< default value
    double min = 0, max = 0;          ///< inclusive range (Int, Float)
    std::string unit;                 ///< unit shown beside the value ("px", "texels", "world units"); may be empty
    std::string doc;                  ///< one line: what it does
    std::vector<std::string> choices; ///< accepted values (Enum)
    ParamChange change = ParamChange::Update;
};

class ParamSchema {
public:
    ParamSchema& boolean(std::string key, bool def, std::string doc, ParamChange change);
    ParamSchema& integer(std::string key, int def, int min, int max, std::string unit, std::string doc, ParamChange change);
    ParamSchema& real(std::string key, double def, double min, double max, std::string unit, std::string doc,
                      ParamChange change);
    ParamSchema& choice(std::string key, std::string def, std::vector<std::string> choices, std::string doc,
                        ParamChange change);

    const std::vector<ParamSpec>& specs() const { return specs_; }
    const ParamSpec* find(const std::string& key) const;

    /// Schema as JSON (for `list --json` and results).
    Json toJson() const;

private:
    std::vector<ParamSpec> specs_;
};

/// Values for every key of a schema (defaults filled in).
class ParamValues {
public:
    ParamValues() = default;
    explicit ParamValues(const ParamSchema& schema); ///< all defaults

    /// Reads and validates `node` against `schema`: unknown keys, wrong types and out-of-range
    /// values are InputErrors naming their JSON path. Missing keys take their defaults.
    static ParamValues parse(const ParamSchema& schema, JsonNode node);

    bool getBool(const std::string& key) const;
    int getInt(const std::string& key) const;
    double getFloat(const std::string& key) const;
    const std::string& getEnum(const std::string& key) const;

    /// Sets one value; throws InputError when the key is unknown or the value invalid for its spec.
    void set(const std::string& key, const ParamValue& value);
    /// The same from a JSON value, validated exactly as in a config file (type, range, choices).
    void setJson(const std::string& key, const Json& value);
    const ParamValue& get(const std::string& key) const;

    Json toJson() const;
    const ParamSchema* schema() const { return schema_; }

private:
    const ParamSpec& spec(const std::string& key) const;
    const ParamSchema* schema_ = nullptr;
    std::map<std::string, ParamValue> values_;
};

std::string toString(const ParamValue& v);
const char* toString(ParamType t);

} // namespace shadowlab
