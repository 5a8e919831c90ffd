#pragma once
// Expectations: bounds on what a run measured, written in its config (`expect`, docs/config.md),
// checked once every result is written. A run whose expectations fail keeps all its results, says
// which failed and by how much, and exits with kExpectationsFailedExit, so a CI job can tell "the
// algorithm got wrong or slower" from "the run could not be made" (1) and "bad input" (2).
#include "framework/core/JsonNode.h"

#include <optional>
#include <set>
#include <string>
#include <vector>

namespace shadowlab {

constexpr int kExpectationsFailedExit = 3;

struct Expectation {
    std::string where;              ///< its JSON path, "/expect/K"
    std::string id;                 ///< an algorithm id, "reference", "*" (every algorithm) or "*exact"
    std::string measure;            ///< a path into summary.json's entry of the id, e.g. "time_ms.total.median"
    std::string relativeTo;         ///< "": the measure itself; else the measure over this id's
    std::optional<double> min, max; ///< inclusive bounds, at least one
    std::string note;               ///< why this bound (shown beside it): a non-zero bound says why
};

/// Which algorithm ids an expectation's id stands for.
struct ExpectationIds {
    std::vector<std::string> all;   ///< every algorithm id of the config, in order (no reference)
    std::set<std::string> exact;    ///< those of exact algorithms
    bool reference = false;         ///< the reference runs (its id is "reference")
};

/// Reads `expect` (a list; InputError naming the entry's path for an unknown id or measure, a
/// missing or inverted bound, an accuracy measure without the reference, a time ratio to itself).
std::vector<Expectation> parseExpectations(JsonNode& root, const ExpectationIds& ids);
/// The ids an expectation's id stands for: itself, or a wildcard's ("*", "*exact") ids but its relative_to.
std::vector<std::string> idsOf(const Expectation& e, const ExpectationIds& ids);

/// Checks each expectation for each id it names on summary.json's content: one record per (entry,
/// id) with {where, id, measure, relative_to, min, max, value, passed, why}; `why` says what failed
/// and by how much, or that the measure was not taken (a stage or counter the algorithm does not
/// have, accuracy on frames without lit pixels).
Json checkExpectations(const std::vector<Expectation>& expectations, const ExpectationIds& ids, const Json& summary);

/// Whether every record of checkExpectations() passed.
bool allPassed(const Json& records);

/// One line for a record: "psv: accuracy.mismatch_ratio_max = 0.0012, above max 0 (/expect/0)".
std::string expectationLine(const Json& record);

/// The records as JUnit XML (one test case per record, grouped in one suite named after the
/// experiment), for CI systems that show test reports; every text escaped for XML.
std::string expectationsJUnit(const std::string& experiment, const Json& records, double wallSeconds);

} // namespace shadowlab
