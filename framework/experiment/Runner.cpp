#include "framework/experiment/Runner.h"

#include "framework/algorithm/AlgorithmHost.h"
#include "framework/core/BuildInfo.h"
#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
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
#include <functional>
#include <optional>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

std::vector<int> sortedCopy(std::vector<int> v) {
    std::sort(v.begin(), v.end());
    return v;
}

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
    if (diskNearlyFull(dir))
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

namespace {

/// What summary.json's top level says of a run before any frame: what ran, on which device and
/// sources, at which settings (the one place this record is built).
Json runMetadata(const ExperimentConfig& cfg, const std::string& backend, bool softwareGl, const std::vector<int>& statFrames,
                 const std::string& startedUtc) {
    return {{"name", cfg.name},
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
            {"resolution", {cfg.resolution.x, cfg.resolution.y}},
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
}

/// The output place a run writes into: the caller's, or one it opens itself (checked and locked).
OutputPlace* openPlace(const ExperimentConfig& cfg, const RunOptions& opt, std::optional<OutputPlace>& own) {
    if (!opt.writeOutputs || opt.place) return opt.place;
    std::vector<std::string> notes;
    own.emplace(OutputPlace::open(opt.outputDir.empty() ? cfg.outputDir : opt.outputDir, opt.force, &notes));
    for (const auto& n : notes) std::fprintf(stderr, "shadowlab: %s\n", n.c_str());
    return &*own;
}

/// One experiment, as named phases in the order run() calls them: set up (scene, G-buffer, a timed
/// host per algorithm), warm up, the timed pass and its repetitions, the statistics pass, the
/// warnings and expectations, then the output written and committed at once.
class ExperimentRun {
public:
    ExperimentRun(const ExperimentConfig& cfg, const RunOptions& opt, const std::string& backend)
        : cfg_(cfg), opt_(opt), backend_(backend), place_(openPlace(cfg, opt, ownPlace_)),
          dir_(place_ ? place_->partialDir() : std::string()), finalDir_(place_ ? place_->finalDir() : std::string()),
          sceneGpu_(*cfg.scene), gbuffer_(cfg.resolution), shading_(cfg.resolution), statFrames_(cfg.statisticsFrames()),
          imageFrames_(sortedCopy(cfg.imagesAtFrames)) {}

    ExperimentResults run() {
        setUp();
        warmUp();
        timedPass();
        repeatTimedPass();
        // What each algorithm's device-dependent choices came to, as the timed pass ran them.
        for (auto& inst : instances_) inst.results.resolvedParams = inst.host->algorithm().resolvedParams();
        statisticsPass();
        progress_->finish();
        for (auto& inst : instances_) results_.algorithms.push_back(std::move(inst.results));
        finishRecord();
        if (opt_.writeOutputs) write();
        return std::move(results_);
    }

private:
    // A GL error (an allocation that failed, a framebuffer left incomplete) means the images and
    // times that follow are not the algorithms': the run stops there and saves nothing (the
    // previous results kept), instead of committing a "complete" output a sweep would then merge.
    void stopIfBroken() const {
        throwIfInterrupted();
        if (glErrorCount() <= glErrorsAtStart_) return;
        std::string first = glLastErrors();
        first = first.size() > glMessagesAtStart_ ? first.substr(glMessagesAtStart_) : std::string("see the GL errors above");
        first = first.substr(0, first.find('\n'));
        throw RuntimeError(std::to_string(glErrorCount() - glErrorsAtStart_) + " OpenGL error(s) during the run (" + shortText(first, 200) +
                           "): its results cannot be trusted, so none were saved");
    }

    void setUp() {
        timer_.setSynchronous(softwareGl_);
        // The reference runs first each frame: every other algorithm is compared with its visibility.
        std::vector<const AlgorithmEntry*> entries;
        if (cfg_.reference) entries.push_back(&cfg_.referenceEntry);
        for (const auto& e : cfg_.algorithms) entries.push_back(&e);
        // Algorithms precompute at the rest pose; the first frame's pose reaches them through sceneMoved().
        sceneGpu_.setTime(cfg_.sceneTimeAt(0));
        for (const AlgorithmEntry* e : entries) {
            std::unique_ptr<AlgorithmHost> host;
            try {
                host = makeHost(*e, false, sceneGpu_, cfg_.resolution);
            } catch (const SceneRefusal& refusal) {
                throw sceneRefusalError(cfg_, *e, refusal.what());
            }
            Instance inst{e, std::move(host), {}, {}, {}};
            inst.results.id = e->id;
            inst.results.algorithm = e->info->name;
            inst.results.params = e->params.toJson();
            inst.results.preprocessMs = inst.host->preprocessMs();
            instances_.push_back(std::move(inst));
        }
        rssAfterSetup_ = residentBytes();
        results_.meta = runMetadata(cfg_, backend_, softwareGl_, statFrames_, startedUtc_);
        progress_.emplace(opt_.progress, size_t(cfg_.frames * cfg_.repeats + int(statFrames_.size()) + (cfg_.warmupFrames > 0 ? 1 : 0)) *
                                             instances_.size());
    }

    bool isImageFrame(int f) const { return opt_.writeOutputs && std::binary_search(imageFrames_.begin(), imageFrames_.end(), f); }
    bool isStatFrame(int f) const { return std::binary_search(statFrames_.begin(), statFrames_.end(), f); }

    // The G-buffer and its CPU copy are every algorithm's shared input, made before any timer
    // starts, in every pass: read back lazily, the copy was paid for by whichever CPU algorithm
    // (the reference, line_space) a repetition's rotated order put first, a different one each
    // pass (results/reference/compare_noise_llvmpipe.md).
    void renderFrame(const Camera& cam) {
        gbuffer_.render(sceneGpu_, cam);
        glFinish();
        cpuG_ = gbuffer_.readBack();
    }
    std::function<const CpuGBuffer&()> cpuG() {
        return [this]() -> const CpuGBuffer& {
            if (!cpuG_) cpuG_ = gbuffer_.readBack();
            return *cpuG_;
        };
    }

    // One timed frame of one algorithm; posing the moving parts is shared work, done once per
    // frame, and its cost is reported in every algorithm's frame.
    FrameMeasurement timedFrame(Instance& inst, const Camera& cam, const Light& light, int frame, const TimedWork& sceneUpdate) {
        FrameMeasurement m = inst.host->computeFrame({gbuffer_, cpuG(), cam, light, frame}, timer_);
        m.stages.insert(m.stages.begin(), sceneUpdate.stages.begin(), sceneUpdate.stages.end());
        m.wallMs += sceneUpdate.wallMs;
        return m;
    }

    // Shader compilation, first-touch allocations and caches are kept out of the timings.
    void warmUp() {
        if (cfg_.warmupFrames <= 0) return;
        Camera cam = cfg_.cameraAt(0);
        Light light = cfg_.lightAt(0);
        renderFrame(cam);
        for (auto& inst : instances_) {
            stopIfBroken();
            progress_->step("warm-up " + inst.entry->id);
            for (int w = 0; w < cfg_.warmupFrames; ++w) inst.host->computeFrame({gbuffer_, cpuG(), cam, light, 0}, timer_);
        }
    }

    void timedPass() {
        for (int frame = 0; frame < cfg_.frames; ++frame) {
            Camera cam = cfg_.cameraAt(frame);
            Light light = cfg_.lightAt(frame);
            // Posing the moving parts is shared work: done once, its cost reported in every algorithm's frame.
            const TimedWork sceneUpdate = sceneGpu_.setTime(cfg_.sceneTimeAt(frame), timer_);
            if (sceneGpu_.dynamic()) checkPoseBounds(cfg_, frame, sceneGpu_.bounds());
            renderFrame(cam);
            const CpuGBuffer& g = *cpuG_;
            // What every algorithm of this frame starts from: runs whose images must agree (a scene
            // rewritten without changing it) compare images only where this agrees too.
            std::vector<float> gbufferWords(g.position);
            gbufferWords.insert(gbufferWords.end(), g.normal.begin(), g.normal.end());
            gbufferHashes_.push_back(hexHash(visibilityHash(gbufferWords)));
            const std::vector<uint8_t> lit = litMask(g, light);
            const std::vector<uint8_t> covered = coveredMask(g);
            if (!std::any_of(lit.begin(), lit.end(), [](uint8_t v) { return v != 0; })) framesWithoutLit_.push_back(frame);
            std::vector<float> reference;
            for (auto& inst : instances_) timedFrameOf(inst, cam, light, frame, sceneUpdate, lit, covered, reference);
        }
    }

    void timedFrameOf(Instance& inst, const Camera& cam, const Light& light, int frame, const TimedWork& sceneUpdate,
                      const std::vector<uint8_t>& lit, const std::vector<uint8_t>& covered, std::vector<float>& reference) {
        stopIfBroken();
        progress_->step(inst.entry->id + " frame " + std::to_string(frame + 1) + "/" + std::to_string(cfg_.frames));
        const FrameMeasurement m = timedFrame(inst, cam, light, frame, sceneUpdate);
        FrameRecord rec = recordOf(m, frame);
        inst.results.memoryBytes = std::max(inst.results.memoryBytes, m.memoryBytes);
        inst.results.residentBytes = std::max(inst.results.residentBytes, m.residentBytes);

        std::vector<float> vis = inst.host->readVisibility();
        const bool isReference = cfg_.reference && inst.entry == &cfg_.referenceEntry;
        if (isReference) reference = vis;
        if (cfg_.reference && (framesWithoutLit_.empty() || framesWithoutLit_.back() != frame)) {
            rec.hasAccuracy = true;
            rec.accuracy = compareVisibility(vis, reference, lit);
        }
        rec.visibilityHash = visibilityHash(vis);
        if (isStatFrame(frame)) inst.timedVisibility[frame] = rec.visibilityHash;
        if (cfg_.repeats > 1) inst.firstImages.push_back(rec.visibilityHash);
        if (isImageFrame(frame)) {
            shading_.run(gbuffer_, inst.host->visibility(), light);
            writeFrameImages(dir_, inst.entry->id, frame, cfg_.resolution, shading_, vis,
                             cfg_.reference && !isReference ? &reference : nullptr, lit, covered);
        }
        inst.results.frames.push_back(std::move(rec));
    }

    // Repetitions of the timed pass: the same frames, the algorithms in a rotated order each time,
    // times and overflow recorded; each image is hashed against the first pass's (they must agree).
    void repeatTimedPass() {
        for (int rep = 1; rep < cfg_.repeats; ++rep) {
            for (auto& inst : instances_) inst.results.repetitions.emplace_back();
            for (int frame = 0; frame < cfg_.frames; ++frame) {
                Camera cam = cfg_.cameraAt(frame);
                Light light = cfg_.lightAt(frame);
                const TimedWork sceneUpdate = sceneGpu_.setTime(cfg_.sceneTimeAt(frame), timer_);
                renderFrame(cam);
                for (size_t k = 0; k < instances_.size(); ++k) {
                    Instance& inst = instances_[(k + size_t(rep)) % instances_.size()];
                    stopIfBroken();
                    progress_->step(inst.entry->id + " repetition " + std::to_string(rep + 1) + ", frame " + std::to_string(frame + 1));
                    inst.results.repetitions.back().push_back(recordOf(timedFrame(inst, cam, light, frame, sceneUpdate), frame));
                    auto& differs = inst.results.repetitionDiffers;
                    if (visibilityHash(inst.host->readVisibility()) != inst.firstImages[size_t(frame)] &&
                        std::find(differs.begin(), differs.end(), frame) == differs.end())
                        differs.push_back(frame);
                }
            }
        }
    }

    // The same frames again with instrumented shaders, untimed as far as any table goes. The timed
    // hosts are released first, so the two passes never hold their GPU structures at once.
    void statisticsPass() {
        if (statFrames_.empty()) return;
        for (auto& inst : instances_) inst.host.reset();
        for (auto& inst : instances_) inst.host = makeHost(*inst.entry, true, sceneGpu_, cfg_.resolution);
        for (int frame : statFrames_) {
            Camera cam = cfg_.cameraAt(frame);
            Light light = cfg_.lightAt(frame);
            sceneGpu_.setTime(cfg_.sceneTimeAt(frame));
            renderFrame(cam);
            // Warmed up like the timed pass, so its times (shown only as the cost of the statistics)
            // leave shader compilation out too.
            if (frame == statFrames_.front())
                for (auto& inst : instances_)
                    for (int w = 0; w < cfg_.warmupFrames; ++w) inst.host->computeFrame({gbuffer_, cpuG(), cam, light, frame}, timer_);
            for (auto& inst : instances_) {
                stopIfBroken();
                progress_->step(inst.entry->id + " statistics, frame " + std::to_string(frame + 1) + "/" + std::to_string(cfg_.frames));
                FrameRecord rec = recordOf(inst.host->computeFrame({gbuffer_, cpuG(), cam, light, frame}, timer_), frame);
                if (visibilityHash(inst.host->readVisibility()) != inst.timedVisibility[frame]) inst.results.visibilityDiffers.push_back(frame);
                if (isImageFrame(frame)) writeHeatMaps(dir_, inst.entry->id, frame, cfg_.resolution, inst.host->algorithm().debugViews());
                inst.results.statistics.push_back(std::move(rec));
            }
        }
    }

    /// What was measured over the whole run, the warnings, and the expectations checked on the
    /// summary as written (so summary.json, the report and the JUnit file say the same; a failed one
    /// changes nothing else: the caller sets the exit code).
    void finishRecord() {
        Json& meta = results_.meta;
        meta["wall_time_s"] = msSince(wallStart_) / 1000.0;
        meta["memory"] = memoryRecord(cfg_, sceneGpu_, results_, rssAfterSetup_, opt_.memoryPlan);
        meta["frames_without_lit_pixels"] = framesWithoutLit_;
        meta["gbuffer_hash_per_frame"] = gbufferHashes_;
        meta["warnings"] = Json::array();
        for (const std::string& w : warnings()) {
            meta["warnings"].push_back(w);
            std::fprintf(stderr, "shadowlab: warning: %s\n", w.c_str());
        }
        if (!cfg_.expectations.empty()) meta["expectations"] = checkExpectations(cfg_.expectations, cfg_.expectationIds(), results_.summary());
    }

    std::vector<std::string> warnings() const {
        std::vector<std::string> out;
        const std::string frames = std::to_string(cfg_.frames);
        if (cfg_.reference && !framesWithoutLit_.empty())
            out.push_back(std::to_string(framesWithoutLit_.size()) + " of " + frames +
                          " frames have no lit pixel (none covered, facing the light and inside its reach): accuracy "
                          "is not measured on them" +
                          (int(framesWithoutLit_.size()) == cfg_.frames ? ", so it is not measured at all" : ""));
        for (const auto& a : results_.algorithms) {
            if (!a.repetitionDiffers.empty())
                out.push_back(a.id + ": a repetition of the timed pass gave another image than the first on " +
                              std::to_string(a.repetitionDiffers.size()) + " of " + frames +
                              " frames (the algorithm is not deterministic; the first pass's images and accuracy are reported)");
            if (!a.visibilityDiffers.empty())
                out.push_back(a.id + ": the statistics pass's visibility differs from the timed pass's on " +
                              std::to_string(a.visibilityDiffers.size()) + " of " + std::to_string(statFrames_.size()) +
                              " frames (statistics must only count; the timed pass's images and accuracy are reported)");
            // A structure that overflowed, or a walk that was capped, leaves pixels decided
            // conservatively rather than measured: the images and accuracy of those frames are not the method's.
            size_t overflowed = 0;
            uint64_t total = 0;
            for (const auto& f : a.frames) overflowed += f.overflow ? 1 : 0, total += f.overflow;
            if (overflowed)
                out.push_back(a.id + ": " + std::to_string(total) + " overflows or capped walks on " + std::to_string(overflowed) + " of " +
                              std::to_string(a.frames.size()) + " timed frames (see its overflow counters): those frames' images are not the method's own");
        }
        return out;
    }

    // Order matters: the resolved config and tables first, plots next, summary.json last; the
    // rename that follows makes the whole directory appear at once.
    void write() {
        stopIfBroken();
        writeFileAtomic(dir_ + "/config.resolved.json", cfg_.resolved.dump(2) + "\n");
        results_.writeFramesCsv(dir_ + "/frames.csv");
        if (!statFrames_.empty()) results_.writeFramesCsv(dir_ + "/statistics.csv", true);
        const Json summary = results_.summary();
        results_.writeReport(dir_ + "/report.md", summary);
        if (summary.contains("expectations"))
            writeFileAtomic(dir_ + "/expectations.junit.xml",
                            expectationsJUnit(cfg_.name, summary["expectations"], results_.meta["wall_time_s"].get<double>()));
        if (cfg_.plots) runPlots(dir_, finalDir_, results_.meta["stage_time_source"].get<std::string>());
        stopIfBroken();
        writeFileAtomic(dir_ + "/summary.json", summary.dump(2) + "\n");
        place_->commit();
    }

    const ExperimentConfig& cfg_;
    const RunOptions& opt_;
    const std::string backend_;
    const Clock::time_point wallStart_ = Clock::now();
    const std::string startedUtc_ = utcTimestamp();
    std::optional<OutputPlace> ownPlace_;
    OutputPlace* place_;
    const std::string dir_, finalDir_;
    const int glErrorsAtStart_ = glErrorCount();
    const size_t glMessagesAtStart_ = glLastErrors().size();
    SceneGpu sceneGpu_;
    GBuffer gbuffer_;
    ShadingPass shading_;
    StageTimer timer_;
    const bool softwareGl_ = isSoftwareRenderer(glRendererString());
    const std::vector<int> statFrames_;
    const std::vector<int> imageFrames_; ///< output.images_at_frames, sorted
    std::vector<Instance> instances_;
    size_t rssAfterSetup_ = 0;
    ExperimentResults results_;
    std::optional<Progress> progress_;
    std::optional<CpuGBuffer> cpuG_;
    std::vector<int> framesWithoutLit_; ///< accuracy is measured over lit pixels: none, nothing to measure
    Json gbufferHashes_ = Json::array();
};

} // namespace

ExperimentResults runExperiment(const ExperimentConfig& cfg, const RunOptions& opt, const std::string& backend) {
    return ExperimentRun(cfg, opt, backend).run();
}

} // namespace shadowlab
