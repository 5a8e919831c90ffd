#include "framework/experiment/History.h"

#include "framework/core/Error.h"
#include "framework/core/JsonNode.h"
#include "framework/core/Text.h"
#include "framework/experiment/Compare.h"
#include "framework/experiment/OutputPlace.h"
#include "framework/metrics/Noise.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

/// More run folders than any CI keeps in one place; past it the folder is refused, not half-read.
constexpr size_t kMaxRuns = 10000;

struct RunRecord {
    std::string folder;
    Json summary;
};

/// A run's own folder whose summary.json says the run finished ("complete": true) or cannot be
/// read at all: a run writes it whole, then puts the folder in place (OutputPlace), so neither is
/// a run in progress or a folder of something else.
bool claimsToBeAFinishedRun(const fs::path& dir) {
    std::error_code ec;
    const fs::path file = dir / "summary.json";
    if (!fs::is_regular_file(fs::symlink_status(file, ec)) || OutputPlace::isRunTemporary(dir.filename().string())) return false;
    try {
        const Json s = JsonNode::parseFile(file.string());
        return !s.is_object() || s.value("complete", Json()) == Json(true);
    } catch (const InputError&) {
        return true;
    }
}

std::vector<RunRecord> readRuns(const std::string& dir, History& h) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw InputError(shortText(dir, 300), "", "is not a folder of run folders");
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        if (names.size() >= kMaxRuns) throw InputError(shortText(dir, 300), "", "holds more than " + std::to_string(kMaxRuns) + " entries");
        names.push_back(e.path().filename().string());
    }
    if (ec) throw InputError(shortText(dir, 300), "", "cannot be listed: " + ec.message());
    std::sort(names.begin(), names.end());
    std::vector<RunRecord> runs;
    std::vector<std::string> skipped;
    for (const std::string& name : names) {
        const fs::path p = fs::path(dir) / name;
        // A link would count a run twice (a "latest" link beside the run it names).
        if (fs::is_symlink(p, ec) || !fs::is_directory(p, ec)) {
            skipped.push_back(name);
            continue;
        }
        try {
            runs.push_back({name, readRunSummary(p.string())});
        } catch (const InputError&) {
            // A finished run whose summary is damaged is refused, as compare refuses it (probe 26:
            // left out, it let the run before it stand for the newest, and a regression pass).
            if (claimsToBeAFinishedRun(p)) throw;
            skipped.push_back(name);
        }
    }
    if (!skipped.empty()) {
        std::string list;
        for (size_t k = 0; k < skipped.size() && k < 5; ++k) list += (k ? ", " : "") + shortText(skipped[k], 60);
        if (skipped.size() > 5) list += ", ...";
        h.notes.push_back(std::to_string(skipped.size()) + " entries are not complete run folders and were left out: " + list);
    }
    if (runs.size() < 2)
        throw InputError(shortText(dir, 300), "", "holds " + std::to_string(runs.size()) +
                                                      " complete run folders (each with a summary.json); a history needs 2 or more");
    return runs;
}

void orderRuns(std::vector<RunRecord>& runs, const HistoryOptions& opt, History& h) {
    const bool dated = std::all_of(runs.begin(), runs.end(), [](const RunRecord& r) { return r.summary.contains("started_utc") && r.summary["started_utc"].is_string(); });
    if (opt.byName) return; // already sorted by name
    if (!dated) {
        h.notes.push_back("some runs do not say when they started (made before summary.json had started_utc): ordered by folder name");
        return;
    }
    std::stable_sort(runs.begin(), runs.end(), [](const RunRecord& a, const RunRecord& b) {
        return a.summary["started_utc"].get<std::string>() < b.summary["started_utc"].get<std::string>();
    });
}

Json runRecord(const RunRecord& r) {
    const Json build = r.summary.value("build", Json::object());
    const std::string commit = build.is_object() ? build.value("commit", std::string("unknown")) : "unknown";
    const bool dirty = build.is_object() && build.value("dirty", false);
    const bool known = commit.size() >= 7 && commit.size() <= 64 && commit.find_first_not_of("0123456789abcdef") == std::string::npos;
    return {{"folder", validUtf8(r.folder)},
            // A commit is hex; anything else is no build's (thirteenth probe: 100,000 characters and a
            // bidi override were written whole into history.json).
            {"commit", known ? commit : std::string("unknown")},
            {"dirty", dirty},
            // The commit names a run when the build knew it; a folder name otherwise.
            {"label", known ? commit.substr(0, 10) + (dirty ? "+" : "") : shortText(r.folder, 40)},
            {"started_utc", validUtf8(r.summary.value("started_utc", std::string()))},
            {"renderer", shortText(r.summary.value("renderer", std::string()), 100)}};
}

double mismatchOf(const Json& entry) {
    const Json acc = entry.value("accuracy", Json());
    return acc.is_object() && acc.contains("mismatch_ratio_max") && acc["mismatch_ratio_max"].is_number() ? acc["mismatch_ratio_max"].get<double>() : NAN;
}

/// The L1 change point of `logMedians` over [a, b): the k in (a, b) whose two segments' absolute
/// deviations from their own medians sum least (a clean step minimises it exactly at the step).
size_t changePoint(const std::vector<double>& logMedians, size_t a, size_t b) {
    auto cost = [&](size_t from, size_t to) {
        std::vector<double> seg(logMedians.begin() + long(from), logMedians.begin() + long(to));
        const double m = medianOf(seg);
        double c = 0;
        for (double v : seg) c += std::fabs(v - m);
        return c;
    };
    size_t best = a + 1;
    double bestCost = INFINITY;
    for (size_t k = a + 1; k < b; ++k)
        if (const double c = cost(a, k) + cost(k, b); c < bestCost) bestCost = c, best = k;
    return best;
}

/// How many run-to-run standard deviations a step must be: with 9 ids judged at every commit, a
/// normal noise crosses 4 about once in 1,700 commits (3 would be once in 40).
constexpr double kStepSigmas = 4.0;

struct Boundary {
    double ratio = 1;          ///< the runs after over the runs before (medians)
    Interval ci;               ///< from the pooled passes (few runs), else not valid
    double p = -1;
    double bar = 0;            ///< the relative change a step must pass (runs' noise), 0 with few runs
    std::string verdict;
};

/// The runs' medians in [from, to), in log.
double medianLog(const std::vector<double>& logMedians, size_t from, size_t to) {
    return medianOf(std::vector<double>(logMedians.begin() + long(from), logMedians.begin() + long(to)));
}

/// The run-to-run noise of one id as a standard deviation in log: from consecutive runs' medians
/// (the median of their absolute differences, so that a few steps do not count as noise).
double runToRunSigma(const std::vector<double>& logMedians) {
    std::vector<double> diffs;
    for (size_t i = 1; i < logMedians.size(); ++i) diffs.push_back(std::fabs(logMedians[i] - logMedians[i - 1]));
    return std::max(1.4826 * medianOf(diffs) / std::sqrt(2.0), 1e-4);
}

/// The runs [j - window, j) against [j, j + window) of one id. With 4 or more runs the run is the
/// unit: a run's passes share its machine state (load, clocks, memory layout), so runs of one
/// build differ by more than their passes' spread says, and pooling passes across runs would call
/// that a step. The medians of the runs either side must then differ past the threshold and past
/// kStepSigmas of the id's run-to-run noise, with at least 2 runs before the boundary: one run is
/// no baseline (a first run's machine state alone can sit past the bar; HistoryTest
/// AFirstRunAloneIsNoBaseline). One run after must do, or the newest commit could never be
/// called; that run alone must be past the bar with its whole interval, not its median only: a
/// run whose own passes spread across the bar met load, not a slower build (HistoryTest
/// ANewestRunThatMetLoadIsNoStep). With 2 or 3 runs there is no noise to measure: the pooled
/// passes are judged by compare's rule.
Boundary judge(const std::vector<std::vector<double>>& samples, const std::vector<double>& logMedians, double sigma, size_t j,
               const HistoryOptions& opt) {
    const size_t from = j > opt.window ? j - opt.window : 0, to = std::min(samples.size(), j + opt.window);
    Boundary b;
    if (samples.size() >= 4) {
        if (j - from < 2) {
            b.verdict = "too few runs before";
            return b;
        }
        const double before = medianLog(logMedians, from, j);
        const double d = medianLog(logMedians, j, to) - before;
        b.ratio = std::exp(d);
        b.bar = std::exp(kStepSigmas * sigma * std::sqrt(1.0 / double(j - from) + 1.0 / double(to - j))) - 1;
        double nearest = d; // the after side's value nearest to the before side
        if (to - j == 1 && samples[j].size() >= 3) {
            const Interval own = bootstrapMedian(samples[j]);
            nearest = d > 0 ? std::min(d, std::log(own.low) - before) : std::max(d, std::log(own.high) - before);
        }
        const bool past = std::fabs(nearest) > std::log1p(b.bar) && d * nearest > 0;
        b.verdict = past && b.ratio > 1 + opt.threshold ? "slower" : past && b.ratio < 1 - opt.threshold ? "faster" : "within noise";
        return b;
    }
    std::vector<double> before, after;
    for (size_t i = from; i < j; ++i) before.insert(before.end(), samples[i].begin(), samples[i].end());
    for (size_t i = j; i < to; ++i) after.insert(after.end(), samples[i].begin(), samples[i].end());
    b.ci = bootstrapRatioOfMedians(before, after);
    b.ratio = b.ci.median;
    if (before.size() >= 4 && after.size() >= 4) b.p = mannWhitneyP(before, after);
    b.verdict = timeVerdict(b.ci, b.p, opt.threshold);
    return b;
}

/// One id's time steps: the boundaries judged a change, grouped where neighbours see the same
/// step, each group named at its change point.
void findTimeSteps(const std::string& id, const std::vector<size_t>& present, const std::vector<std::vector<double>>& samples,
                   const HistoryOptions& opt, History& h) {
    std::vector<double> logMedians;
    for (const auto& s : samples) logMedians.push_back(std::log(std::max(medianOf(s), 1e-300)));
    const double sigma = runToRunSigma(logMedians);
    std::vector<Boundary> bounds(samples.size());
    for (size_t j = 1; j < samples.size(); ++j) bounds[j] = judge(samples, logMedians, sigma, j, opt);
    for (size_t j = 1; j < samples.size();) {
        const std::string v = bounds[j].verdict;
        if (v != "slower" && v != "faster") {
            ++j;
            continue;
        }
        size_t end = j;
        while (end + 1 < samples.size() && bounds[end + 1].verdict == v) ++end;
        const size_t a = j > opt.window ? j - opt.window : 0, b = std::min(samples.size(), end + opt.window);
        size_t k = changePoint(logMedians, a, b);
        if (k < j || k > end) k = j; // the change point outside the group: its first boundary
        const Boundary& at = bounds[k];
        const size_t from = k > opt.window ? k - opt.window : 0, to = std::min(samples.size(), k + opt.window);
        Json step = {{"id", id}, {"measure", "time"}, {"run", present[k]}, {"label", h.runs[present[k]]["label"]}, {"direction", v},
                     {"ratio", at.ratio}, {"before", std::exp(medianLog(logMedians, from, k))}, {"after", std::exp(medianLog(logMedians, k, to))}};
        if (at.ci.valid) step.update({{"low", at.ci.low}, {"high", at.ci.high}, {"p", at.p < 0 ? Json() : Json(at.p)}});
        else step.update({{"run_to_run_noise", std::exp(sigma) - 1}, {"bar", at.bar}});
        h.steps.push_back(step);
        j = end + 1;
    }
}

void findAccuracySteps(const std::string& id, const Json& mismatch, const HistoryOptions& opt, History& h) {
    std::optional<size_t> last;
    for (size_t i = 0; i < mismatch.size(); ++i) {
        if (!mismatch[i].is_number()) continue;
        if (last) {
            const double x = mismatch[*last].get<double>(), y = mismatch[i].get<double>();
            const char* dir = y > x * (1 + opt.threshold) + 1e-12 ? "worse" : y < x * (1 - opt.threshold) - 1e-12 ? "better" : nullptr;
            if (dir)
                h.steps.push_back({{"id", id}, {"measure", "accuracy"}, {"run", i}, {"label", h.runs[i]["label"]}, {"direction", dir},
                                   {"before", x}, {"after", y}});
        }
        last = i;
    }
}

} // namespace

History readHistory(const std::string& dir, const HistoryOptions& opt) {
    History h;
    std::vector<RunRecord> runs = readRuns(dir, h);
    orderRuns(runs, opt, h);
    std::set<std::string> ids, renderers;
    for (const RunRecord& r : runs) {
        h.runs.push_back(runRecord(r));
        renderers.insert(r.summary.value("renderer", std::string()));
        for (const auto& [id, v] : r.summary["algorithms"].items()) ids.insert(id);
        if (!opt.relativeTo.empty() && opt.relativeTo != "*" && !r.summary["algorithms"].contains(opt.relativeTo))
            throw InputError("--relative-to", "", "\"" + shortText(opt.relativeTo, 60) + "\" is not an algorithm id of run " + shortText(r.folder, 100));
    }
    // The scales of "*": the oldest run's, the same for every run, so the yardstick is comparable.
    const Json scales = yardstickScales(runs.front().summary);
    if (renderers.size() > 1)
        h.notes.push_back("the runs ran on " + std::to_string(renderers.size()) + " different renderers: a step there may be the machine's");
    // A step where the config changed may be the config's, as compare says (fifteenth probe: a
    // newest run at another resolution was a REGRESSION with no word of it).
    // Runs without a readable config.resolved.json (made by hand, or older) are not compared.
    size_t changes = 0;
    for (size_t k = 1; k < runs.size(); ++k) {
        const auto keys = configDifferences((fs::path(dir) / runs[k - 1].folder).string(), (fs::path(dir) / runs[k].folder).string());
        if (keys.empty() || keys.front().starts_with("(")) continue;
        if (++changes > 3) continue;
        std::string list;
        for (const auto& key : keys) list += (list.empty() ? "" : ", ") + key;
        h.notes.push_back("the config changed between " + shortText(runs[k - 1].folder, 60) + " and " + shortText(runs[k].folder, 60) +
                          " in: " + shortText(list, 200) + " (a step there may be the config's, not the code's)");
    }
    if (changes > 3) h.notes.push_back("the config changed " + std::to_string(changes - 3) + " more times between consecutive runs");
    for (const std::string& id : ids) {
        Json time = Json::array(), mismatch = Json::array();
        std::vector<size_t> present;
        std::vector<std::vector<double>> samples;
        for (size_t i = 0; i < runs.size(); ++i) {
            const Json& algs = runs[i].summary["algorithms"];
            if (!algs.contains(id)) {
                time.push_back(nullptr);
                mismatch.push_back(nullptr);
                continue;
            }
            const Json yardstick = opt.relativeTo.empty() || id == opt.relativeTo ? Json() : yardstickOf(runs[i].summary, opt.relativeTo, scales);
            std::vector<double> s = totalTimeSamples(algs[id], yardstick.is_null() ? nullptr : &yardstick);
            const double m = mismatchOf(algs[id]);
            mismatch.push_back(std::isfinite(m) ? Json(m) : Json());
            if (s.empty()) {
                time.push_back(nullptr);
                continue;
            }
            const Interval ci = bootstrapMedian(s);
            time.push_back({{"median", medianOf(s)}, {"low", ci.valid ? Json(ci.low) : Json()}, {"high", ci.valid ? Json(ci.high) : Json()}});
            present.push_back(i);
            samples.push_back(std::move(s));
        }
        h.ids[id] = {{"time", time}, {"mismatch", mismatch}};
        // The yardstick measures the machine: its own steps are the machine's, never a regression.
        if (id != opt.relativeTo) findTimeSteps(id, present, samples, opt, h);
        findAccuracySteps(id, mismatch, opt, h);
    }
    std::stable_sort(h.steps.begin(), h.steps.end(), [](const Json& a, const Json& b) { return a["run"].get<size_t>() < b["run"].get<size_t>(); });
    h.newestRegressions = size_t(std::count_if(h.steps.begin(), h.steps.end(), [&](const Json& s) { return isNewestRegression(h, s); }));
    return h;
}

bool isNewestRegression(const History& h, const Json& s) {
    return s["run"].get<size_t>() + 1 == h.runs.size() && (s["direction"] == "slower" || s["direction"] == "worse");
}

namespace {

std::string interval(const Json& t) {
    if (t.is_null()) return "";
    std::string s = shortNumber(t["median"].get<double>(), 4);
    if (!t["low"].is_null()) s += " (" + shortNumber(t["low"].get<double>(), 4) + "–" + shortNumber(t["high"].get<double>(), 4) + ")";
    return s;
}

std::string stepChange(const Json& s) {
    if (s["measure"] == "accuracy")
        return "worst-frame mismatch " + shortNumber(100 * s["before"].get<double>(), 4) + " % → " + shortNumber(100 * s["after"].get<double>(), 4) + " %";
    std::string t = shortNumber(s["ratio"].get<double>(), 4) + "× (";
    if (s.contains("bar"))
        return t + "past " + shortNumber(100 * s["bar"].get<double>(), 3) + " %, " + shortNumber(kStepSigmas, 2) + "× the run-to-run noise of " +
               shortNumber(100 * s["run_to_run_noise"].get<double>(), 3) + " %)";
    t += "95 % interval " + shortNumber(s["low"].get<double>(), 4) + "–" + shortNumber(s["high"].get<double>(), 4);
    if (!s["p"].is_null()) t += ", p " + shortNumber(s["p"].get<double>(), 2);
    return t + ")";
}

} // namespace

std::string historyMarkdown(const History& h, const std::string& dir, const HistoryOptions& opt, bool withPlots) {
    std::ostringstream os;
    os << "# History of " << markdownLiteral(dir) << "\n\n- " << h.runs.size() << " runs, "
       << (opt.byName ? "ordered by folder name" : "oldest first") << "; a time step: the median of the " << opt.window
       << " runs after a boundary over that of the " << opt.window << " before, past " << shortNumber(100 * opt.threshold, 4) << " % and past "
       << shortNumber(kStepSigmas, 2) << "× the id's run-to-run noise, with 2 runs or more before it and a single run after it past with its whole interval (with fewer than 4 runs: compare's rule on the pooled passes)\n";
    if (!opt.relativeTo.empty())
        os << "- times relative to " << markdownLiteral(opt.relativeTo) << "'s total of the same pass (quotients, not milliseconds)\n";
    for (const auto& n : h.notes) os << "- **note**: " << markdownLiteral(n) << "\n";
    os << "\n## " << (h.steps.empty() ? std::string("No step") : std::to_string(h.steps.size()) + " steps") << "\n\n";
    for (const Json& s : h.steps) {
        const std::string dirn = s["direction"].get<std::string>();
        os << "- " << markdownLiteral(s["id"].get<std::string>()) << ": " << (dirn == "slower" || dirn == "worse" ? "**" + dirn + "**" : dirn)
           << " from run " << s["run"].get<size_t>() << " (" << markdownLiteral(s["label"].get<std::string>()) << ") on: " << markdownLiteral(stepChange(s)) << "\n";
    }
    os << "\n## Runs\n\n| # | commit | started (UTC) | folder |\n|---:|---|---|---|\n";
    for (size_t i = 0; i < h.runs.size(); ++i) {
        const Json& r = h.runs[i];
        os << "| " << i << " | " << markdownLiteral(r["label"].get<std::string>()) << " | " << markdownLiteral(r["started_utc"].get<std::string>())
           << " | " << markdownLiteral(shortText(r["folder"].get<std::string>(), 80)) << " |\n";
    }
    auto table = [&](const std::string& title, auto cell) {
        os << "\n## " << title << "\n\n| # |";
        for (const auto& [id, v] : h.ids.items()) os << " " << markdownLiteral(id) << " |";
        os << "\n|---:|";
        for (size_t k = 0; k < h.ids.size(); ++k) os << "---:|";
        os << "\n";
        for (size_t i = 0; i < h.runs.size(); ++i) {
            os << "| " << i << " |";
            for (const auto& [id, v] : h.ids.items()) os << " " << cell(v, i) << " |";
            os << "\n";
        }
    };
    table(opt.relativeTo.empty() ? "Total time per frame (ms): median (95 % interval)" : "Total time over the yardstick's: median (95 % interval)",
          [](const Json& v, size_t i) { return interval(v["time"][i]); });
    if (withPlots) os << "\n![total time per run](history_time.png)\n";
    table("Worst-frame mismatch (% of pixels)", [](const Json& v, size_t i) {
        return v["mismatch"][i].is_null() ? std::string() : shortNumber(100 * v["mismatch"][i].get<double>(), 4);
    });
    if (withPlots) os << "\n![worst-frame mismatch per run](history_accuracy.png)\n";
    return os.str();
}

Json historyJson(const History& h, const HistoryOptions& opt) {
    return {{"threshold", opt.threshold}, {"relative_to", opt.relativeTo}, {"window", opt.window}, {"notes", h.notes}, {"runs", h.runs},
            {"ids", h.ids}, {"steps", h.steps}, {"newest_regressions", h.newestRegressions}};
}

} // namespace shadowlab
