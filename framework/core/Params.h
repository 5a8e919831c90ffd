#pragma once
// One parameter schema per algorithm. The schema is the single place a parameter is declared:
// config validation, `shadowlab list`, results metadata, docs and the GUI panel all read it.
#include "framework/core/JsonNode.h"

#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace shadowlab {

enum class ParamType { Bool, Int, Float, Enum };

/// What a change of the parameter costs, cheapest first: new uniforms only (Update); new shader
/// programs, the structures kept (Recompile: shader #defines); re-running setScene() and resize()
/// (Rebuild: per-scene structures, buffer sizes). A host applies the costliest kind among the
/// keys that changed (AlgorithmHost::setParams).
enum class ParamChange { Update, Recompile, Rebuild };
const char* toString(ParamChange c);

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
    /// Stores the value into the member of a typed params struct it was declared with (ParamStruct).
    std::function<void(void* params, const ParamValue& value)> assign;
};

class ParamValues;

/// A rule between parameters that no single range or choice list can state (psv: the stackless
/// walk cannot take transparency). Checked wherever values are validated (configs, --set, the
/// GUI), so what validation accepts, an algorithm can run.
struct ParamRule {
    std::string key;  ///< the parameter an error points at (its JSON path)
    std::function<std::string(const ParamValues&)> problem; ///< "" when the values obey the rule, else why not
};

class ParamSchema {
public:
    ParamSchema& boolean(std::string key, bool def, std::string doc, ParamChange change);
    ParamSchema& integer(std::string key, int def, int min, int max, std::string unit, std::string doc, ParamChange change);
    ParamSchema& real(std::string key, double def, double min, double max, std::string unit, std::string doc,
                      ParamChange change);
    ParamSchema& choice(std::string key, std::string def, std::vector<std::string> choices, std::string doc,
                        ParamChange change);

    /// Adds a rule over several parameters; `key` names the one an error points at.
    ParamSchema& rule(std::string key, std::function<std::string(const ParamValues&)> problem);

    const std::vector<ParamSpec>& specs() const { return specs_; }
    const std::vector<ParamRule>& rules() const { return rules_; }
    /// Sets how the last row declared is stored into a typed struct (used by ParamStruct).
    void bindLast(std::function<void(void*, const ParamValue&)> assign) { specs_.back().assign = std::move(assign); }
    const ParamSpec* find(const std::string& key) const;

    /// Schema as JSON (for `list --json` and results).
    Json toJson() const;
    /// Schema as a Markdown table (`list --markdown`): the parameter table of docs/algorithms/NAME.md.
    std::string markdownTable() const;

private:
    std::vector<ParamSpec> specs_;
    std::vector<ParamRule> rules_;
};

/// Values for every key of a schema (defaults filled in).
class ParamValues {
public:
    ParamValues() = default;
    explicit ParamValues(const ParamSchema& schema); ///< all defaults

    /// Reads and validates `node` against `schema`: unknown keys, wrong types and out-of-range
    /// values are InputErrors naming their JSON path. Missing keys take their defaults.
    static ParamValues parse(const ParamSchema& schema, JsonNode node);

    /// Sets one value; throws InputError when the key is unknown or the value invalid for its spec.
    void set(const std::string& key, const ParamValue& value);
    /// The same from a JSON value, validated exactly as in a config file (type, range, choices).
    void setJson(const std::string& key, const Json& value);
    const ParamValue& get(const std::string& key) const;

    /// The first rule of the schema these values break, or nullptr (with `why` its reason).
    const ParamRule* brokenRule(std::string* why) const;
    /// Throws InputError(file, `pathPrefix` + "/" + key, why) for the first broken rule.
    void checkRules(const std::string& file, const std::string& pathPrefix) const;

    Json toJson() const;
    const ParamSchema* schema() const { return schema_; }

private:
    const ParamSpec& spec(const std::string& key) const;
    const ParamSchema* schema_ = nullptr;
    std::map<std::string, ParamValue> values_;
};

std::string toString(const ParamValue& v);
const char* toString(ParamType t);

/// One accepted name of a choice parameter and the enumerator it stands for (ParamStruct::choice).
template <class E> struct Choice {
    const char* name;
    E value;
};

/// The config name of a choice's enumerator (resolved parameters, messages).
template <class E> const char* choiceName(const std::vector<Choice<E>>& choices, E value) {
    for (const Choice<E>& c : choices)
        if (c.value == value) return c.name;
    return "?";
}

/// A typed view of one algorithm's parameters: the schema's rows are declared with the member of
/// `T` each one fills, so a key, its type, default, range, unit, doc and change kind are written
/// once, and the algorithm reads plain fields (`params.rayOffset`) instead of strings.
///
///   struct PsvParams { bool wedge = true; float rayOffset = 1e-4f; ... };
///   const ParamStruct<PsvParams>& psvParams() {
///       static const ParamStruct<PsvParams> s = ParamStruct<PsvParams>()
///           .boolean("wedge", &PsvParams::wedge, true, "wedge optimisation", ParamChange::Recompile)
///           .apply(rayOffsetRow<PsvParams>(&PsvParams::rayOffset));   // a shared row
///       return s;
///   }
///   PsvParams p = psvParams().read(values);   // once per change
template <class T>
class ParamStruct {
public:
    ParamStruct& boolean(std::string key, bool T::*member, bool def, std::string doc, ParamChange change) {
        schema_.boolean(std::move(key), def, std::move(doc), change);
        return bind([member](T& t, const ParamValue& v) { t.*member = std::get<bool>(v); });
    }
    ParamStruct& integer(std::string key, int T::*member, int def, int min, int max, std::string unit, std::string doc,
                         ParamChange change) {
        schema_.integer(std::move(key), def, min, max, std::move(unit), std::move(doc), change);
        return bind([member](T& t, const ParamValue& v) { t.*member = std::get<int>(v); });
    }
    /// A real stored as a float (what reaches a shader) or a double.
    template <class F>
    ParamStruct& real(std::string key, F T::*member, double def, double min, double max, std::string unit, std::string doc,
                      ParamChange change) {
        static_assert(std::is_floating_point_v<F>);
        schema_.real(std::move(key), def, min, max, std::move(unit), std::move(doc), change);
        return bind([member](T& t, const ParamValue& v) { t.*member = F(std::get<double>(v)); });
    }
    /// A choice stored as an enumerator: each accepted name is written once, beside the value it
    /// binds, so an algorithm compares enumerators (a misspelt one does not compile) and configs,
    /// `list`, docs and the GUI see the names.
    template <class E>
    ParamStruct& choice(std::string key, E T::*member, E def, std::vector<Choice<E>> choices, std::string doc,
                        ParamChange change) {
        static_assert(std::is_enum_v<E>, "a choice binds an enum class");
        std::vector<std::string> names;
        std::string defName;
        for (const Choice<E>& c : choices) {
            names.push_back(c.name);
            if (c.value == def) defName = c.name;
        }
        schema_.choice(key, defName, std::move(names), std::move(doc), change);
        return bind([member, choices, key](T& t, const ParamValue& v) {
            const std::string& name = std::get<std::string>(v);
            for (const Choice<E>& c : choices)
                if (name == c.name) return void(t.*member = c.value);
            throw std::logic_error("parameter " + key + ": \"" + name + "\" is not one of its choices"); // validated before
        });
    }
    /// A rule over the typed values (see ParamRule); `key` names the parameter an error points at.
    ParamStruct& rule(std::string key, std::function<std::string(const T&)> problem) {
        schema_.rule(std::move(key), [problem](const ParamValues& values) {
            T t{};
            for (const ParamSpec& s : values.schema()->specs()) s.assign(&t, values.get(s.key));
            return problem(t);
        });
        return *this;
    }
    /// Adds rows declared elsewhere once (shared rows such as ray_offset), `row(*this)`.
    template <class Row> ParamStruct& apply(Row row) {
        row(*this);
        return *this;
    }

    const ParamSchema& schema() const { return schema_; }
    /// The values as a T: every member declared here is set.
    T read(const ParamValues& values) const {
        T out{};
        for (const ParamSpec& s : schema_.specs()) s.assign(&out, values.get(s.key));
        return out;
    }

private:
    ParamStruct& bind(std::function<void(T&, const ParamValue&)> set) {
        schema_.bindLast([set](void* p, const ParamValue& v) { set(*static_cast<T*>(p), v); });
        return *this;
    }
    ParamSchema schema_;
};

} // namespace shadowlab
