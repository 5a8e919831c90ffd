#include "framework/experiment/Expectations.h"

#include "framework/core/Error.h"
#include "framework/core/Text.h"
#include "framework/experiment/JUnit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace shadowlab {

namespace {

const std::vector<std::string> kFixedMeasures = {"accuracy.mismatch_ratio", "accuracy.mismatch_ratio_max", "accuracy.false_lit",
                                                 "accuracy.false_shadowed", "accuracy.rmse",        "overflow",
                                                 "memory_bytes",            "resident_bytes",              "preprocess_ms"};
const std::vector<std::string> kStatistics = {"mean", "median", "min", "max"};

bool isIdentifier(const std::string& s) {
    return !s.empty() && s.size() <= 64 &&
           std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> parts;
    size_t start = 0;
    for (size_t dot; (dot = s.find(sep, start)) != std::string::npos; start = dot + 1) parts.push_back(s.substr(start, dot - start));
    parts.push_back(s.substr(start));
    return parts;
}

/// "" when `m` names something summary.json holds per algorithm, else why not.
std::string measureProblem(const std::string& m) {
    if (std::find(kFixedMeasures.begin(), kFixedMeasures.end(), m) != kFixedMeasures.end()) return "";
    const std::vector<std::string> parts = split(m, '.');
    if (parts.size() == 3 && (parts[0] == "time_ms" || parts[0] == "counters") && isIdentifier(parts[1]) &&
        std::find(kStatistics.begin(), kStatistics.end(), parts[2]) != kStatistics.end())
        return "";
    std::string why = "\"";
    why += shortText(m, 80);
    return why + "\" is not a measure: accuracy.mismatch_ratio, accuracy.mismatch_ratio_max, accuracy.false_lit, accuracy.false_shadowed, "
           "accuracy.rmse, overflow, memory_bytes, resident_bytes, preprocess_ms, time_ms.STAGE.STAT or counters.NAME.STAT "
           "(STAT: mean, median, min or max)";
}

/// The measure of `id` in summary.json, or why there is none.
std::optional<double> measured(const Json& summary, const std::string& id, const std::string& measure, std::string& why) {
    if (!summary.contains("algorithms") || !summary["algorithms"].contains(id)) {
        why = id + " has no results";
        return std::nullopt;
    }
    const Json* node = &summary["algorithms"][id];
    for (const std::string& key : split(measure, '.')) {
        if (node->is_null()) break;  // accuracy is null where no frame had a lit pixel
        if (!node->is_object() || !node->contains(key)) {
            std::string have;
            if (node->is_object())
                for (const auto& [k, v] : node->items()) have += (have.empty() ? "" : ", ") + k;
            why = id + " did not measure " + measure + (have.empty() ? "" : " (" + key + " is not among: " + shortText(have, 200) + ")");
            return std::nullopt;
        }
        node = &(*node)[key];
    }
    if (node->is_null()) {
        why = id + " has no " + measure + " in this run (no frame had a lit pixel to compare)";
        return std::nullopt;
    }
    if (!node->is_number()) {
        why = id + "'s " + measure + " is not a number";
        return std::nullopt;
    }
    return node->get<double>();
}

} // namespace

/// The ids an expectation's id stands for: a wildcard's never include its relative_to id, which
/// is 1 relative to itself (fifteenth probe: "*" relative to psv passed psv with 1).
std::vector<std::string> idsOf(const Expectation& e, const ExpectationIds& ids) {
    if (e.id != "*" && e.id != "*exact") return {e.id};
    std::vector<std::string> out;
    for (const auto& id : ids.all)
        if ((e.id == "*" || ids.exact.count(id)) && id != e.relativeTo) out.push_back(id);
    return out;
}

std::vector<Expectation> parseExpectations(JsonNode& root, const ExpectationIds& ids) {
    std::vector<Expectation> out;
    if (!root.has("expect")) return out;
    if (!root.raw()["expect"].is_array())
        root.fail("expect", "expected a list of {\"id\", \"measure\", \"max\" and/or \"min\", optional \"relative_to\"}");
    std::vector<JsonNode> entries = root.objectArray("expect");
    for (size_t k = 0; k < entries.size(); ++k) {
        JsonNode& node = entries[k];
        Expectation e;
        e.where = node.path();
        e.id = node.requireString("id");
        const bool known = e.id == "*" || e.id == "*exact" ||
                           std::find(ids.all.begin(), ids.all.end(), e.id) != ids.all.end() || (e.id == "reference" && ids.reference);
        if (!known)
            node.fail("id", "\"" + shortText(e.id, 60) + "\" is not an algorithm id of this experiment (ids: " +
                                shortText([&] {
                                    std::string s;
                                    for (const auto& id : ids.all) s += (s.empty() ? "" : ", ") + id;
                                    return s + (ids.reference ? ", reference" : "");
                                }(), 200) +
                                "; \"*\" for every algorithm, \"*exact\" for the exact ones; where a --set or a sweep's "
                                "axis changes the algorithms, \"expect\": [] (--set expect=[]) leaves the expectations out)");
        e.measure = node.requireString("measure");
        if (const std::string why = measureProblem(e.measure); !why.empty()) node.fail("measure", why);
        if (e.measure.starts_with("accuracy.") && !ids.reference)
            node.fail("measure", "accuracy is measured against the reference, which this experiment turns off (\"reference\": false)");
        if (node.has("relative_to")) {
            e.relativeTo = node.requireString("relative_to");
            if (std::find(ids.all.begin(), ids.all.end(), e.relativeTo) == ids.all.end() && !(e.relativeTo == "reference" && ids.reference))
                node.fail("relative_to", "\"" + shortText(e.relativeTo, 60) + "\" is not an algorithm id of this experiment");
            if (e.relativeTo == e.id) node.fail("relative_to", "an id relative to itself is always 1: name another id");
        }
        // A wildcard that stands for no id would pass without checking anything (fifteenth probe:
        // "*exact" in a run of shadow_map alone was "all 0 met").
        if (idsOf(e, ids).empty())
            node.fail("id", "\"" + e.id + "\" stands for no algorithm of this experiment" +
                                (e.relativeTo.empty() ? "" : " but its relative_to") + ": the check would pass without checking anything");
        if (node.has("min")) e.min = node.getFloat("min", 0);
        if (node.has("max")) e.max = node.getFloat("max", 0);
        if (!e.min && !e.max) node.fail("max", "an expectation needs \"max\", \"min\" or both");
        if (e.min && e.max && *e.min > *e.max) node.fail("min", "is above max: no value could pass");
        if (node.has("note")) {
            e.note = node.requireString("note");
            if (const std::string why = userTextProblem(e.note); !why.empty()) node.fail("note", "the note " + why);
        }
        node.finish();
        out.push_back(std::move(e));
    }
    return out;
}

Json checkExpectations(const std::vector<Expectation>& expectations, const ExpectationIds& ids, const Json& summary) {
    Json records = Json::array();
    for (const Expectation& e : expectations) {
        for (const std::string& id : idsOf(e, ids)) {
            Json r = {{"where", e.where}, {"id", id}, {"measure", e.measure}, {"relative_to", e.relativeTo.empty() ? Json() : Json(e.relativeTo)},
                      {"min", e.min ? Json(*e.min) : Json()}, {"max", e.max ? Json(*e.max) : Json()}, {"value", Json()},
                      {"note", e.note}};
            std::string why;
            const std::optional<double> own = measured(summary, id, e.measure, why);
            bool has = own.has_value();
            double value = own.value_or(0.0);
            if (has && !e.relativeTo.empty()) {
                const std::optional<double> base = measured(summary, e.relativeTo, e.measure, why);
                has = base.has_value() && *base > 0;
                if (base && !(*base > 0)) why = e.relativeTo + "'s " + e.measure + " is " + shortNumber(*base) + ": no ratio to it";
                if (has) value /= *base;
            }
            const std::string what = id + ": " + e.measure + (e.relativeTo.empty() ? "" : " / " + e.relativeTo + "'s");
            if (has) {
                r["value"] = value;
                // A ratio to the bound only where both are positive (seventh probe: "above max -1 (-0×)").
                if (e.max && !(value <= *e.max))
                    why = what + " = " + shortNumber(value) + ", above max " + shortNumber(*e.max) +
                          (*e.max > 0 && value > 0 ? " (" + shortNumber(value / *e.max) + "×)" : "");
                else if (e.min && !(value >= *e.min))
                    why = what + " = " + shortNumber(value) + ", below min " + shortNumber(*e.min) +
                          (*e.min > 0 && value > 0 ? " (" + shortNumber(value / *e.min) + "×)" : "");
            } else {
                why = id + ": not measured: " + why; // the id, as a measured failure names it (probe 26)
            }
            r["passed"] = why.empty();
            r["why"] = why;
            records.push_back(std::move(r));
        }
    }
    return records;
}

bool allPassed(const Json& records) {
    return std::all_of(records.begin(), records.end(), [](const Json& r) { return r.value("passed", false); });
}

std::string expectationLine(const Json& r) {
    const std::string where = r.value("where", std::string());
    if (!r.value("passed", false)) return r.value("why", std::string()) + " (" + where + ")";
    std::string bound;
    if (!r["min"].is_null()) bound += "min " + shortNumber(r["min"].get<double>());
    if (!r["max"].is_null()) bound += std::string(bound.empty() ? "" : ", ") + "max " + shortNumber(r["max"].get<double>());
    const std::string rel = r["relative_to"].is_null() ? "" : " / " + r["relative_to"].get<std::string>() + "'s";
    return r["id"].get<std::string>() + ": " + r["measure"].get<std::string>() + rel + " = " + shortNumber(r["value"].get<double>()) + " (" +
           bound + "; " + where + ")";
}

std::string expectationsJUnit(const std::string& experiment, const Json& records, double wallSeconds) {
    std::vector<JUnitCase> cases;
    for (const Json& r : records) {
        const std::string rel = r["relative_to"].is_null() ? "" : " / " + r["relative_to"].get<std::string>();
        cases.push_back({r["id"].get<std::string>(), r["measure"].get<std::string>() + rel + " " + r["where"].get<std::string>(),
                         r.value("passed", false) ? std::string() : r.value("why", std::string())});
    }
    return junitXml("shadowlab expectations: " + experiment, cases, wallSeconds);
}

} // namespace shadowlab
