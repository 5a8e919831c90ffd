#include "framework/experiment/Results.h"

#include "framework/metrics/Noise.h"

#include "framework/core/Text.h"

#include "framework/core/Error.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

namespace shadowlab {

Stats computeStats(std::vector<double> v) {
    Stats s;
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    double sum = 0;
    for (double x : v) sum += x;
    s.mean = sum / double(v.size());
    s.min = v.front();
    s.max = v.back();
    s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    return s;
}

static std::string num(double v) {
    std::ostringstream os;
    os << std::setprecision(6) << v;
    return os.str();
}

namespace {

/// Every stage any frame ran, in the order they run ("total" last): stages that run only on some
/// frames (a refit when parts moved) count as taking 0 ms on the others, so each stage's statistics
/// are per frame, like the total they add up to.
std::vector<std::string> stageOrder(const std::vector<FrameRecord>& frames) {
    std::vector<std::string> order;
    for (const auto& f : frames)
        for (size_t i = 0; i < f.stages.size(); ++i) {
            const std::string& name = f.stages[i].name;
            if (std::find(order.begin(), order.end(), name) != order.end()) continue;
            // After the stage that ran before it in this frame, else first.
            auto at = order.begin();
            if (i > 0) {
                auto prev = std::find(order.begin(), order.end(), f.stages[i - 1].name);
                if (prev != order.end()) at = prev + 1;
            }
            order.insert(at, name);
        }
    return order;
}

} // namespace

void ExperimentResults::writeFramesCsv(const std::string& path, bool statisticsPass) const {
    auto framesOf = [&](const AlgorithmResults& a) -> const std::vector<FrameRecord>& { return statisticsPass ? a.statistics : a.frames; };
    std::set<std::string> counterNames;
    for (const auto& a : algorithms)
        for (const auto& f : framesOf(a))
            for (const auto& [k, v] : f.counters) counterNames.insert(k);
    std::ostringstream os;
    os << "id,algorithm,frame,stage,gpu_ms,cpu_ms,mismatch_ratio,false_lit,false_shadowed,rmse,overflow";
    for (const auto& c : counterNames) os << "," << c;
    os << "\n";
    for (const auto& a : algorithms)
        for (const auto& f : framesOf(a))
            for (const auto& s : f.stages) {
                os << a.id << "," << a.algorithm << "," << f.frame << "," << s.name << ","
                   << (s.gpuMs >= 0 ? num(s.gpuMs) : "") << "," << num(s.cpuMs);
                // Per-frame values (accuracy, overflow, counters) go on the "total" row only.
                bool total = s.name == "total";
                if (total && f.hasAccuracy)
                    os << "," << num(f.accuracy.mismatchRatio) << "," << num(f.accuracy.falseLit) << ","
                       << num(f.accuracy.falseShadowed) << "," << num(f.accuracy.rmse);
                else
                    os << ",,,,";
                os << "," << (total ? std::to_string(f.overflow) : "");
                for (const auto& c : counterNames) {
                    auto it = f.counters.find(c);
                    os << "," << (total && it != f.counters.end() ? num(it->second) : "");
                }
                os << "\n";
            }
    writeFileAtomic(path, os.str());
}

namespace {

/// time_ms and cpu_time_ms of a pass: GPU time where the stage has it (timer queries) and they can
/// be trusted (`gpuTimes`), else the stage's CPU/wall time; "total" is the wall-clock time of the
/// whole visibility computation, GPU finished.
std::pair<Json, Json> stageTimes(const std::vector<FrameRecord>& frames, bool gpuTimes) {
    const std::vector<std::string> order = stageOrder(frames);
    std::map<std::string, std::vector<double>> gpu, cpu;
    for (const auto& f : frames)
        for (const auto& name : order) {
            auto s = std::find_if(f.stages.begin(), f.stages.end(), [&](const StageTime& t) { return t.name == name; });
            if (s == f.stages.end()) {  // did not run this frame: it cost nothing
                cpu[name].push_back(0.0);
                if (gpu.count(name)) gpu[name].push_back(0.0);
                continue;
            }
            cpu[name].push_back(s->cpuMs);
            if (s->gpuMs >= 0) gpu[name].push_back(s->gpuMs);
        }
    Json time = Json::object(), cpuTime = Json::object();
    for (const auto& name : order) {
        bool useGpu = gpuTimes && name != "total" && gpu.count(name) && gpu[name].size() == cpu[name].size();
        time[name] = computeStats(useGpu ? gpu[name] : cpu[name]).toJson();
        cpuTime[name] = computeStats(cpu[name]).toJson();
    }
    return {time, cpuTime};
}

Json counterStats(const std::vector<FrameRecord>& frames) {
    std::map<std::string, std::vector<double>> counters;
    for (const auto& f : frames)
        for (const auto& [k, v] : f.counters) counters[k].push_back(v);
    Json cj = Json::object();
    for (const auto& [k, v] : counters) cj[k] = computeStats(v).toJson();
    return cj;
}

/// summary.json's device record in one line: the implementation, the subgroup width, the limits
/// that bound the algorithms' structures and the extensions the shaders use.
std::string deviceLine(const Json& d) {
    std::ostringstream os;
    const Json lim = d.value("limits", Json::object());
    auto limit = [&](const char* key) -> long long { return lim.contains(key) && lim[key].is_number() ? lim[key].get<long long>() : 0; };
    os << d.value("vendor", std::string()) << ", OpenGL " << d.value("version", std::string()) << ", GLSL "
       << d.value("glsl_version", std::string()) << "; subgroup width " << d.value("subgroup_size", 0) << "; storage block "
       << (limit("GL_MAX_SHADER_STORAGE_BLOCK_SIZE") >> 20) << " MiB, texture buffer " << limit("GL_MAX_TEXTURE_BUFFER_SIZE")
       << " texels, compute shared memory " << (limit("GL_MAX_COMPUTE_SHARED_MEMORY_SIZE") >> 10) << " KiB, "
       << limit("GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS") << " invocations per work group; extensions:";
    std::string missing;
    const Json extensions = d.value("extensions", Json::object());
    for (const auto& [name, present] : extensions.items()) {
        if (present.get<bool>()) os << " " << name;
        else missing += " " + name;
    }
    if (!missing.empty()) os << " (missing:" << missing << ")";
    return os.str();
}

} // namespace

namespace {
/// Each stage's mean time per frame in each repetition of the timed pass (the first included), and
/// from three repetitions on, the median of those means with its 95 % bootstrap interval: the noise
/// of this machine between repetitions, which is what a comparison of two runs must exceed.
void addRepetitions(Json& j, const AlgorithmResults& a, bool gpuTimes) {
    Json perRep = Json::object();
    auto add = [&](const std::vector<FrameRecord>& frames) {
        const Json t = stageTimes(frames, gpuTimes).first;
        for (const auto& [stage, stats] : t.items()) perRep[stage].push_back(stats["mean"]);
    };
    add(a.frames);
    for (const auto& rep : a.repetitions) add(rep);
    j["repetitions"] = {{"count", a.repetitions.size() + 1}, {"time_ms", perRep}};
    if (a.repetitions.size() + 1 < 3) return;
    Json intervals = Json::object();
    for (const auto& [stage, means] : perRep.items()) {
        const Interval ci = bootstrapMedian(means.get<std::vector<double>>());
        intervals[stage] = {{"median", ci.median}, {"low", ci.low}, {"high", ci.high}, {"level", ci.level}};
    }
    j["time_ms_interval"] = intervals;
}

/// "A/B": per repetition, A's mean total time per frame over B's (the two ran interleaved, under
/// the same load), then the median of those ratios and its 95 % bootstrap interval.
Json totalTimeRatios(const Json& algs) {
    Json ratios = Json::object();
    for (const auto& [a, ja] : algs.items())
        for (const auto& [b, jb] : algs.items()) {
            if (a == b || !ja.contains("repetitions") || !jb.contains("repetitions")) continue;
            const auto ta = ja["repetitions"]["time_ms"]["total"].get<std::vector<double>>();
            const auto tb = jb["repetitions"]["time_ms"]["total"].get<std::vector<double>>();
            std::vector<double> r;
            for (size_t k = 0; k < std::min(ta.size(), tb.size()); ++k)
                if (tb[k] > 0) r.push_back(ta[k] / tb[k]);
            const Interval ci = bootstrapMedian(r);
            ratios[a + "/" + b] = {{"median", ci.median}, {"low", ci.valid ? Json(ci.low) : Json()}, {"high", ci.valid ? Json(ci.high) : Json()}};
        }
    return ratios;
}
} // namespace

namespace {
/// A frame's first wrong pixel as {"frame", "x", "y"}: y counts rows up from the image's bottom
/// row, as GL reads them (images/ are written top row first: row height - 1 - y there).
Json wrongPixelJson(const FrameRecord& f, int width) {
    const int64_t i = f.accuracy.firstWrongPixel, w = std::max(1, width);
    return {{"frame", f.frame}, {"x", i % w}, {"y", i / w}};
}
} // namespace

std::string hexHash(uint64_t h) {
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return hex;
}

int ExperimentResults::imageWidth() const {
    const Json res = meta.value("resolution", Json());
    return res.is_array() && !res.empty() && res[0].is_number_integer() ? res[0].get<int>() : 1;
}

Json ExperimentResults::summary() const {
    Json out = meta;
    Json algs = Json::object();
    const bool gpuTimes = meta.value("stage_time_source", std::string("gpu")) == "gpu";
    for (const auto& a : algorithms) {
        std::vector<double> mismatch, falseLit, falseShadowed, rmse;
        Json wrongPixels = Json::array(); // one entry per frame: null where nothing was measured
        size_t falseLitPixels = 0, falseShadowedPixels = 0;
        Json firstWrong = nullptr;  // where a failure can be looked at (and the exactness fuzzer shrinks to)
        uint64_t overflow = 0;
        for (const auto& f : a.frames) {
            wrongPixels.push_back(f.hasAccuracy ? Json(f.accuracy.falseLitPixels + f.accuracy.falseShadowedPixels) : Json());
            if (f.hasAccuracy) {
                falseLitPixels += f.accuracy.falseLitPixels;
                falseShadowedPixels += f.accuracy.falseShadowedPixels;
                if (firstWrong.is_null() && f.accuracy.firstWrongPixel >= 0) firstWrong = wrongPixelJson(f, imageWidth());
                mismatch.push_back(f.accuracy.mismatchRatio);
                falseLit.push_back(f.accuracy.falseLit);
                falseShadowed.push_back(f.accuracy.falseShadowed);
                rmse.push_back(f.accuracy.rmse);
            }
            overflow += f.overflow;
        }
        Json j;
        j["algorithm"] = a.algorithm;
        j["params"] = a.params;
        j["preprocess_ms"] = a.preprocessMs;
        // Times, accuracy and overflow come from the timed pass, in which no statistics are gathered.
        std::vector<FrameRecord> timed = a.frames;  // every repetition's frames
        for (const auto& rep : a.repetitions) timed.insert(timed.end(), rep.begin(), rep.end());
        auto [time, cpuTime] = stageTimes(timed, gpuTimes);
        j["time_ms"] = time;
        j["cpu_time_ms"] = cpuTime;
        if (!a.repetitions.empty()) addRepetitions(j, a, gpuTimes);
        // Each frame's total of the first pass: `compare` pairs two runs' frames (the same views).
        Json perFrame = Json::array();
        for (const auto& f : a.frames)
            for (const auto& st : f.stages)
                if (st.name == "total") perFrame.push_back(st.cpuMs);
        j["total_ms_per_frame"] = perFrame;
        // Each frame's visibility image as a hash (hex): two runs that must give the same image
        // (a scene rewritten without changing what it is, docs/exactness_fuzzing.md) compare these.
        Json hashes = Json::array();
        for (const auto& f : a.frames) hashes.push_back(hexHash(f.visibilityHash));
        j["visibility_hash_per_frame"] = hashes;
        if (!mismatch.empty()) {
            Stats m = computeStats(mismatch);
            j["accuracy"] = {{"mismatch_ratio", m.mean},
                             {"frames_measured", mismatch.size()},
                             {"mismatch_ratio_max", m.max},
                             {"false_lit", computeStats(falseLit).mean},
                             {"false_shadowed", computeStats(falseShadowed).mean},
                             {"rmse", computeStats(rmse).mean},
                             {"per_frame_mismatch", mismatch},
                             {"false_lit_pixels", falseLitPixels},
                             {"false_shadowed_pixels", falseShadowedPixels},
                             {"per_frame_wrong_pixels", wrongPixels},
                             {"first_wrong_pixel", firstWrong}};
        } else {
            j["accuracy"] = nullptr;  // no reference, or no frame with a lit pixel to compare
        }
        // Counters: the statistics pass's where it ran (they need the instrumented shaders); else the
        // timed pass's, which hold only what stays measured there (overflow, errors, structure sizes).
        const bool fromStatistics = !a.statistics.empty();
        j["counters"] = counterStats(fromStatistics ? a.statistics : a.frames);
        j["counters_source"] = fromStatistics ? "statistics_pass" : "timed_pass";
        if (fromStatistics) {
            Json frames = Json::array();
            uint64_t statOverflow = 0;
            for (const auto& f : a.statistics) {
                frames.push_back(f.frame);
                statOverflow += f.overflow;
            }
            auto [statTime, statCpu] = stageTimes(a.statistics, gpuTimes);
            (void)statCpu;
            j["statistics_pass"] = {{"frames", frames},
                                    {"time_ms", statTime},
                                    {"overflow", statOverflow},
                                    {"visibility_differs_frames", a.visibilityDiffers}};
        }
        j["memory_bytes"] = a.memoryBytes;
        j["resident_bytes"] = a.residentBytes;
        j["overflow"] = overflow;
        Json resolved = Json::object();
        for (const auto& [k, v] : a.resolvedParams) resolved[k] = v;
        j["resolved_params"] = resolved;
        algs[a.id] = j;
    }
    out["algorithms"] = algs;
    if (!algorithms.empty() && algorithms.front().repetitions.size() >= 2) out["time_ratios"] = totalTimeRatios(algs);
    out["complete"] = true;
    return out;
}

namespace {
/// "## Memory": the peak resident set and each part's bytes, per triangle, beside the plan's estimate.
void writeMemorySection(std::ostream& os, const Json& s) {
    if (!s.contains("memory")) return;
    const Json& m = s["memory"];
    const double mib = 1024.0 * 1024.0, gib = mib * 1024.0;
    os << "\n## Memory\n\n" << std::fixed << std::setprecision(2) << "Peak resident memory of the run "
       << double(m["peak_rss_bytes"].get<size_t>()) / gib << " GiB (" << double(m["rss_after_setup_bytes"].get<size_t>()) / gib
       << " GiB once every algorithm had its scene), machine " << double(m["machine_bytes"].get<size_t>()) / gib
       << " GiB. A software renderer keeps GPU buffers in host memory, so every part below is resident.\n\n";
    const Json plan = m.value("plan", Json());
    if (!plan.is_null())
        os << "Estimated before the scene was made: peak " << double(plan["peak_bytes"].get<size_t>()) / gib << " GiB for up to "
           << plan["triangles"].get<size_t>() << " triangles, of " << double(plan["available_bytes"].get<size_t>()) / gib
           << " GiB available.\n\n";
    os << "| part | MiB | bytes per triangle | estimate (MiB) |\n|---|---:|---:|---:|\n";
    for (const auto& [name, v] : m["parts"].items()) {
        os << "| " << markdownLiteral(name) << " | " << double(v["bytes"].get<size_t>()) / mib << " | " << std::setprecision(1)
           << v["bytes_per_triangle"].get<double>() << std::setprecision(2) << " | ";
        if (!plan.is_null() && plan["held_bytes"].contains(name)) os << double(plan["held_bytes"][name].get<size_t>()) / mib;
        os << " |\n";
    }
    os.unsetf(std::ios::fixed);
}
} // namespace

namespace {
/// The config's expectations first in the report: what a CI job checks, and what failed.
void writeExpectationsSection(std::ostream& os, const Json& records) {
    size_t failed = 0;
    for (const Json& r : records) failed += r.value("passed", false) ? 0 : 1;
    os << "## Expectations: " << (failed ? std::to_string(failed) + " of " + std::to_string(records.size()) + " failed"
                                         : "all " + std::to_string(records.size()) + " met")
       << "\n\n| result | id | measure | bound | value | where | note |\n|---|---|---|---|---:|---|---|\n";
    auto num = [](const Json& v) { return v.is_null() ? std::string() : markdownLiteral(shortNumber(v.get<double>())); };
    for (const Json& r : records) {
        std::string bound;
        if (!r["min"].is_null()) bound += "≥ " + num(r["min"]);
        if (!r["max"].is_null()) bound += std::string(bound.empty() ? "" : ", ") + "≤ " + num(r["max"]);
        std::string measure = r["measure"].get<std::string>();
        if (!r["relative_to"].is_null()) measure += " / " + r["relative_to"].get<std::string>() + "'s";
        os << "| " << (r.value("passed", false) ? "met" : "**FAILED**") << " | " << markdownLiteral(r["id"].get<std::string>()) << " | "
           << markdownLiteral(measure) << " | " << bound << " | " << (r["value"].is_null() ? "not measured" : num(r["value"])) << " | "
           << markdownLiteral(r["where"].get<std::string>()) << " | " << markdownLiteral(r.value("note", std::string())) << " |\n";
    }
    os << "\n";
}
} // namespace

namespace {
/// With repetitions: each id's total time per frame, the median over repetitions and its interval,
/// and how far the repetitions spread (what a change must exceed to be more than noise here).
void writeRepetitionsSection(std::ostream& os, const Json& s) {
    const Json& algs = s["algorithms"];
    if (algs.empty() || !algs.begin()->contains("repetitions")) return;
    const size_t count = (*algs.begin())["repetitions"]["count"].get<size_t>();
    os << "\n## Total time per frame over " << count << " repetitions (ms; the algorithms' order rotated each time)\n\n"
       << "| id | median | 95 % interval | spread of the repetitions |\n|---|---:|---|---:|\n";
    for (const auto& [id, j] : algs.items()) {
        const std::vector<double> t = j["repetitions"]["time_ms"]["total"].get<std::vector<double>>();
        const auto [lo, hi] = std::minmax_element(t.begin(), t.end());
        const double median = medianOf(t);
        os << "| " << markdownLiteral(id) << " | " << std::setprecision(3) << median << " | ";
        if (j.contains("time_ms_interval")) os << j["time_ms_interval"]["total"]["low"].get<double>() << " – " << j["time_ms_interval"]["total"]["high"].get<double>();
        os << " | " << std::setprecision(1) << (median > 0 ? 100.0 * (*hi - *lo) / median : 0.0) << " % |\n";
    }
}
} // namespace

void ExperimentResults::writeReport(const std::string& path, const Json& s) const {
    std::ostringstream os;
    os << std::fixed;
    // Text from the config or the driver is written as literal text (markdownLiteral): a name can
    // never become a link, an image, a table cell or markup in report.md or report.html.
    os << "# " << markdownLiteral(s.value("name", std::string("experiment"))) << "\n\n";
    os << "- renderer: " << markdownLiteral(s.value("renderer", std::string())) << " (" << markdownLiteral(s.value("backend", std::string()))
       << ")\n";
    if (s.contains("device")) os << "- device: " << markdownLiteral(deviceLine(s["device"])) << "\n";
    os << "- resolution: " << s["resolution"][0] << "×" << s["resolution"][1] << ", frames: " << s["frames"]
       << ", triangles: " << s["triangles"] << "\n";
    os << "- wall time: " << std::setprecision(1) << s.value("wall_time_s", 0.0) << " s\n";
    if (s.contains("warnings"))
        for (const auto& w : s["warnings"]) os << "- **warning**: " << markdownLiteral(w.get<std::string>()) << "\n";
    os << "\n";

    if (s.contains("expectations")) writeExpectationsSection(os, s["expectations"]);

    if (std::any_of(algorithms.begin(), algorithms.end(), [](const AlgorithmResults& a) { return !a.resolvedParams.empty(); })) {
        os << "## Parameters resolved on this device\n\n"
              "What each parameter whose choice depends on the device (`auto`, or 0 for a rule) came to in this run.\n\n"
              "| id | algorithm | resolved |\n|---|---|---|\n";
        for (const auto& a : algorithms) {
            if (a.resolvedParams.empty()) continue;
            os << "| " << markdownLiteral(a.id) << " | " << a.algorithm << " | ";
            for (size_t i = 0; i < a.resolvedParams.size(); ++i)
                os << (i ? ", " : "") << a.resolvedParams[i].first << " = " << a.resolvedParams[i].second; // the plugin's words
            os << " |\n";
        }
        os << "\n";
    }

    if (s.value("stage_time_source", std::string("gpu")) == "gpu")
        os << "## Time per frame (ms; GPU timer queries where the stage runs on the GPU, CPU time otherwise)\n\n";
    else
        os << "## Time per frame (ms; wall clock of each stage run to completion: this renderer's timer queries are unreliable)\n\n";
    os << "Timed pass: every frame, statistics compiled out of the shaders (counters, heat maps and their atomics "
          "are gathered in a separate, untimed pass below).\n\n";
    os << "| id | algorithm | stage | mean | min | max | median |\n|---|---|---|---:|---:|---:|---:|\n";
    for (const auto& a : algorithms) {
        const Json& j = s["algorithms"][a.id];
        os << "| " << markdownLiteral(a.id) << " | " << a.algorithm << " | preprocess | " << std::setprecision(2) << j["preprocess_ms"].get<double>()
           << " | | | |\n";
        // Stages in the order the algorithm ran them (JSON objects sort their keys).
        for (const auto& stage : stageOrder(a.frames)) {
            const Json& st = j["time_ms"][stage];
            os << "| " << markdownLiteral(a.id) << " | " << a.algorithm << " | " << (stage == "total" ? "**total**" : markdownLiteral(stage)) << " | "
               << std::setprecision(3) << st["mean"].get<double>() << " | " << st["min"].get<double>() << " | "
               << st["max"].get<double>() << " | " << st["median"].get<double>() << " |\n";
        }
    }
    writeRepetitionsSection(os, s);
    os << "\n## Accuracy against the reference (over lit pixels, N·L > 0)\n\n";
    os << "| id | mismatch (mean) | mismatch (worst frame) | false lit | false shadowed | RMSE |\n|---|---:|---:|---:|---:|---:|\n";
    for (const auto& a : algorithms) {
        const Json& acc = s["algorithms"][a.id]["accuracy"];
        if (acc.is_null()) continue;
        os << "| " << markdownLiteral(a.id) << " | " << std::setprecision(4) << 100.0 * acc["mismatch_ratio"].get<double>() << " % | "
           << 100.0 * acc["mismatch_ratio_max"].get<double>() << " % | " << 100.0 * acc["false_lit"].get<double>() << " % | "
           << 100.0 * acc["false_shadowed"].get<double>() << " % | " << std::setprecision(5) << acc["rmse"].get<double>() << " |\n";
    }
    os << "\n## Memory and counters\n\n";
    const Json& statFrames = s.value("statistics_frames", Json::array());
    if (statFrames.empty())
        os << "No statistics pass (`statistics: none`): the counters are the timed pass's, which keep only what stays "
              "measured without statistics (overflow, errors, structure sizes).\n\n";
    else
        os << "Counters from the untimed statistics pass (instrumented shaders) over frame" << (statFrames.size() > 1 ? "s " : " ")
           << statFrames.dump() << "; *instrumented total* is that pass's mean frame time, shown only to tell what "
              "statistics cost. Memory and overflow from the timed pass.\n\n";
    os << "| id | memory (MiB) | overflow | timed total (ms) | instrumented total (ms) | counters (mean / max) |\n"
          "|---|---:|---:|---:|---:|---|\n";
    for (const auto& a : algorithms) {
        const Json& j = s["algorithms"][a.id];
        os << "| " << markdownLiteral(a.id) << " | " << std::setprecision(2) << double(j["memory_bytes"].get<size_t>()) / (1024.0 * 1024.0)
           << " | " << j["overflow"] << " | " << std::setprecision(3) << j["time_ms"]["total"]["mean"].get<double>() << " | ";
        if (j.contains("statistics_pass")) os << j["statistics_pass"]["time_ms"]["total"]["mean"].get<double>();
        os << " | ";
        bool first = true;
        for (const auto& [k, v] : j["counters"].items()) {
            os << (first ? "" : "; ") << markdownLiteral(k) << " " << std::setprecision(3) << v["mean"].get<double>() << " / " << v["max"].get<double>();
            first = false;
        }
        os << " |\n";
    }
    writeMemorySection(os, s);
    writeFileAtomic(path, os.str());
}

std::string summaryTable(const Json& s) {
    std::ostringstream os;
    char line[256];
    std::snprintf(line, sizeof line, "%-22s %12s %14s %12s %9s\n", "id", "frame (ms)", "preprocess", "mismatch", "overflow");
    os << line;
    for (const auto& [id, a] : s.at("algorithms").items()) {
        const Json& acc = a.at("accuracy");
        char mismatch[32] = "-";
        if (!acc.is_null()) std::snprintf(mismatch, sizeof mismatch, "%.4f %%", 100.0 * acc.at("mismatch_ratio_max").get<double>());
        // Ids are config text: cut so that one long id cannot push the table out of shape.
        const std::string shown = id.size() > 22 ? id.substr(0, 19) + "..." : id;
        std::snprintf(line, sizeof line, "%-22s %12.2f %11.1f ms %12s %9llu\n", shown.c_str(),
                      a.at("time_ms").at("total").at("mean").get<double>(), a.at("preprocess_ms").get<double>(), mismatch,
                      (unsigned long long)a.at("overflow").get<uint64_t>());
        os << line;
    }
    os << "frame: mean of the timed pass (statistics compiled out); mismatch: worst frame, of lit pixels\n";
    return os.str();
}

} // namespace shadowlab
