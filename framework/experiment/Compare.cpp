#include "framework/experiment/Compare.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/Text.h"
#include "framework/experiment/Config.h"
#include "framework/experiment/FrameImages.h"
#include "framework/experiment/JUnit.h"
#include "framework/experiment/OutputPlace.h"
#include "framework/metrics/Noise.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>

#include <stb_image.h>
#include <stb_image_write.h>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

bool isUtcTimestamp(const Json& j) {
    if (!j.is_string()) return false;
    const std::string& t = j.get_ref<const std::string&>();
    static const char* kShape = "dddd-dd-ddTdd:dd:ddZ";
    if (t.size() != std::strlen(kShape)) return false;
    for (size_t k = 0; k < t.size(); ++k)
        if (kShape[k] == 'd' ? !(t[k] >= '0' && t[k] <= '9') : t[k] != kShape[k]) return false;
    // And a time that exists (eleventh probe: "2026-13-45T99:99:99Z" sorted as the newest run).
    auto field = [&](size_t at, size_t n) { return std::stoi(t.substr(at, n)); };
    const int year = field(0, 4), month = field(5, 2), day = field(8, 2);
    const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    const int days[12] = {31, leap ? 29 : 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return month >= 1 && month <= 12 && day >= 1 && day <= days[month - 1] && field(11, 2) < 24 && field(14, 2) < 60 &&
           field(17, 2) <= 60;  // 60: a leap second
}

} // namespace

namespace {
/// Counts and counters a run writes stay below 2^64 (1.8e19).
constexpr double kMaxRunNumber = 1e20;

/// Every leaf of `j` is a number (or null): else bad input, naming its JSON path.
void checkNumbersOnly(const Json& j, const std::string& file, const std::string& path) {
    if (j.is_object() || j.is_array()) {
        size_t i = 0;
        for (auto it = j.begin(); it != j.end(); ++it, ++i)
            checkNumbersOnly(*it, file, path + "/" + (j.is_object() ? shortText(it.key(), 60) : std::to_string(i)));
    } else if (!j.is_null() && !(j.is_number() && std::abs(j.get<double>()) <= kMaxRunNumber)) {
        throw InputError(file, path, "holds " + shortText(j.dump(), 40) + " where a run writes a number (of at most 1e20)");
    }
}

/// A time in ms a run measured: a number from 0 (what a coarse timer can read) to 1e12 (30 years)
/// (seventh and fourteenth probes: negative times were tabulated; twenty-first: -5 and a 309-digit
/// time; twenty-second: a null one stopped compare with the JSON library's message and exit 1).
void checkTime(const Json& j, const std::string& file, const std::string& path) {
    if (!(j.is_number() && j.get<double>() >= 0 && j.get<double>() <= 1e12))
        throw InputError(file, path, "holds " + shortText(j.dump(), 40) + " where a run writes a time in ms (0 to 1e12)");
}

/// A statistic of a counter: a run always computes it, a number of at least 0, as every counter is
/// a count, a size, a share or a time (twenty-second probe: a null mean stopped compare with the
/// JSON library's message and exit 1; twenty-fourth: an object did too, and -5e9 rays were tabulated).
void checkMeasured(const Json& j, const std::string& file, const std::string& path) {
    if (!(j.is_number() && j.get<double>() >= 0))
        throw InputError(file, path, "holds " + shortText(j.dump(), 40) + " where a run writes a count (a number, at least 0)");
}

/// A statistic's min, mean, median and max, where given, in the order a run's are: min <= mean,
/// median <= max, within the rounding of a mean (twenty-second probe: min > max was compared).
void checkStatisticOrder(const Json& stats, const std::string& file, const std::string& path) {
    auto at = [&](const char* k) { return stats.contains(k) && stats[k].is_number() ? std::optional<double>(stats[k].get<double>()) : std::nullopt; };
    const auto lo = at("min"), hi = at("max");
    if (!lo || !hi) return;
    const double slack = 1e-9 * std::max(std::abs(*lo), std::abs(*hi));
    if (*lo > *hi + slack) throw InputError(file, path + "/min", "is above its max, which no run writes");
    for (const char* k : {"mean", "median"})
        if (const auto v = at(k); v && (*v < *lo - slack || *v > *hi + slack))
            throw InputError(file, path + "/" + k, "lies outside [min, max], which no run writes");
}

/// Every time of one algorithm entry: the stage statistics, the frames' totals, the repetitions'
/// (as many as the repetitions' count, which a config holds to 1000).
void checkTimes(const Json& entry, const std::string& file, const std::string& at, const Json& frames) {
    if (!entry.contains("time_ms") || !entry["time_ms"].is_object() || !entry["time_ms"].contains("total"))
        throw InputError(file, at + "/time_ms/total", "is missing: every run times each algorithm's total");
    for (const char* key : {"time_ms", "cpu_time_ms"})
        if (entry.contains(key) && entry[key].is_object())
            for (const auto& [stage, stats] : entry[key].items())
                if (stats.is_object()) {
                    for (const auto& [stat, v] : stats.items())
                        checkTime(v, file, at + "/" + key + "/" + shortText(stage, 60) + "/" + shortText(stat, 60));
                    checkStatisticOrder(stats, file, at + "/" + key + "/" + shortText(stage, 60));
                }
    if (entry.contains("counters") && entry["counters"].is_object())
        for (const auto& [name, stats] : entry["counters"].items())
            if (stats.is_object()) {
                for (const auto& [stat, v] : stats.items())
                    checkMeasured(v, file, at + "/counters/" + shortText(name, 60) + "/" + shortText(stat, 60));
                checkStatisticOrder(stats, file, at + "/counters/" + shortText(name, 60));
            }
    if (entry.contains("total_ms_per_frame") && entry["total_ms_per_frame"].is_array() && frames.is_number_unsigned() &&
        entry["total_ms_per_frame"].size() != frames.get<uint64_t>())
        throw InputError(file, at + "/total_ms_per_frame", "holds " + std::to_string(entry["total_ms_per_frame"].size()) +
                                                               " times where the run has " + std::to_string(frames.get<uint64_t>()) + " frames");
    if (entry.contains("total_ms_per_frame") && entry["total_ms_per_frame"].is_array())
        for (size_t i = 0; i < entry["total_ms_per_frame"].size(); ++i)
            checkTime(entry["total_ms_per_frame"][i], file, at + "/total_ms_per_frame/" + std::to_string(i));
    if (entry.contains("repetitions") && entry["repetitions"].is_object() && entry["repetitions"].contains("time_ms") &&
        entry["repetitions"]["time_ms"].is_object())
        for (const auto& [stage, times] : entry["repetitions"]["time_ms"].items()) {
            if (!times.is_array()) continue;
            const std::string path = at + "/repetitions/time_ms/" + shortText(stage, 60);
            const Json& count = entry["repetitions"].value("count", Json());
            if (count.is_number_unsigned() && times.size() != count.get<uint64_t>())
                throw InputError(file, path, "holds " + std::to_string(times.size()) + " times where the repetitions' count is " +
                                                 std::to_string(count.get<uint64_t>()));
            for (size_t i = 0; i < times.size(); ++i) checkTime(times[i], file, path + "/" + std::to_string(i));
        }
}

/// A count: an integer, 0 or more (1e30, -1 and 0.5 are no run's).
void checkCount(const Json& j, const std::string& file, const std::string& path) {
    if (!j.is_number_unsigned() && !(j.is_number_integer() && j.get<int64_t>() >= 0))
        throw InputError(file, path, "holds " + shortText(j.dump(), 40) + " where a run writes a count (an integer, 0 or more)");
}

/// accuracy: null, or an object of shares in [0, 1] and counts.
void checkAccuracy(const Json& a, const std::string& file, const std::string& path) {
    if (a.is_null()) return;
    if (!a.is_object()) throw InputError(file, path, "is neither null nor an object, as a run writes it");
    for (const char* key : {"mismatch_ratio", "mismatch_ratio_max", "false_lit", "false_shadowed", "rmse"})
        if (a.contains(key) && !(a[key].is_number() && a[key].get<double>() >= 0 && a[key].get<double>() <= 1))
            throw InputError(file, path + "/" + key, "holds " + shortText(a[key].dump(), 40) + " where a run writes a share in [0, 1]");
    for (const char* key : {"frames_measured", "false_lit_pixels", "false_shadowed_pixels"})
        if (a.contains(key)) checkCount(a[key], file, path + "/" + key);
    for (const char* key : {"per_frame_mismatch", "per_frame_wrong_pixels"}) {
        if (!a.contains(key)) continue;
        if (!a[key].is_array()) throw InputError(file, path + "/" + key, "is not a list, as a run writes it");
        for (size_t i = 0; i < a[key].size(); ++i) {
            const Json& v = a[key][i];
            const std::string where = path + "/" + key + "/" + std::to_string(i);
            if (std::string(key) == "per_frame_wrong_pixels") {
                if (!v.is_null()) checkCount(v, file, where);
            } else if (!(v.is_number() && v.get<double>() >= 0 && v.get<double>() <= 1)) {
                throw InputError(file, where, "holds " + shortText(v.dump(), 40) + " where a run writes a share in [0, 1]");
            }
        }
    }
    // The worst frame is the worst of the frames and of their mean (twenty-fourth probe: frames of
    // 50 % beside a worst frame of 0 compared as "same").
    if (a.contains("mismatch_ratio_max")) {
        // With the rounding of a mean of frames beside it, relative and near 0.
        const double worst = a["mismatch_ratio_max"].get<double>() * (1 + 1e-9) + 1e-12;
        if (a.contains("mismatch_ratio") && a["mismatch_ratio"].get<double>() > worst)
            throw InputError(file, path + "/mismatch_ratio", "lies above mismatch_ratio_max, which no run writes");
        if (a.contains("per_frame_mismatch"))
            for (size_t i = 0; i < a["per_frame_mismatch"].size(); ++i)
                if (a["per_frame_mismatch"][i].get<double>() > worst)
                    throw InputError(file, path + "/per_frame_mismatch/" + std::to_string(i), "lies above mismatch_ratio_max, which no run writes");
    }
}

/// The nesting compare and history read is the one a run writes (seventeenth probe: a stage time
/// written as a bare number, or repetitions without their times, stopped compare and history
/// with the JSON library's message and exit 1): time_ms, cpu_time_ms and counters map names to
/// statistics objects; repetitions holds a count and, per stage, a list of times; the frames'
/// totals are a list; the algorithm is a name as a run writes it (a formula in it reached sweep.csv).
void checkRunFieldShapes(const Json& entry, const std::string& file, const std::string& at) {
    if (entry.contains("algorithm") && !(entry["algorithm"].is_string() && isAlgorithmId(entry["algorithm"].get<std::string>())))
        throw InputError(file, at + "/algorithm", "holds " + shortText(entry["algorithm"].dump(), 40) + " where a run writes an algorithm's name");
    for (const char* key : {"time_ms", "cpu_time_ms", "counters"}) {
        if (!entry.contains(key)) continue;
        if (!entry[key].is_object()) throw InputError(file, at + "/" + key, "is not an object, as a run writes it");
        for (const auto& [name, stats] : entry[key].items())
            if (!stats.is_object())
                throw InputError(file, at + "/" + key + "/" + shortText(name, 60), "is not an object of statistics (mean, median, ...), as a run writes it");
    }
    if (entry.contains("total_ms_per_frame") && !entry["total_ms_per_frame"].is_array())
        throw InputError(file, at + "/total_ms_per_frame", "is not a list, as a run writes it");
    if (entry.contains("repetitions")) {
        const Json& r = entry["repetitions"];
        if (!r.is_object() || !r.contains("count") || !r.contains("time_ms") || !r["time_ms"].is_object())
            throw InputError(file, at + "/repetitions", "is not a run's repetitions ({\"count\": N, \"time_ms\": {stage: [times]}})");
        checkCount(r["count"], file, at + "/repetitions/count");
        for (const auto& [name, times] : r["time_ms"].items())
            if (!times.is_array())
                throw InputError(file, at + "/repetitions/time_ms/" + shortText(name, 60), "is not a list of times, as a run writes it");
    }
}

/// The fields compare and history read have the types a run writes (eighth probe: a time written
/// as the string "NaN" stopped compare with a library's message and exit 1).
void checkRunFieldTypes(const Json& s, const std::string& file) {
    for (const char* key : {"renderer", "name"})
        if (s.contains(key) && !s[key].is_string()) throw InputError(file, std::string("/") + key, "is not text, as a run writes it");
    // Text that reaches tables and reports is one short line of visible characters (twenty-second
    // probe: sweep merge copied a 1 MB renderer, bidi overrides and zero-width spaces into sweep.md).
    for (const char* key : {"renderer", "gl_version", "backend", "stage_time_source"})
        if (s.contains(key) && s[key].is_string())
            if (const std::string why = userTextProblem(s[key].get<std::string>()); !why.empty())
                throw InputError(file, std::string("/") + key, "is not text a run writes: " + why);
    if (s.contains("memory") && !s["memory"].is_object()) throw InputError(file, "/memory", "is not an object, as a run writes it");
    if (s.contains("frames")) checkCount(s["frames"], file, "/frames");
    if (s.contains("build")) {
        const Json& b = s["build"];
        if (!b.is_object() || (b.contains("commit") && !b["commit"].is_string()) || (b.contains("dirty") && !b["dirty"].is_boolean()))
            throw InputError(file, "/build", "is not a run's build record ({\"commit\": text, \"dirty\": true or false})");
    }
    if (s.contains("triangles")) checkCount(s["triangles"], file, "/triangles");
    // Each side what a config may ask (twenty-first probe: sweep merge multiplied 2^33 + 1 by 2^31
    // into a wrapped pixel count, and took 0 x 0).
    if (s.contains("resolution")) {
        const Json& r = s["resolution"];
        const auto side = [](const Json& v) {
            return v.is_number_unsigned() && v.get<uint64_t>() >= uint64_t(configlimits::kResolutionMin) &&
                   v.get<uint64_t>() <= uint64_t(configlimits::kResolutionMax);
        };
        if (!r.is_array() || r.size() != 2 || !side(r[0]) || !side(r[1]))
            throw InputError(file, "/resolution", "holds " + shortText(r.dump(), 40) + " where a run writes [width, height] of " +
                                                      std::to_string(configlimits::kResolutionMin) + " to " +
                                                      std::to_string(configlimits::kResolutionMax) + " pixels each");
    }
    for (const auto& [id, entry] : s["algorithms"].items()) {
        const std::string at = "/algorithms/" + shortText(id, 60);
        // Ids reach file names, tables and JUnit classnames (eleventh probe: control characters
        // and U+FFFE in one made compare.junit.xml unreadable).
        if (!isAlgorithmId(id))
            throw InputError(file, "/algorithms", "holds the id \"" + shortText(id, 60) +
                                                      "\", which no run writes (ids are 1 to 64 letters, digits, '_', '-' or '.', starting with a letter or digit)");
        if (!entry.is_object()) throw InputError(file, at, "is not an object, as a run writes each algorithm's results");
        // Stage and counter names reach tables and plots too (twelfth probe: a 200,000-character
        // stage name was written whole into compare.md, .html and .json).
        for (const char* key : {"time_ms", "cpu_time_ms", "counters"})
            if (entry.contains(key) && entry[key].is_object())
                for (const auto& [name, value] : entry[key].items())
                    if (!isMeasureName(name))
                        throw InputError(file, at + "/" + key, "holds the name \"" + shortText(name, 60) +
                                                                   "\", which no run writes (1 to 64 letters, digits, '_', '-' or '.', starting with a letter or digit)");
        for (const char* key : {"accuracy", "counters", "cpu_time_ms", "time_ms", "memory_bytes", "overflow", "preprocess_ms",
                                "resident_bytes", "statistics_pass", "total_ms_per_frame", "repetitions"})
            if (entry.contains(key)) checkNumbersOnly(entry[key], file, at + "/" + key);
        checkRunFieldShapes(entry, file, at);
        // Counts are what a run counts (ninth probe: an overflow of 1e30 read as 0, -1 as 2^64 - 1).
        for (const char* key : {"overflow", "memory_bytes", "resident_bytes"})
            if (entry.contains(key)) checkCount(entry[key], file, at + "/" + key);
        if (entry.contains("accuracy")) checkAccuracy(entry["accuracy"], file, at + "/accuracy");
        if (entry.contains("preprocess_ms")) checkTime(entry["preprocess_ms"], file, at + "/preprocess_ms");
        checkTimes(entry, file, at, s.value("frames", Json()));
    }
}
} // namespace

namespace {
/// The summary's resolution is the run's config's, when the folder holds it (twenty-second probe:
/// a summary saying 64 x 64 beside a 32 x 32 config gave sweep.csv four times the pixels).
void checkAgainstConfig(const Json& s, const std::string& dir, const std::string& file) {
    const std::string config = dir + "/config.resolved.json";
    std::error_code ec;
    if (!fs::is_regular_file(fs::symlink_status(config, ec))) return;
    Json c;
    try {
        c = Json::parse(readInputFile(config, size_t(16) << 20));
    } catch (const std::exception&) {
        return; // not a run's config: what is checked of the summary stands alone
    }
    if (c.is_object() && c.contains("resolution") && s.contains("resolution") && c["resolution"] != s["resolution"])
        throw InputError(file, "/resolution", "holds " + shortText(s["resolution"].dump(), 40) + " where the run's config.resolved.json says " +
                                                  shortText(c["resolution"].dump(), 40));
    // Results for exactly the ids the config gives, each of its algorithm (twenty-third probe: a
    // summary with no results compared as "No regression"; sweep merge held its runs to this).
    if (!c.is_object() || !c.contains("algorithms")) return; // not a run's resolved config, which lists them
    std::set<std::string> ids;
    collectIds(c, ids);
    for (const auto& [id, entry] : s["algorithms"].items()) {
        if (!ids.count(id))
            throw InputError(file, "/algorithms/" + id, "holds results under an id its config.resolved.json does not give");
        if (const std::string algorithm = algorithmOf(c, id); entry.value("algorithm", Json()) != Json(algorithm))
            throw InputError(file, "/algorithms/" + id + "/algorithm",
                             "names another algorithm than its config.resolved.json (" + shortText(algorithm, 60) + ")");
    }
    for (const std::string& id : ids)
        if (!s["algorithms"].contains(id))
            throw InputError(file, "/algorithms", "holds no results for \"" + shortText(id, 60) + "\", which its config.resolved.json runs");
}
} // namespace

void collectIds(const Json& resolved, std::set<std::string>& ids) {
    if (resolved.value("reference", Json(true)) != Json(false)) ids.insert("reference");
    if (resolved.contains("algorithms") && resolved["algorithms"].is_array())
        for (const Json& a : resolved["algorithms"])
            if (a.is_object() && a.contains("id") && a["id"].is_string()) ids.insert(a["id"].get<std::string>());
}

std::string algorithmOf(const Json& resolved, const std::string& id) {
    if (id == "reference") return resolved.value("reference", Json(true)) != Json(false) ? "reference" : "";
    if (resolved.contains("algorithms") && resolved["algorithms"].is_array())
        for (const Json& a : resolved["algorithms"])
            if (a.is_object() && a.value("id", Json()) == Json(id) && a.contains("algorithm") && a["algorithm"].is_string())
                return a["algorithm"].get<std::string>();
    return "";
}

Json readRunSummary(const std::string& dir) {
    const std::string file = dir + "/summary.json";
    std::error_code ec;
    if (!fs::is_directory(dir, ec) || !fs::exists(file, ec))
        throw InputError(shortText(dir, 300), "", "is not a run's output folder (it holds no summary.json)");
    // A killed run's leftover is not a run (twenty-third probe: the previous results, half
    // deleted, were counted by history as a complete run).
    if (OutputPlace::isRunTemporary(fs::path(dir).lexically_normal().filename().string()))
        throw InputError(shortText(dir, 300), "", "is a run's temporary folder (DIR.partial-PID, DIR.old-PID or DIR.kept-PID), not a run's output");
    // The run's own file, as sweep merge holds it (twenty-second probe: compare followed a link to
    // another run's summary).
    if (fs::is_symlink(fs::symlink_status(file, ec)))
        throw InputError(shortText(file, 300), "", "is a symbolic link, not the run's own file");
    const Json s = JsonNode::parseFile(file);
    // Compared as JSON, not read as a bool (twenty-fourth probe: "complete": "yes" stopped compare
    // with the JSON library's message, exit 1).
    if (!s.is_object() || !s.contains("complete") || s["complete"] != Json(true) || !s.contains("algorithms") ||
        !s["algorithms"].is_object())
        throw InputError(shortText(file, 300), "", "is not a complete run's summary (no \"complete\": true and \"algorithms\")");
    // What compare and history order and divide by is what a run writes (seventh probe: a
    // started_utc of "not-a-date" sorted as the newest run and decided history's exit code;
    // negative times were tabulated).
    if (s.contains("started_utc") && !isUtcTimestamp(s["started_utc"]))
        throw InputError(shortText(file, 300), "/started_utc", "is not a UTC time as a run writes it (YYYY-MM-DDTHH:MM:SSZ)");
    checkRunFieldTypes(s, shortText(file, 300)); // every time included (checkTimes)
    checkAgainstConfig(s, dir, shortText(file, 300));
    return s;
}

namespace {

std::vector<double> numbers(const Json& j) {
    std::vector<double> v;
    if (j.is_array())
        for (const Json& x : j)
            if (x.is_number()) v.push_back(x.get<double>());
    return v;
}

size_t repetitionCount(const Json& a) { return a.contains("repetitions") ? a["repetitions"].value("count", size_t(1)) : 1; }

/// `x` divided element by element by `by` (the yardstick's samples of the same passes or frames);
/// empty when they do not pair up.
std::vector<double> over(const std::vector<double>& x, const std::vector<double>& by) {
    if (by.empty()) return x;
    std::vector<double> out;
    if (x.size() != by.size()) return out;
    for (size_t k = 0; k < x.size(); ++k)
        if (by[k] > 0) out.push_back(x[k] / by[k]);
    return out;
}

/// One stage's time, BASE → NEW: the ratio of the medians with its interval, from the passes'
/// means when both ran 3 or more (independent samples, U test too), else from the first pass's
/// frames paired one to one (the same views), else the ratio of the means without an interval.
/// With a yardstick (`--relative-to`), each pass's (or frame's) time is first divided by the
/// yardstick's total of the same pass in the same run: a machine that got slower between the
/// two runs slows both, and the quotient keeps only what changed in the algorithm.
Json compareStage(const Json& a, const Json& b, const std::string& stage, double threshold, const Json* ya, const Json* yb) {
    Json r = {{"stage", stage}};
    Interval ci;
    std::string method;
    auto passes = [&](const Json& e, const std::string& s) { return numbers(e["repetitions"]["time_ms"].value(s, Json())); };
    if (repetitionCount(a) >= 3 && repetitionCount(b) >= 3) {
        const auto x = over(passes(a, stage), ya ? passes(*ya, "total") : std::vector<double>{});
        const auto y = over(passes(b, stage), yb ? passes(*yb, "total") : std::vector<double>{});
        ci = bootstrapRatioOfMedians(x, y);
        r["base"] = medianOf(x);
        r["new"] = medianOf(y);
        r["p"] = mannWhitneyP(x, y);
        method = "repetitions";
    } else if (stage == "total" && a.contains("total_ms_per_frame") && b.contains("total_ms_per_frame") &&
               a["total_ms_per_frame"].size() == b["total_ms_per_frame"].size() && a["total_ms_per_frame"].size() >= 3) {
        const auto x = over(numbers(a["total_ms_per_frame"]), ya ? numbers((*ya)["total_ms_per_frame"]) : std::vector<double>{});
        const auto y = over(numbers(b["total_ms_per_frame"]), yb ? numbers((*yb)["total_ms_per_frame"]) : std::vector<double>{});
        std::vector<double> ratios;
        for (size_t k = 0; k < std::min(x.size(), y.size()); ++k)
            if (x[k] > 0) ratios.push_back(y[k] / x[k]);
        ci = bootstrapMedian(ratios);
        r["base"] = medianOf(x);
        r["new"] = medianOf(y);
        method = "frames paired";
    } else {
        auto mean = [&](const Json& e, const std::string& s) { return e["time_ms"].contains(s) ? e["time_ms"][s].value("mean", 0.0) : 0.0; };
        const double x = mean(a, stage) / (ya ? std::max(mean(*ya, "total"), 1e-300) : 1.0);
        const double y = mean(b, stage) / (yb ? std::max(mean(*yb, "total"), 1e-300) : 1.0);
        r["base"] = x;
        r["new"] = y;
        ci.median = x > 0 ? y / x : 0;
        method = "means only";
    }
    if (ya) method += ", over the yardstick";
    // New over a base of 0 is no number (fifteenth probe: it was written 0, an infinite speed-up).
    const bool defined = r["base"].get<double>() > 0 || r["new"].get<double>() == 0;
    if (r["base"].get<double>() == 0 && r["new"].get<double>() == 0) ci.median = 1;
    r["ratio"] = defined && std::isfinite(ci.median) ? Json(ci.median) : Json();
    r["low"] = ci.valid ? Json(ci.low) : Json();
    r["high"] = ci.valid ? Json(ci.high) : Json();
    r["method"] = method;
    // Frames paired or means only say nothing about how two runs of one build differ (false calls
    // in results/reference/compare_noise_llvmpipe.md), so they get no verdict.
    r["verdict"] = r.contains("p") ? timeVerdict(ci, r["p"].get<double>(), threshold) : ci.valid ? "too few passes" : "no interval";
    if (r["ratio"].is_null()) r["verdict"] = "no ratio (base time 0)";
    return r;
}

/// The first pass's stage names of `a`, "total" last (as summary.json's object sorts them).
std::vector<std::string> stagesOf(const Json& a, const Json& b) {
    std::vector<std::string> out;
    for (const auto& [stage, v] : a["time_ms"].items())
        if (stage != "total" && b["time_ms"].contains(stage)) out.push_back(stage);
    out.push_back("total");
    return out;
}

struct Picture {
    int width = 0, height = 0;
    std::vector<unsigned char> rgba;
};

/// Reads a run's saved image; "" when it was read, else why not (a run's images are at most the
/// largest resolution a config takes, so a larger one is not a run's and is not decoded).
std::string readPng(const std::string& path, Picture& p) {
    std::vector<unsigned char> bytes;
    try {
        bytes = readInputFileBytes(path, size_t(256) << 20);
    } catch (const InputError& e) {
        return e.cause();
    }
    int n = 0;
    if (!stbi_info_from_memory(bytes.data(), int(bytes.size()), &p.width, &p.height, &n)) return "not an image stb can read";
    if (p.width > configlimits::kResolutionMax || p.height > configlimits::kResolutionMax)
        return std::to_string(p.width) + "×" + std::to_string(p.height) + " pixels, larger than any run's image";
    unsigned char* data = stbi_load_from_memory(bytes.data(), int(bytes.size()), &p.width, &p.height, &n, 4);
    if (!data) return std::string("cannot be decoded: ") + stbi_failure_reason();
    p.rgba.assign(data, data + size_t(p.width) * size_t(p.height) * 4);
    stbi_image_free(data);
    return "";
}

/// Compares one saved image of both runs: the pixels that differ, and a picture of them (changed
/// pixels red over the new image in grey) written to `imagesDir` as `picture`.
Json compareImagePair(const std::string& baseDir, const std::string& newDir, const std::string& name, int frame,
                      const std::string& kind, const std::string& imagesDir, const std::string& picture) {
    Json rec = {{"frame", frame}, {"image", kind}};
    auto notCompared = [&](const std::string& why) {
        rec["changed_pixels"] = Json();
        rec["note"] = why;
        return rec;
    };
    Picture a, b;
    if (const std::string why = readPng(baseDir + "/images/" + name, a); !why.empty()) return notCompared("BASE's image " + name + ": " + why);
    if (const std::string why = readPng(newDir + "/images/" + name, b); !why.empty()) return notCompared("NEW's image " + name + ": " + why);
    if (a.width != b.width || a.height != b.height)
        return notCompared("the images " + name + " differ in size (" + std::to_string(a.width) + "×" + std::to_string(a.height) + " → " +
                           std::to_string(b.width) + "×" + std::to_string(b.height) + ")");
    size_t changed = 0;
    std::vector<unsigned char> pixels(b.rgba.size());
    for (size_t i = 0; i < b.rgba.size(); i += 4) {
        const bool differs = !std::equal(a.rgba.begin() + long(i), a.rgba.begin() + long(i) + 3, b.rgba.begin() + long(i));
        changed += differs ? 1 : 0;
        const unsigned char grey = static_cast<unsigned char>(b.rgba[i] / 3 + 60);
        pixels[i] = differs ? 255 : grey;
        pixels[i + 1] = differs ? 0 : grey;
        pixels[i + 2] = differs ? 0 : grey;
        pixels[i + 3] = 255;
    }
    rec["changed_pixels"] = changed;
    rec["pixels"] = size_t(b.width) * size_t(b.height);
    if (changed > 0 && !imagesDir.empty() &&
        stbi_write_png((imagesDir + "/" + picture).c_str(), b.width, b.height, 4, pixels.data(), b.width * 4))
        rec["picture"] = "images/" + picture;
    return rec;
}

/// Every image a run saves of `id` a frame (writeFrameImages: visibility, shaded, and the difference
/// to the reference when it ran; writeHeatMaps: heat_NAME), compared between both runs frame by
/// frame. An image either run saved is compared or named with why not (saved by one run only,
/// unreadable, another size): the visibility image alone used to be read, and a shaded, difference
/// or heat-map image that was lost or changed went unreported (probes 25 and 26).
Json compareImages(const std::string& baseDir, const std::string& newDir, const std::string& id, const std::string& imagesDir) {
    Json out = Json::array();
    const std::string prefix = id + "_f";
    // A heat map's name is an identifier (a debug view's): a file name of other text in a run's
    // folder is no image of ours, and never reaches the report or a picture's name.
    auto isKind = [](const std::string& kind) {
        const size_t p = std::strlen(kHeatMapPrefix);
        return std::find(kFrameImageKinds.begin(), kFrameImageKinds.end(), kind) != kFrameImageKinds.end() ||
               (kind.starts_with(kHeatMapPrefix) && kind.size() > p && kind.size() <= p + 64 &&
                std::all_of(kind.begin() + long(p), kind.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }));
    };
    std::error_code ec;
    std::set<std::pair<int, std::string>> saved; // (frame, kind)
    for (const std::string& dir : {baseDir, newDir})
        for (const auto& e : fs::directory_iterator(dir + "/images", ec)) {
            const std::string n = e.path().filename().string();
            if (!n.starts_with(prefix) || n.size() < prefix.size() + 5 || n[prefix.size() + 4] != '_' || !n.ends_with(".png") ||
                !std::all_of(n.begin() + long(prefix.size()), n.begin() + long(prefix.size() + 4), [](char c) { return c >= '0' && c <= '9'; }))
                continue;
            const std::string kind = n.substr(prefix.size() + 5, n.size() - prefix.size() - 5 - 4);
            if (isKind(kind)) saved.insert({std::stoi(n.substr(prefix.size(), 4)), kind});
        }
    for (const auto& [frame, kind] : saved) {
        const std::string tag = frameImagePrefix(id, frame);
        // The visibility picture keeps the name it always had; the others say which image they show.
        const std::string picture = tag + (kind == "visibility" ? std::string() : kind + "_") + "changed.png";
        out.push_back(compareImagePair(baseDir, newDir, tag + kind + ".png", frame, kind, imagesDir, picture));
    }
    return out;
}

} // namespace

std::vector<std::string> configDifferences(const std::string& baseDir, const std::string& newDir) {
    std::vector<std::string> keys;
    try {
        Json a = JsonNode::parseFile(baseDir + "/config.resolved.json"), b = JsonNode::parseFile(newDir + "/config.resolved.json");
        for (Json* j : {&a, &b})
            if (j->contains("output") && (*j)["output"].is_object()) (*j)["output"].erase("dir");
        std::set<std::string> all;
        for (const auto& [k, v] : a.items()) all.insert(k);
        for (const auto& [k, v] : b.items()) all.insert(k);
        for (const auto& k : all)
            if (a.value(k, Json()) != b.value(k, Json())) keys.push_back(k);
    } catch (const InputError&) {
        keys.push_back("(a config.resolved.json cannot be read)");
    }
    return keys;
}

std::string timeVerdict(const Interval& ci, double p, double threshold) {
    // A change counts when it exceeds the threshold, its whole interval lies on one side of 1 and
    // the U test finds the two samples different (p < 0.05: 5 or more each; no test, no change).
    const bool significant = p >= 0 && p < 0.05;
    if (!ci.valid) return "no interval";
    if (significant && ci.low > 1.0 && ci.median > 1.0 + threshold) return "slower";
    if (significant && ci.high < 1.0 && ci.median < 1.0 - threshold) return "faster";
    return "within noise";
}

std::vector<double> totalTimeSamples(const Json& entry, const Json* yardstick) {
    if (repetitionCount(entry) >= 3)
        return over(numbers(entry["repetitions"]["time_ms"].value("total", Json())),
                    yardstick ? numbers((*yardstick)["repetitions"]["time_ms"].value("total", Json())) : std::vector<double>{});
    return over(numbers(entry.value("total_ms_per_frame", Json())), yardstick ? numbers((*yardstick)["total_ms_per_frame"]) : std::vector<double>{});
}

/// The yardstick of `--relative-to`: an id's entry, or for "*" the machine's speed in each pass
/// (and frame) as the ids saw it: the median over the ids of each one's time over its scale (its
/// median total in `scales`, the same for both runs compared). A median, not a mean: one id whose
/// time swings between runs (the reference's CPU threads on a shared machine) or one that
/// regressed leaves it where the others put it; a geometric mean moves every other id with it
/// (results/reference/compare_noise_llvmpipe.md).
Json yardstickOf(const Json& summary, const std::string& id, const Json& scales) {
    if (id != "*") return summary["algorithms"][id];
    std::vector<std::vector<double>> passes, frames;
    std::vector<double> means;
    for (const auto& [name, e] : summary["algorithms"].items()) {
        if (!scales.contains(name) || !(scales[name].get<double>() > 0)) continue;
        const double scale = scales[name].get<double>();
        auto scaled = [&](std::vector<double> v) {
            for (double& x : v) x /= scale;
            return v;
        };
        passes.push_back(scaled(numbers(e.contains("repetitions") ? e["repetitions"]["time_ms"].value("total", Json()) : Json())));
        frames.push_back(scaled(numbers(e.value("total_ms_per_frame", Json()))));
        means.push_back((e["time_ms"].contains("total") ? e["time_ms"]["total"].value("mean", 0.0) : 0.0) / scale);
    }
    auto medianAcross = [](const std::vector<std::vector<double>>& rows) {
        std::vector<double> out;
        if (rows.empty()) return out;
        for (size_t k = 0; k < rows.front().size(); ++k) {
            std::vector<double> column;
            for (const auto& row : rows)
                if (k < row.size() && row[k] > 0) column.push_back(row[k]);
            out.push_back(column.empty() ? 0.0 : medianOf(column));
        }
        return out;
    };
    Json y;
    y["repetitions"] = {{"count", passes.empty() ? 1 : passes.front().size()}, {"time_ms", {{"total", medianAcross(passes)}}}};
    y["total_ms_per_frame"] = medianAcross(frames);
    y["time_ms"] = {{"total", {{"mean", means.empty() ? 0.0 : medianOf(means)}}}};
    return y;
}

Json yardstickScales(const Json& summary) {
    Json scales = Json::object();
    for (const auto& [name, e] : summary["algorithms"].items()) {
        const std::vector<double> s = totalTimeSamples(e, nullptr);
        if (!s.empty() && medianOf(s) > 0) scales[name] = medianOf(s);
    }
    return scales;
}

Comparison compareRuns(const std::string& baseDir, const std::string& newDir, const CompareOptions& opt) {
    const Json base = readRunSummary(baseDir), next = readRunSummary(newDir);
    Comparison c;
    if (!opt.relativeTo.empty() && opt.relativeTo != "*" &&
        !(base["algorithms"].contains(opt.relativeTo) && next["algorithms"].contains(opt.relativeTo)))
        throw InputError("--relative-to", "", "\"" + shortText(opt.relativeTo, 60) + "\" is not an algorithm id of both runs (or \"*\")");
    const Json scales = yardstickScales(base);
    const Json baseYardstick = opt.relativeTo.empty() ? Json() : yardstickOf(base, opt.relativeTo, scales);
    const Json newYardstick = opt.relativeTo.empty() ? Json() : yardstickOf(next, opt.relativeTo, scales);
    if (const auto keys = configDifferences(baseDir, newDir); !keys.empty()) {
        std::string list;
        for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
        c.notes.push_back("the two runs' configs differ in: " + shortText(list, 300) + " (a change may be the config's, not the code's)");
    }
    if (base.value("renderer", std::string()) != next.value("renderer", std::string()))
        c.notes.push_back("the runs ran on different renderers: " + shortText(base.value("renderer", std::string()), 100) + " and " +
                          shortText(next.value("renderer", std::string()), 100));
    std::set<std::string> ids;
    for (const auto& [id, v] : base["algorithms"].items()) ids.insert(id);
    for (const auto& [id, v] : next["algorithms"].items()) ids.insert(id);
    for (const std::string& id : ids) {
        Json r = {{"id", id}};
        const bool inBase = base["algorithms"].contains(id), inNew = next["algorithms"].contains(id);
        r["present"] = inBase && inNew ? "both" : inBase ? "base only" : "new only";
        r["regressions"] = Json::array();
        if (!(inBase && inNew)) {
            c.records.push_back(r);
            continue;
        }
        const Json& a = base["algorithms"][id];
        const Json& b = next["algorithms"][id];
        Json time = Json::array();
        const Json* ya = opt.relativeTo.empty() || id == opt.relativeTo ? nullptr : &baseYardstick;
        const Json* yb = opt.relativeTo.empty() || id == opt.relativeTo ? nullptr : &newYardstick;
        for (const std::string& stage : stagesOf(a, b)) time.push_back(compareStage(a, b, stage, opt.threshold, ya, yb));
        // The yardstick itself is compared as it is, but it measures the machine: never a regression.
        if (!opt.relativeTo.empty() && id == opt.relativeTo) time.back()["verdict"] = "the yardstick";
        r["time"] = time;
        if (time.back()["verdict"] == "slower")
            r["regressions"].push_back("total time " + shortNumber(time.back()["ratio"].get<double>(), 4) + "× (95 % interval " +
                                       shortNumber(time.back()["low"].get<double>(), 4) + " – " + shortNumber(time.back()["high"].get<double>(), 4) + ")");
        const Json accA = a.value("accuracy", Json()), accB = b.value("accuracy", Json());
        if (accA.is_object() && accB.is_object()) {
            const double x = accA.value("mismatch_ratio_max", 0.0), y = accB.value("mismatch_ratio_max", 0.0);
            // Accuracy is deterministic on one renderer: any growth past the threshold is the code's.
            const std::string verdict = y > x * (1 + opt.threshold) + 1e-12 ? "worse" : y < x * (1 - opt.threshold) - 1e-12 ? "better" : "same";
            r["accuracy"] = {{"base", x}, {"new", y}, {"verdict", verdict}};
            if (verdict == "worse") r["regressions"].push_back("worst-frame mismatch " + shortNumber(100 * x, 4) + " % → " + shortNumber(100 * y, 4) + " %");
        }
        const uint64_t ova = a.value("overflow", uint64_t(0)), ovb = b.value("overflow", uint64_t(0));
        r["overflow"] = {{"base", ova}, {"new", ovb}};
        if (ovb > ova) r["regressions"].push_back("overflow " + std::to_string(ova) + " → " + std::to_string(ovb));
        const double ma = a.value("memory_bytes", 0.0), mb = b.value("memory_bytes", 0.0);
        r["memory_bytes"] = {{"base", ma}, {"new", mb}, {"ratio", ma > 0 ? Json(mb / ma) : Json()}};
        Json counters = Json::object();
        if (a.contains("counters") && b.contains("counters"))
            for (const auto& [name, v] : a["counters"].items()) {
                if (!b["counters"].contains(name)) continue;
                const double x = v.value("mean", 0.0), y = b["counters"][name].value("mean", 0.0);
                if (std::fabs(y - x) > opt.threshold * std::max(std::fabs(x), 1e-12)) counters[name] = {{"base", x}, {"new", y}};
            }
        r["counters_changed"] = counters;
        r["images"] = compareImages(baseDir, newDir, id, opt.imagesDir);
        c.regressions += r["regressions"].size();
        c.records.push_back(r);
    }
    size_t fewest = SIZE_MAX;
    for (const auto& [id, v] : next["algorithms"].items()) fewest = std::min(fewest, repetitionCount(v));
    for (const auto& [id, v] : base["algorithms"].items()) fewest = std::min(fewest, repetitionCount(v));
    if (fewest < 3)
        c.notes.push_back("a run has fewer than 3 repetitions (config \"repeats\"): total times are compared frame by frame, the other "
                          "stages without an interval, and no time is called slower or faster; use \"repeats\": 9");
    else if (fewest < 5)
        c.notes.push_back("a run has fewer than 5 repetitions: the U test cannot find a difference (p < 0.05) in so few, so no time is "
                          "called slower or faster; use \"repeats\": 5 or more (9 is safer on a shared machine)");
    return c;
}

std::string comparisonMarkdown(const Comparison& c, const std::string& baseDir, const std::string& newDir, const CompareOptions& opt) {
    std::ostringstream os;
    os << "# Comparison\n\n- base: " << markdownLiteral(baseDir) << "\n- new: " << markdownLiteral(newDir) << "\n- threshold: "
       << shortNumber(100 * opt.threshold, 4) << " % (a time counts as slower or faster only past it, with its whole 95 % interval on one side of 1)\n";
    if (!opt.relativeTo.empty())
        os << "- times relative to " << markdownLiteral(opt.relativeTo)
           << "'s total of the same pass (base and new columns are quotients, not milliseconds)\n";
    for (const auto& n : c.notes) os << "- **note**: " << markdownLiteral(n) << "\n";
    os << "\n## " << (c.regressions ? std::to_string(c.regressions) + " regressions" : std::string("No regression")) << "\n\n";
    for (const Json& r : c.records)
        for (const Json& g : r["regressions"]) os << "- " << markdownLiteral(r["id"].get<std::string>()) << ": " << markdownLiteral(g.get<std::string>()) << "\n";
    os << "\n## Time per frame (ms), new over base\n\n| id | stage | base | new | ratio | 95 % interval | p (U test) | from | verdict |\n"
          "|---|---|---:|---:|---:|---|---:|---|---|\n";
    for (const Json& r : c.records) {
        if (r["present"] != "both") {
            os << "| " << markdownLiteral(r["id"].get<std::string>()) << " | | | | | | | | " << r["present"].get<std::string>() << " |\n";
            continue;
        }
        for (const Json& t : r["time"]) {
            os << "| " << markdownLiteral(r["id"].get<std::string>()) << " | " << markdownLiteral(t["stage"].get<std::string>()) << " | "
               << shortNumber(t["base"].get<double>(), 4) << " | " << shortNumber(t["new"].get<double>(), 4) << " | " << (t["ratio"].is_number() ? shortNumber(t["ratio"].get<double>(), 4) : std::string("undefined (base 0)")) << " | "
               << (t["low"].is_null() ? std::string() : shortNumber(t["low"].get<double>(), 4) + " – " + shortNumber(t["high"].get<double>(), 4)) << " | "
               << (t.contains("p") ? shortNumber(t["p"].get<double>(), 4) : std::string()) << " | " << t["method"].get<std::string>() << " | "
               << (t["verdict"] == "slower" ? "**slower**" : t["verdict"].get<std::string>()) << " |\n";
        }
    }
    os << "\n## Accuracy, overflow, memory\n\n| id | worst-frame mismatch base → new | verdict | overflow | memory (MiB) |\n|---|---|---|---|---|\n";
    for (const Json& r : c.records) {
        if (r["present"] != "both") continue;
        os << "| " << markdownLiteral(r["id"].get<std::string>()) << " | ";
        if (r.contains("accuracy"))
            os << shortNumber(100 * r["accuracy"]["base"].get<double>(), 4) << " % → " << shortNumber(100 * r["accuracy"]["new"].get<double>(), 4) << " % | "
               << (r["accuracy"]["verdict"] == "worse" ? "**worse**" : r["accuracy"]["verdict"].get<std::string>());
        else
            os << "not measured | ";
        os << " | " << r["overflow"]["base"] << " → " << r["overflow"]["new"] << " | " << shortNumber(r["memory_bytes"]["base"].get<double>() / 1048576.0, 4)
           << " → " << shortNumber(r["memory_bytes"]["new"].get<double>() / 1048576.0, 4) << " |\n";
    }
    os << "\n## Changed counters (mean past the threshold) and images\n\n";
    for (const Json& r : c.records) {
        if (r["present"] != "both") continue;
        for (const auto& [name, v] : r["counters_changed"].items())
            os << "- " << markdownLiteral(r["id"].get<std::string>()) << " " << markdownLiteral(name) << ": " << shortNumber(v["base"].get<double>(), 4)
               << " → " << shortNumber(v["new"].get<double>(), 4) << "\n";
        for (const Json& im : r["images"]) {
            if (im.contains("note")) {
                os << "- " << markdownLiteral(r["id"].get<std::string>()) << " frame " << im["frame"] << " "
                   << markdownLiteral(im["image"].get<std::string>()) << ": image not compared: "
                   << markdownLiteral(im["note"].get<std::string>()) << "\n";
                continue;
            }
            if (im["changed_pixels"].get<size_t>() == 0) continue;
            os << "- " << markdownLiteral(r["id"].get<std::string>()) << " frame " << im["frame"] << " "
               << markdownLiteral(im["image"].get<std::string>()) << ": "
               << im["changed_pixels"] << " of " << im["pixels"] << " pixels changed";
            if (im.contains("picture")) os << "\n\n  ![changed pixels](" << im["picture"].get<std::string>() << ")";
            os << "\n";
        }
    }
    return os.str();
}


std::string comparisonJUnit(const Comparison& c) {
    std::vector<JUnitCase> cases;
    for (const Json& r : c.records) {
        if (r["present"] != "both") continue;
        const std::string id = r["id"].get<std::string>();
        auto regression = [&](const std::string& start) {
            for (const Json& g : r["regressions"])
                if (g.get<std::string>().starts_with(start)) return g.get<std::string>();
            return std::string();
        };
        cases.push_back({id, "total time not slower", regression("total time")});
        if (r.contains("accuracy")) cases.push_back({id, "accuracy not worse", regression("worst-frame mismatch")});
        cases.push_back({id, "overflow not more", regression("overflow")});
    }
    return junitXml("shadowlab compare", cases, 0.0);
}

} // namespace shadowlab
