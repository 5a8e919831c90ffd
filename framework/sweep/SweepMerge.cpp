#include "framework/sweep/SweepMerge.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/Interrupt.h"
#include "framework/experiment/Compare.h"
#include "framework/sweep/SweepFile.h"
#include "framework/sweep/SweepRunner.h"
#include "framework/sweep/SweepText.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

/// A number as JSON writes it: the shortest text that reads back as the same double, so equal
/// results give equal rows wherever they were computed.
std::string number(const Json& v) { return v.is_null() ? std::string() : v.dump(); }

/// A summary.json that lacks what the table needs: the run is reported, not merged.
struct BadSummary {
    std::string path, cause;
};

/// summary.json's `key` of `parent` (at JSON path `where`), of the kind `want` says: "object",
/// "number" (or null: a measure not taken), "count" (a number, never null), "string".
const Json& field(const Json& parent, const std::string& key, const std::string& where, const char* want) {
    const std::string at = where + "/" + key;
    if (!parent.is_object() || !parent.contains(key)) throw BadSummary{at, "missing"};
    const Json& v = parent[key];
    const std::string w = want;
    const bool number = v.is_number() && std::isfinite(v.get<double>());
    const bool ok = w == "object" ? v.is_object() : w == "string" ? v.is_string() : w == "count" ? number : (v.is_null() || number);
    if (!ok) throw BadSummary{at, "expected " + w + ", got " + shortText(v.dump(), 40)};
    return v;
}

/// measure → value of one algorithm entry of summary.json. Times are means over the measured
/// frames; the spread stays in each run's own summary.json and frames.csv.
std::vector<std::pair<std::string, Json>> measures(const Json& a, const std::string& where) {
    std::vector<std::pair<std::string, Json>> m;
    for (const auto& [stage, t] : field(a, "time_ms", where, "object").items())
        m.emplace_back("time_ms." + stage, field(t, "mean", where + "/time_ms/" + stage, "number"));
    m.emplace_back("preprocess_ms", field(a, "preprocess_ms", where, "number"));
    if (a.contains("accuracy") && !a["accuracy"].is_null())
        for (const char* k : {"mismatch_ratio", "mismatch_ratio_max", "false_lit", "false_shadowed", "rmse"})
            m.emplace_back(std::string("accuracy.") + k, field(field(a, "accuracy", where, "object"), k, where + "/accuracy", "number"));
    for (const auto& [name, c] : field(a, "counters", where, "object").items())
        m.emplace_back("counters." + name, field(c, "mean", where + "/counters/" + name, "number"));
    m.emplace_back("memory_bytes", field(a, "memory_bytes", where, "count"));
    m.emplace_back("overflow", field(a, "overflow", where, "count"));
    return m;
}

/// What a measure depends on besides the run's config, so tables can be compared across machines
/// and reruns:
///   "accuracy"  accuracy.*: equal for equal configs on the same renderer;
///   "counter"   work counters, memory, overflow: equal too where an algorithm builds its structures
///               deterministically, but those built by racing threads change a little from run to
///               run even on one machine (the trees psv and metric_tree build on the GPU, whose
///               threads race for their place in them: node counts, triangle tests, a rare stack
///               overflow; the reference's Embree BVH, built in parallel: its memory at millions
///               of triangles);
///   "cache"     counters named cache*: whether a disk cache was warm;
///   "time"      stage times, preprocessing, and counters named *_ms, *_s, *_per_s.
const char* measureKind(const std::string& m) {
    auto ends = [&](const std::string& suffix) { return m.size() > suffix.size() && m.compare(m.size() - suffix.size(), suffix.size(), suffix) == 0; };
    if (m.rfind("time_ms.", 0) == 0 || m == "preprocess_ms" || ends("_ms") || ends("_s")) return "time";
    if (m.rfind("counters.cache", 0) == 0) return "cache";
    if (m.rfind("accuracy.", 0) == 0) return "accuracy";
    return "counter";
}

/// sweep.csv's rows of one complete run (BadSummary when its summary.json lacks what they need), its
/// ids and stage and counter names already held to the run's rules by readRunSummary().
std::string runRows(const Sweep& sweep, const SweepRun& run, const Json& s, std::set<std::string>& measured) {
    std::ostringstream prefix, rows;
    prefix << run.id << "," << run.index;
    for (size_t a = 0; a < sweep.axes.size(); ++a) prefix << "," << csvField(sweep.axes[a].labels[run.point[a]]);
    const Json& res = s.is_object() && s.contains("resolution") ? s["resolution"] : Json();
    if (!res.is_array() || res.size() != 2 || !res[0].is_number_unsigned() || !res[1].is_number_unsigned())
        throw BadSummary{"/resolution", "expected [width, height]"};
    const Json& triangles = field(s, "triangles", "", "count");
    if (!triangles.is_number_unsigned()) throw BadSummary{"/triangles", "expected a count"};
    prefix << "," << triangles.dump() << "," << res[0].get<uint64_t>() * res[1].get<uint64_t>();
    for (const auto& [id, a] : field(s, "algorithms", "", "object").items()) {
        const std::string where = "/algorithms/" + id;
        const std::string algorithm = field(a, "algorithm", where, "string").get<std::string>();
        for (const auto& [measure, value] : measures(a, where)) {
            measured.insert(measure);
            rows << prefix.str() << "," << csvField(id) << "," << csvField(algorithm) << "," << csvField(measure) << ","
                 << measureKind(measure) << "," << number(value) << "\n";
        }
    }
    return rows.str();
}

/// merge.stages and merge.counters name what the report's tables show: each must be something a
/// merged run measured, or its column would be empty (a misspelled stage, say). Checked against
/// the runs' results, since a stage exists only once an algorithm has run it.
void checkMergeMeasures(const Sweep& sweep, const std::string& snapshot, const std::set<std::string>& measured) {
    if (!sweep.merge.is_object()) return;
    for (const auto& [key, prefix] : {std::pair<std::string, std::string>{"stages", "time_ms."}, {"counters", "counters."}}) {
        if (!sweep.merge.contains(key)) continue;
        const Json& list = sweep.merge[key];
        for (size_t k = 0; k < list.size(); ++k) {
            const std::string name = list[k].get<std::string>();
            if (measured.count(prefix + name)) continue;
            std::string known;
            for (const std::string& m : measured)
                if (m.rfind(prefix, 0) == 0) known += (known.empty() ? "" : ", ") + m.substr(prefix.size());
            throw InputError(snapshot, "/merge/" + key + "/" + std::to_string(k),
                             "no merged run measured the " + std::string(key == "stages" ? "stage" : "counter") + " \"" +
                                 shortText(name, 60) + "\" (measured: " + shortText(known, 300) +
                                 "); sweep.csv is written, the report is not: correct merge." + key + " here and merge again");
        }
    }
}

/// The previous merge's report (sweep.md, sweep.html, sweep_*.png: scripts/sweep_report.py),
/// removed before this merge writes its tables: a merge whose report is then refused or fails
/// would otherwise leave that report beside tables it does not show (probe 26).
void removePreviousReport(const std::string& dir) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string n = e.path().filename().string();
        const bool report = n == "sweep.md" || n == "sweep.html" ||
                            (n.starts_with("sweep_") && n.ends_with(".png") &&
                             std::all_of(n.begin() + 6, n.end() - 4, [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }));
        // A link is left where it is, for the report's own refusal of it to name.
        if (report && fs::is_regular_file(e.symlink_status(ec))) fs::remove(e.path(), ec);
    }
}

} // namespace

MergeResult mergeSweep(const std::string& dir, bool plots) {
    if (dir.empty()) throw InputError("sweep merge", "", "the output folder must not be empty");
    const std::string snapshot = dir + "/sweep.json";
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(snapshot, ec)))
        throw InputError(shortText(snapshot, 300), "", "not found: is " + shortText(dir, 200) + " the output folder of `sweep run` or `sweep slurm`?");
    const Sweep sweep = loadSweep(snapshot);
    MergeResult r;
    r.runs = sweep.runs.size();

    std::ostringstream csv;
    csv << "run,index";
    for (const auto& axis : sweep.axes) csv << "," << axis.name;
    csv << ",triangles,pixels,id,algorithm,measure,kind,value\n";
    Json plan = planJson(sweep);
    std::set<std::string> measured;
    for (size_t i = 0; i < sweep.runs.size(); ++i) {
        const SweepRun& run = sweep.runs[i];
        RunPaths p(dir, run.id);
        Json& entry = plan["runs"][i];
        auto fail = [&](const std::string& status, const std::string& detail) {
            entry["status"] = status;
            if (status == "failed") {
                ++r.failed;
                entry["error"] = detail;
            }
            std::fprintf(stderr, "sweep merge: run %zu %s (%s): %s\n", run.index, run.id.c_str(), runLabel(sweep, run).c_str(),
                         shortText(detail, 400).c_str());
        };
        std::string why;
        if (!p.complete(&why)) {
            // A broken summary.json is a failed run (its folder is there, its results are not); an
            // error record beside no folder is one too.
            if (!why.empty()) fail("failed", "results unreadable: " + shortText(p.dir, 200) + ": " + why);
            else if (fs::exists(fs::symlink_status(p.error, ec))) fail("failed", "failed, see " + shortText(p.error, 300));
            else fail("missing", "no results yet");
            continue;
        }
        // complete() read it already; read again here (a run written meanwhile is read whole or not at all).
        Json s;
        std::string rows;
        try {
            // Held to what compare holds a run's summary to (fourteenth probe: a mismatch of 500 %,
            // an overflow of 1e300 and negative memory were merged and tabulated).
            s = readRunSummary(p.dir);
            rows = runRows(sweep, run, s, measured);
        } catch (const InputError& e) {
            fail("failed", shortText(p.dir, 200) + "/summary.json: " + (e.jsonPath().empty() ? "" : "at " + shortText(e.jsonPath(), 120) + ": ") +
                               e.cause());
            continue;
        } catch (const BadSummary& b) {
            fail("failed", shortText(p.dir, 200) + "/summary.json: at " + shortText(b.path, 120) + ": " + b.cause);
            continue;
        }
        // A complete run's error record is stale (an earlier attempt's): the run counts as complete.
        entry["status"] = "complete";
        for (const char* key : {"renderer", "stage_time_source"})
            entry[key] = s.contains(key) && s[key].is_string() ? s[key] : Json("");
        csv << rows;
        ++r.merged;
    }
    removePreviousReport(dir);
    writeFileAtomic(dir + "/plan.json", plan.dump(2, ' ', false, Json::error_handler_t::replace) + "\n");
    writeFileAtomic(dir + "/sweep.csv", csv.str());
    if (r.merged > 0) checkMergeMeasures(sweep, snapshot, measured);

    // An argv, never a shell command line: the folder's name is passed as it is, whatever it holds.
    const std::string script = std::string(SHADOWLAB_SOURCE_DIR) + "/scripts/sweep_report.py";
    const std::string log = dir + "/sweep_report.log";
    std::vector<std::string> argv = {SHADOWLAB_PLOT_PYTHON, script, absoluteFolder(dir)};
    if (!plots) argv.push_back("--no-plots");
    writeFileAtomic(log, ""); // runChildProcess appends: this merge's output only
    const int rc = runChildProcess(argv, log);
    r.reportWritten = rc == 0;
    if (!r.reportWritten) {
        std::string tail;
        try {
            tail = readInputFile(log, size_t(1) << 20);
        } catch (const InputError&) {
        }
        while (!tail.empty() && tail.back() == '\n') tail.pop_back();
        const size_t nl = tail.find_last_of('\n');
        const std::string last = shortText(nl == std::string::npos ? tail : tail.substr(nl + 1), 300);
        // Exit 2 is the scripts' refusal of a path that is not a regular file (scripts/safe_files.py):
        // bad input, said once, as the same refusal of sweep.csv is (twenty-first probe: exit 1 and
        // two lines for sweep.md, exit 2 and one for sweep.csv).
        if (rc == 2) throw InputError(shortText(dir, 300), "", "the report was refused: " + last + "; sweep.csv is complete");
        // A full disk is a failed write with a reason, not an empty one (the script may have had no
        // room to say anything).
        if (diskNearlyFull(dir))
            throw RuntimeError("the disk holding " + shortText(dir, 300) + " is full: the report could not be written; sweep.csv is complete");
        std::fprintf(stderr, "sweep merge: the report script failed (%s): %s; sweep.csv is complete (log: %s)\n",
                     rc < 0 ? "it could not start, or died of a signal" : ("exit code " + std::to_string(rc)).c_str(),
                     last.empty() ? "it printed nothing" : last.c_str(), shortText(log, 300).c_str());
    }
    return r;
}

} // namespace shadowlab
