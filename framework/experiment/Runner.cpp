#include "framework/experiment/Runner.h"

#include "framework/algorithm/AlgorithmHost.h"
#include "framework/core/BuildInfo.h"
#include "framework/core/Error.h"
#include "framework/core/Interrupt.h"
#include "framework/core/SystemMemory.h"
#include "framework/core/Text.h"
#include "framework/experiment/OutputPlace.h"
#include "framework/experiment/Progress.h"
#include "framework/gl/DeviceInfo.h"
#include "framework/gl/GlContext.h"
#include "framework/gl/Shader.h"
#include "framework/experiment/FrameImages.h"
#include "framework/experiment/MemoryPlan.h"
#include "framework/render/ShadingPass.h"

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <map>
#include <filesystem>
#include <optional>
#include <sys/statvfs.h>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

struct Instance {
    const AlgorithmEntry* entry;
    std::unique_ptr<AlgorithmHost> host;
    AlgorithmResults results;
    std::map<int, uint64_t> timedVisibility; ///< frame → visibilityHash, on the statistics frames
    std::vector<uint64_t> firstImages;       ///< visibilityHash of each frame of the first timed pass, with repeats
};

/// A host for `entry` on the scene: instrumented for the statistics pass, else with statistics
/// compiled out (the timed pass).
std::unique_ptr<AlgorithmHost> makeHost(const AlgorithmEntry& e, bool instrumented, const SceneGpu& scene, glm::ivec2 res) {
    auto host = std::make_unique<AlgorithmHost>(*e.info, e.params, AlgorithmOptions{instrumented});
    host->resize(res);
    host->setScene(scene);
    return host;
}

/// The per-frame record of a measurement, as either pass keeps it.
FrameRecord recordOf(const FrameMeasurement& m, int frame) {
    FrameRecord rec;
    rec.frame = frame;
    rec.stages = m.stagesWithTotal();
    for (const auto& c : m.counters) rec.counters[c.name] = c.value;
    rec.overflow = m.overflow;
    return rec;
}

/// A fingerprint of a visibility image: the statistics pass must reproduce the timed pass's bits.
uint64_t visibilityHash(const std::vector<float>& vis) {
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the raw words
    for (float v : vis) {
        uint32_t w;
        std::memcpy(&w, &v, sizeof w);
        h = (h ^ w) * 1099511628211ull;
    }
    return h;
}

/// `timeSource` is summary.json's stage_time_source: which column of frames.csv the stage plot uses.
void runPlots(const std::string& dir, const std::string& finalDir, const std::string& timeSource) {
    // SHADOWLAB_PYTHON picks another interpreter (one with matplotlib) than the one found at build time.
    const char* python = std::getenv("SHADOWLAB_PYTHON");
    std::string script = std::string(SHADOWLAB_SOURCE_DIR) + "/scripts/plot_results.py";
    std::string log = dir + "/plots.log";
    const bool failed = runChildProcess({python && *python ? python : SHADOWLAB_PLOT_PYTHON, script, dir, timeSource}, log) != 0;
    if (!failed && std::filesystem::exists(dir + "/report.html")) {
        std::filesystem::remove(log);
        return;
    }
    // A full disk is a failed write, not a missing plot (seventh probe: the run exited 0 without
    // report.html): the run fails and the previous results stay.
    struct statvfs disk {};
    if (::statvfs(dir.c_str(), &disk) == 0 && uint64_t(disk.f_bavail) * uint64_t(disk.f_frsize) < (uint64_t(1) << 20))
        throw RuntimeError("the disk holding " + shortText(finalDir, 300) + " is full: the plots and report.html could not be written");
    const std::string see = std::filesystem::exists(log) ? " (see " + finalDir + "/plots.log)" : " (its log could not be written)";
    if (failed) std::fprintf(stderr, "warning: plotting failed%s; tables and images are complete\n", see.c_str());
    // An interpreter that exits 0 without doing the work (a wrong SHADOWLAB_PYTHON) is said too.
    else std::fprintf(stderr, "warning: the plotter exited 0 but wrote no report.html%s; tables and images are complete\n", see.c_str());
}

} // namespace

/// Memory as measured: the process's peak resident set, and bytes (and bytes per triangle) of the
/// scene on the host and the GPU and of everything each algorithm held; with the plan checked
/// before the scene was made, when there was one.
Json memoryRecord(const ExperimentConfig& cfg, const SceneGpu& sceneGpu, const ExperimentResults& results,
                  size_t rssAfterSetup, const Json& plan) {
    const double n = double(std::max<size_t>(1, cfg.scene->triangleCount()));
    Json parts = Json::object();
    auto part = [&](const std::string& name, size_t bytes) {
        parts[name] = {{"bytes", bytes}, {"bytes_per_triangle", double(bytes) / n}};
    };
    part("scene", cfg.scene->bytes());
    part("scene_gpu", sceneGpu.bytes());
    for (const auto& a : results.algorithms) part(a.id, a.residentBytes);
    const SystemMemory machine = systemMemory();
    Json m = {{"peak_rss_bytes", peakResidentBytes()},
              {"rss_after_setup_bytes", rssAfterSetup},
              {"machine_bytes", machine.total},
              {"parts", parts}};
    if (!plan.is_null()) m["plan"] = plan;
    return m;
}

ExperimentResults runExperiment(const ExperimentConfig& cfg, const RunOptions& opt, const std::string& backend) {
    auto wallStart = Clock::now();
    const std::string startedUtc = utcTimestamp();
    std::optional<OutputPlace> ownPlace;
    OutputPlace* place = opt.place;
    if (opt.writeOutputs && !place) {
        std::vector<std::string> notes;
        ownPlace.emplace(OutputPlace::open(opt.outputDir.empty() ? cfg.outputDir : opt.outputDir, opt.force, &notes));
        for (const auto& n : notes) std::fprintf(stderr, "shadowlab: %s\n", n.c_str());
        place = &*ownPlace;
    }
    const std::string dir = place ? place->partialDir() : std::string();
    const std::string finalDir = place ? place->finalDir() : std::string();
    // A GL error (an allocation that failed, a framebuffer left incomplete) means the images and
    // times that follow are not the algorithms': the run stops there and saves nothing (the
    // previous results kept), instead of committing a "complete" output a sweep would then merge.
    const int glErrorsAtStart = glErrorCount();
    const size_t glMessagesAtStart = glLastErrors().size();
    const auto stopIfBroken = [&] {
        throwIfInterrupted();
        if (glErrorCount() > glErrorsAtStart) {
            std::string first = glLastErrors();
            first = first.size() > glMessagesAtStart ? first.substr(glMessagesAtStart) : std::string("see the GL errors above");
            first = first.substr(0, first.find('\n'));
            throw RuntimeError(std::to_string(glErrorCount() - glErrorsAtStart) + " OpenGL error(s) during the run (" + shortText(first, 200) +
                               "): its results cannot be trusted, so none were saved");
        }
    };

    const glm::ivec2 res = cfg.resolution;
    SceneGpu sceneGpu(*cfg.scene);
    GBuffer gbuffer(res);
    ShadingPass shading(res);
    StageTimer timer;
    const bool softwareGl = isSoftwareRenderer(glRendererString());
    timer.setSynchronous(softwareGl);

    // The reference runs first each frame: every other algorithm is compared with its visibility.
    std::vector<const AlgorithmEntry*> entries;
    if (cfg.reference) entries.push_back(&cfg.referenceEntry);
    for (const auto& e : cfg.algorithms) entries.push_back(&e);

    // Algorithms precompute at the rest pose; the first frame's pose reaches them through sceneMoved().
    sceneGpu.setTime(cfg.sceneTimeAt(0));
    std::vector<Instance> instances;
    for (const AlgorithmEntry* e : entries) {
        std::unique_ptr<AlgorithmHost> host;
        try {
            host = makeHost(*e, false, sceneGpu, res);
        } catch (const SceneRefusal& refusal) {
            throw sceneRefusalError(cfg, *e, refusal.what());
        }
        Instance inst{e, std::move(host), {}, {}, {}};
        inst.results.id = e->id;
        inst.results.algorithm = e->info->name;
        inst.results.params = e->params.toJson();
        inst.results.preprocessMs = inst.host->preprocessMs();
        instances.push_back(std::move(inst));
    }
    const size_t rssAfterSetup = residentBytes();
    const std::vector<int> statFrames = cfg.statisticsFrames();
    auto isStatFrame = [&](int f) { return std::binary_search(statFrames.begin(), statFrames.end(), f); };
    auto isImageFrame = [&](int f) {
        return opt.writeOutputs && std::find(cfg.imagesAtFrames.begin(), cfg.imagesAtFrames.end(), f) != cfg.imagesAtFrames.end();
    };

    ExperimentResults results;
    results.meta = {{"name", cfg.name},
                    {"config", cfg.file},
                    {"renderer", glRendererString()},
                    {"gl_version", glVersionString()},
                    {"backend", backend},
                    // Where time_ms comes from (see isSoftwareRenderer()): "gpu" = timer queries,
                    // "wall" = the wall clock of each stage run synchronously.
                    {"stage_time_source", softwareGl ? "wall" : "gpu"},
                    {"subgroup_size", querySubgroupSize()},
                    // Implementation strings, limits and extensions (framework/gl/DeviceInfo.h).
                    {"device", deviceRecord(backend)},
                    {"resolution", {res.x, res.y}},
                    {"frames", cfg.frames},
                    {"warmup_frames", cfg.warmupFrames},
                    // The timed pass never carries statistics; counters and heat maps come
                    // from an untimed statistics pass over these frames (Results.h).
                    {"statistics", toString(cfg.statistics)},
                    {"statistics_frames", statFrames},
                    {"triangles", cfg.scene->triangleCount()},
                    {"moving_parts", cfg.scene->moving.size()},
                    {"moving_triangles", cfg.scene->movingTriangleCount()},
                    {"light", toString(cfg.light.type)},
                    {"reference", cfg.reference},
                    // Which sources and when: what `shadowlab history` orders and names runs by.
                    {"build", {{"commit", buildCommit()}, {"dirty", buildDirty()}}},
                    {"started_utc", startedUtc}};

    std::vector<int> framesWithoutLit;  // accuracy is measured over lit pixels: none, nothing to measure
    Json gbufferHashes = Json::array();
    Progress progress(opt.progress,
                      size_t(cfg.frames * cfg.repeats + int(statFrames.size()) + (cfg.warmupFrames > 0 ? 1 : 0)) * instances.size());
    std::optional<CpuGBuffer> cpuG;
    // The G-buffer and its CPU copy are every algorithm's shared input, made before any timer
    // starts, in every pass: read back lazily, the copy was paid for by whichever CPU algorithm
    // (the reference, line_space) a repetition's rotated order put first, a different one each
    // pass (results/reference/compare_noise_llvmpipe.md).
    auto renderFrame = [&](const Camera& cam) {
        gbuffer.render(sceneGpu, cam);
        glFinish();
        cpuG = gbuffer.readBack();
    };
    auto getCpuG = [&]() -> const CpuGBuffer& {
        if (!cpuG) cpuG = gbuffer.readBack();
        return *cpuG;
    };

    // One timed frame of one algorithm; posing the moving parts is shared work, done once per
    // frame, and its cost is reported in every algorithm's frame.
    auto timedFrame = [&](Instance& inst, const Camera& cam, const Light& light, int frame, const TimedWork& sceneUpdate) {
        FrameMeasurement m = inst.host->computeFrame({gbuffer, getCpuG, cam, light, frame}, timer);
        m.stages.insert(m.stages.begin(), sceneUpdate.stages.begin(), sceneUpdate.stages.end());
        m.wallMs += sceneUpdate.wallMs;
        return m;
    };

    // Warm-up: shader compilation, first-touch allocations and caches are kept out of the timings.
    if (cfg.warmupFrames > 0) {
        Camera cam = cfg.cameraAt(0);
        Light light = cfg.lightAt(0);
        renderFrame(cam);
        for (auto& inst : instances) {
            stopIfBroken();
            progress.step("warm-up " + inst.entry->id);
            for (int w = 0; w < cfg.warmupFrames; ++w) inst.host->computeFrame({gbuffer, getCpuG, cam, light, 0}, timer);
        }
    }

    for (int frame = 0; frame < cfg.frames; ++frame) {
        Camera cam = cfg.cameraAt(frame);
        Light light = cfg.lightAt(frame);
        // Posing the moving parts is shared work: done once, its cost reported in every algorithm's frame.
        const TimedWork sceneUpdate = sceneGpu.setTime(cfg.sceneTimeAt(frame), timer);
        if (sceneGpu.dynamic()) checkPoseBounds(cfg, frame, sceneGpu.bounds());
        renderFrame(cam);
        const CpuGBuffer& g = getCpuG();
        // What every algorithm of this frame starts from: runs whose images must agree (a scene
        // rewritten without changing it) compare images only where this agrees too.
        std::vector<float> gbufferWords(g.position);
        gbufferWords.insert(gbufferWords.end(), g.normal.begin(), g.normal.end());
        gbufferHashes.push_back(hexHash(visibilityHash(gbufferWords)));
        std::vector<uint8_t> lit = litMask(g, light);
        std::vector<uint8_t> covered = coveredMask(g);
        const bool saveImages = isImageFrame(frame);
        std::vector<float> reference;

        if (!std::any_of(lit.begin(), lit.end(), [](uint8_t v) { return v != 0; })) framesWithoutLit.push_back(frame);

        for (auto& inst : instances) {
            stopIfBroken();
            progress.step(inst.entry->id + " frame " + std::to_string(frame + 1) + "/" + std::to_string(cfg.frames));
            const FrameMeasurement m = timedFrame(inst, cam, light, frame, sceneUpdate);
            FrameRecord rec = recordOf(m, frame);
            inst.results.memoryBytes = std::max(inst.results.memoryBytes, m.memoryBytes);
            inst.results.residentBytes = std::max(inst.results.residentBytes, m.residentBytes);

            std::vector<float> vis = inst.host->readVisibility();
            bool isReference = cfg.reference && inst.entry == &cfg.referenceEntry;
            if (isReference) reference = vis;
            if (cfg.reference && (framesWithoutLit.empty() || framesWithoutLit.back() != frame)) {
                rec.hasAccuracy = true;
                rec.accuracy = compareVisibility(vis, reference, lit);
            }
            rec.visibilityHash = visibilityHash(vis);
            if (isStatFrame(frame)) inst.timedVisibility[frame] = rec.visibilityHash;
            if (cfg.repeats > 1) inst.firstImages.push_back(rec.visibilityHash);
            if (saveImages) {
                shading.run(gbuffer, inst.host->visibility(), light);
                writeFrameImages(dir, inst.entry->id, frame, res, shading, vis, cfg.reference && !isReference ? &reference : nullptr,
                                 lit, covered);
            }
            inst.results.frames.push_back(std::move(rec));
        }
    }

    // Repetitions of the timed pass: the same frames, the algorithms in a rotated order each time,
    // times and overflow recorded; each image is hashed against the first pass's (they must agree).
    for (int rep = 1; rep < cfg.repeats; ++rep) {
        for (auto& inst : instances) inst.results.repetitions.emplace_back();
        for (int frame = 0; frame < cfg.frames; ++frame) {
            Camera cam = cfg.cameraAt(frame);
            Light light = cfg.lightAt(frame);
            const TimedWork sceneUpdate = sceneGpu.setTime(cfg.sceneTimeAt(frame), timer);
            renderFrame(cam);
            for (size_t k = 0; k < instances.size(); ++k) {
                Instance& inst = instances[(k + size_t(rep)) % instances.size()];
                stopIfBroken();
                progress.step(inst.entry->id + " repetition " + std::to_string(rep + 1) + ", frame " + std::to_string(frame + 1));
                inst.results.repetitions.back().push_back(recordOf(timedFrame(inst, cam, light, frame, sceneUpdate), frame));
                if (visibilityHash(inst.host->readVisibility()) != inst.firstImages[size_t(frame)] &&
                    std::find(inst.results.repetitionDiffers.begin(), inst.results.repetitionDiffers.end(), frame) ==
                        inst.results.repetitionDiffers.end())
                    inst.results.repetitionDiffers.push_back(frame);
            }
        }
    }

    // What each algorithm's device-dependent choices came to, as the timed pass ran them.
    for (auto& inst : instances) inst.results.resolvedParams = inst.host->algorithm().resolvedParams();

    // The statistics pass: the same frames again with instrumented shaders, untimed as far as any
    // table goes. The timed hosts are released first, so the two passes never hold their GPU
    // structures at once.
    if (!statFrames.empty()) {
        for (auto& inst : instances) inst.host.reset();
        for (auto& inst : instances) inst.host = makeHost(*inst.entry, true, sceneGpu, res);
    }
    for (int frame : statFrames) {
        Camera cam = cfg.cameraAt(frame);
        Light light = cfg.lightAt(frame);
        sceneGpu.setTime(cfg.sceneTimeAt(frame));
        renderFrame(cam);
        // Warmed up like the timed pass, so its times (shown only as the cost of the statistics)
        // leave shader compilation out too.
        if (frame == statFrames.front())
            for (auto& inst : instances)
                for (int w = 0; w < cfg.warmupFrames; ++w) inst.host->computeFrame({gbuffer, getCpuG, cam, light, frame}, timer);
        const bool saveImages = isImageFrame(frame);
        for (auto& inst : instances) {
            stopIfBroken();
            progress.step(inst.entry->id + " statistics, frame " + std::to_string(frame + 1) + "/" + std::to_string(cfg.frames));
            FrameRecord rec = recordOf(inst.host->computeFrame({gbuffer, getCpuG, cam, light, frame}, timer), frame);
            if (visibilityHash(inst.host->readVisibility()) != inst.timedVisibility[frame]) inst.results.visibilityDiffers.push_back(frame);
            if (saveImages) writeHeatMaps(dir, inst.entry->id, frame, res, inst.host->algorithm().debugViews());
            inst.results.statistics.push_back(std::move(rec));
        }
    }
    progress.finish();

    for (auto& inst : instances) results.algorithms.push_back(std::move(inst.results));
    results.meta["wall_time_s"] = msSince(wallStart) / 1000.0;
    results.meta["memory"] = memoryRecord(cfg, sceneGpu, results, rssAfterSetup, opt.memoryPlan);
    results.meta["frames_without_lit_pixels"] = framesWithoutLit;
    results.meta["gbuffer_hash_per_frame"] = gbufferHashes;
    results.meta["warnings"] = Json::array();
    const auto warn = [&](const std::string& w) {
        results.meta["warnings"].push_back(w);
        std::fprintf(stderr, "shadowlab: warning: %s\n", w.c_str());
    };
    if (cfg.reference && !framesWithoutLit.empty())
        warn(std::to_string(framesWithoutLit.size()) + " of " + std::to_string(cfg.frames) +
             " frames have no lit pixel (none covered, facing the light and inside its reach): accuracy "
             "is not measured on them" +
             (int(framesWithoutLit.size()) == cfg.frames ? ", so it is not measured at all" : ""));
    for (const auto& a : results.algorithms) {
        if (!a.repetitionDiffers.empty())
            warn(a.id + ": a repetition of the timed pass gave another image than the first on " + std::to_string(a.repetitionDiffers.size()) +
                 " of " + std::to_string(cfg.frames) + " frames (the algorithm is not deterministic; the first pass's images and accuracy are reported)");
        if (!a.visibilityDiffers.empty())
            warn(a.id + ": the statistics pass's visibility differs from the timed pass's on " + std::to_string(a.visibilityDiffers.size()) +
                 " of " + std::to_string(statFrames.size()) +
                 " frames (statistics must only count; the timed pass's images and accuracy are reported)");
        // A structure that overflowed, or a walk that was capped, leaves pixels decided conservatively
        // rather than measured: the images and accuracy of those frames are not the method's.
        size_t frames = 0;
        uint64_t total = 0;
        for (const auto& f : a.frames) frames += f.overflow ? 1 : 0, total += f.overflow;
        if (frames)
            warn(a.id + ": " + std::to_string(total) + " overflows or capped walks on " + std::to_string(frames) + " of " +
                 std::to_string(a.frames.size()) + " timed frames (see its overflow counters): those frames' images are not the method's own");
    }
    // Expectations are checked on the summary as written, so summary.json, the report and the
    // JUnit file say the same; a failed one changes nothing else (the caller sets the exit code).
    if (!cfg.expectations.empty()) results.meta["expectations"] = checkExpectations(cfg.expectations, cfg.expectationIds(), results.summary());
    if (!opt.writeOutputs) return results;
    stopIfBroken();

    // Order matters: the resolved config and tables first, plots next, summary.json last; the
    // rename that follows makes the whole directory appear at once.
    writeFileAtomic(dir + "/config.resolved.json", cfg.resolved.dump(2) + "\n");
    results.writeFramesCsv(dir + "/frames.csv");
    if (!statFrames.empty()) results.writeFramesCsv(dir + "/statistics.csv", true);
    Json summary = results.summary();
    results.writeReport(dir + "/report.md", summary);
    if (summary.contains("expectations"))
        writeFileAtomic(dir + "/expectations.junit.xml",
                        expectationsJUnit(cfg.name, summary["expectations"], results.meta["wall_time_s"].get<double>()));
    if (cfg.plots) runPlots(dir, finalDir, results.meta["stage_time_source"].get<std::string>());
    stopIfBroken();
    writeFileAtomic(dir + "/summary.json", summary.dump(2) + "\n");
    place->commit();
    return results;
}

} // namespace shadowlab
