#include "framework/sweep/SweepMerge.h"

#include "framework/core/Error.h"
#include "framework/experiment/Results.h"
#include "framework/sweep/SweepFile.h"
#include "framework/sweep/SweepRunner.h"

#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

/// A number as JSON writes it: the shortest text that reads back as the same double, so equal
/// results give equal rows wherever they were computed.
std::string number(const Json& v) { return v.is_null() ? std::string() : v.dump(); }

/// measure → value of one algorithm entry of summary.json. Times are means over the measured
/// frames; the spread stays in each run's own summary.json and frames.csv.
std::vector<std::pair<std::string, Json>> measures(const Json& a) {
    std::vector<std::pair<std::string, Json>> m;
    for (const auto& [stage, t] : a.at("time_ms").items()) m.emplace_back("time_ms." + stage, t.at("mean"));
    m.emplace_back("preprocess_ms", a.at("preprocess_ms"));
    if (a.contains("accuracy") && a["accuracy"].is_object())
        for (const char* k : {"mismatch_ratio", "mismatch_ratio_max", "false_lit", "false_shadowed", "rmse"})
            m.emplace_back(std::string("accuracy.") + k, a["accuracy"].at(k));
    for (const auto& [name, c] : a.at("counters").items()) m.emplace_back("counters." + name, c.at("mean"));
    m.emplace_back("memory_bytes", a.at("memory_bytes"));
    m.emplace_back("overflow", a.at("overflow"));
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

} // namespace

MergeResult mergeSweep(const std::string& dir, bool plots) {
    const std::string snapshot = dir + "/sweep.json";
    if (!fs::exists(snapshot)) throw InputError(snapshot, "", "not found: is " + dir + " the output folder of `sweep run` or `sweep slurm`?");
    const Sweep sweep = loadSweep(snapshot);
    MergeResult r;
    r.runs = sweep.runs.size();

    std::ostringstream csv;
    csv << "run,index";
    for (const auto& axis : sweep.axes) csv << "," << axis.name;
    csv << ",triangles,pixels,id,algorithm,measure,kind,value\n";
    Json plan = planJson(sweep);
    for (size_t i = 0; i < sweep.runs.size(); ++i) {
        const SweepRun& run = sweep.runs[i];
        RunPaths p(dir, run.id);
        Json& entry = plan["runs"][i];
        if (!p.complete()) {
            const bool failed = fs::exists(p.error);
            r.failed += failed;
            entry["status"] = failed ? "failed" : "missing";
            std::fprintf(stderr, "sweep merge: run %zu %s (%s): %s\n", run.index, run.id.c_str(), runLabel(sweep, run).c_str(),
                         failed ? ("failed, see " + p.error).c_str() : "no results yet");
            continue;
        }
        entry["status"] = "complete";
        const Json s = JsonNode::parseFile(p.dir + "/summary.json");
        entry["renderer"] = s.value("renderer", "");
        entry["stage_time_source"] = s.value("stage_time_source", "");
        std::ostringstream prefix;
        prefix << run.id << "," << run.index;
        for (size_t a = 0; a < sweep.axes.size(); ++a) prefix << "," << csvField(sweep.axes[a].labels[run.point[a]]);
        const Json& res = s.at("resolution");
        prefix << "," << s.at("triangles").dump() << "," << res[0].get<long>() * res[1].get<long>();
        for (const auto& [id, a] : s.at("algorithms").items())
            for (const auto& [measure, value] : measures(a))
                csv << prefix.str() << "," << csvField(id) << "," << csvField(a.at("algorithm").get<std::string>()) << "," << measure
                    << "," << measureKind(measure) << "," << number(value) << "\n";
        ++r.merged;
    }
    writeFileAtomic(dir + "/plan.json", plan.dump(2) + "\n");
    writeFileAtomic(dir + "/sweep.csv", csv.str());

    const std::string script = std::string(SHADOWLAB_SOURCE_DIR) + "/scripts/sweep_report.py";
    const std::string cmd = std::string(SHADOWLAB_PLOT_PYTHON) + " '" + script + "' '" + dir + "'" + (plots ? "" : " --no-plots");
    r.reportWritten = std::system(cmd.c_str()) == 0;
    if (!r.reportWritten) std::fprintf(stderr, "sweep merge: the report script failed (%s); sweep.csv is complete\n", cmd.c_str());
    return r;
}

} // namespace shadowlab
