#include "framework/core/Params.h"

#include <cmath>
#include <sstream>

namespace shadowlab {

const char* toString(ParamType t) {
    switch (t) {
    case ParamType::Bool: return "bool";
    case ParamType::Int: return "int";
    case ParamType::Float: return "float";
    case ParamType::Enum: return "enum";
    }
    return "?";
}

const char* toString(ParamChange c) {
    switch (c) {
    case ParamChange::Update: return "update";
    case ParamChange::Recompile: return "recompile";
    case ParamChange::Rebuild: return "rebuild";
    }
    return "?";
}

std::string toString(const ParamValue& v) {
    struct V {
        std::string operator()(bool b) const { return b ? "true" : "false"; }
        std::string operator()(int i) const { return std::to_string(i); }
        std::string operator()(double d) const {
            std::ostringstream os;
            os << d;
            return os.str();
        }
        std::string operator()(const std::string& s) const { return s; }
    };
    return std::visit(V{}, v);
}

static Json valueToJson(const ParamValue& v) {
    return std::visit([](const auto& x) { return Json(x); }, v);
}

ParamSchema& ParamSchema::boolean(std::string key, bool def, std::string doc, ParamChange change) {
    specs_.push_back({std::move(key), ParamType::Bool, def, 0, 1, "", std::move(doc), {}, change, {}});
    return *this;
}

ParamSchema& ParamSchema::integer(std::string key, int def, int min, int max, std::string unit, std::string doc,
                                  ParamChange change) {
    specs_.push_back({std::move(key), ParamType::Int, def, double(min), double(max), std::move(unit), std::move(doc), {}, change, {}});
    return *this;
}

ParamSchema& ParamSchema::real(std::string key, double def, double min, double max, std::string unit, std::string doc,
                               ParamChange change) {
    specs_.push_back({std::move(key), ParamType::Float, def, min, max, std::move(unit), std::move(doc), {}, change, {}});
    return *this;
}

ParamSchema& ParamSchema::choice(std::string key, std::string def, std::vector<std::string> choices, std::string doc,
                                 ParamChange change) {
    specs_.push_back({std::move(key), ParamType::Enum, std::move(def), 0, 0, "", std::move(doc), std::move(choices), change, {}});
    return *this;
}

ParamSchema& ParamSchema::rule(std::string key, std::function<std::string(const ParamValues&)> problem) {
    rules_.push_back({std::move(key), std::move(problem)});
    return *this;
}

const ParamSpec* ParamSchema::find(const std::string& key) const {
    for (const auto& s : specs_)
        if (s.key == key) return &s;
    return nullptr;
}

Json ParamSchema::toJson() const {
    Json out = Json::array();
    for (const auto& s : specs_) {
        Json j = {{"key", s.key}, {"type", toString(s.type)}, {"default", valueToJson(s.def)}, {"doc", s.doc},
                  {"change", toString(s.change)}};
        if (s.type == ParamType::Int || s.type == ParamType::Float) j["range"] = {s.min, s.max};
        if (!s.unit.empty()) j["unit"] = s.unit;
        if (s.type == ParamType::Enum) j["choices"] = s.choices;
        out.push_back(j);
    }
    return out;
}

std::string ParamSchema::markdownTable() const {
    std::ostringstream os;
    os << "| key | type | default | range | change | meaning |\n|---|---|---|---|---|---|\n";
    for (const auto& s : specs_) {
        std::string range;
        if (s.type == ParamType::Int) range = std::to_string(int(s.min)) + "–" + std::to_string(int(s.max));
        if (s.type == ParamType::Float) range = toString(ParamValue(s.min)) + "–" + toString(ParamValue(s.max));
        if (s.type == ParamType::Enum)
            for (const auto& c : s.choices) range += (range.empty() ? "`" : ", `") + c + "`";
        if (!s.unit.empty()) range += " " + s.unit;
        os << "| `" << s.key << "` | " << toString(s.type) << " | `" << toString(s.def) << "` | " << range << " | "
           << toString(s.change) << " | " << s.doc << " |\n";
    }
    return os.str();
}

ParamValues::ParamValues(const ParamSchema& schema) : schema_(&schema) {
    for (const auto& s : schema.specs()) values_[s.key] = s.def;
}

ParamValues ParamValues::parse(const ParamSchema& schema, JsonNode node) {
    ParamValues out(schema);
    for (const auto& s : schema.specs()) {
        switch (s.type) {
        case ParamType::Bool: out.values_[s.key] = node.getBool(s.key, std::get<bool>(s.def)); break;
        case ParamType::Int:
            out.values_[s.key] = node.getInt(s.key, std::get<int>(s.def), int(s.min), int(s.max));
            break;
        case ParamType::Float: out.values_[s.key] = node.getFloat(s.key, std::get<double>(s.def), s.min, s.max); break;
        case ParamType::Enum: out.values_[s.key] = node.getEnum(s.key, std::get<std::string>(s.def), s.choices); break;
        }
    }
    std::string why;
    if (const ParamRule* r = out.brokenRule(&why)) node.fail(r->key, why);
    node.finish();
    return out;
}

const ParamRule* ParamValues::brokenRule(std::string* why) const {
    if (!schema_) return nullptr;
    for (const ParamRule& r : schema_->rules())
        if (std::string p = r.problem(*this); !p.empty()) {
            if (why) *why = std::move(p);
            return &r;
        }
    return nullptr;
}

void ParamValues::checkRules(const std::string& file, const std::string& pathPrefix) const {
    std::string why;
    if (const ParamRule* r = brokenRule(&why)) throw InputError(file, pathPrefix + "/" + r->key, why);
}

const ParamSpec& ParamValues::spec(const std::string& key) const {
    const ParamSpec* s = schema_ ? schema_->find(key) : nullptr;
    if (!s) throw InputError("", "", "unknown parameter \"" + key + "\"");
    return *s;
}

const ParamValue& ParamValues::get(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) throw InputError("", "", "unknown parameter \"" + key + "\"");
    return it->second;
}


void ParamValues::set(const std::string& key, const ParamValue& value) { setJson(key, valueToJson(value)); }

void ParamValues::setJson(const std::string& key, const Json& value) {
    const ParamSpec& s = spec(key);
    // Validate through the same path as a config file, so the UI and configs agree on what is legal.
    Json obj = {{key, value}};
    Json resolved;
    JsonNode node("<parameter>", &obj, "", &resolved);
    ParamValue v;
    switch (s.type) {
    case ParamType::Bool: v = node.getBool(key, false); break;
    case ParamType::Int: v = node.getInt(key, 0, int(s.min), int(s.max)); break;
    case ParamType::Float: v = node.getFloat(key, 0, s.min, s.max); break;
    case ParamType::Enum: v = node.getEnum(key, "", s.choices); break;
    }
    values_[key] = v;
}

Json ParamValues::toJson() const {
    Json out = Json::object();
    for (const auto& [k, v] : values_) out[k] = valueToJson(v);
    return out;
}

} // namespace shadowlab
