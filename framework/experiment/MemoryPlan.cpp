#include "framework/experiment/MemoryPlan.h"

#include "framework/core/CheckedMath.h"
#include "framework/core/Error.h"
#include "framework/core/SystemMemory.h"
#include "framework/gl/GlObjects.h"
#include "framework/gl/Shader.h"

#include <algorithm>
#include <cstdio>
#include <thread>

namespace shadowlab {

namespace {
/// Bytes a storage block really addresses here: GL_MAX_SHADER_STORAGE_BLOCK_SIZE, or more where a
/// write and a read at the end of a larger buffer round-trip. llvmpipe reports 128 MiB but bounds
/// its accesses by the bound buffer, which may hold up to 4 GiB; by the spec an access past the
/// reported size is undefined, so the larger figure is taken only as measured on this context.
/// The probe's buffer is the reported size and 64 KiB more (llvmpipe zero-fills a new buffer, so it
/// is resident), and an implementation that addresses past the reported size there is taken to
/// bound accesses by the buffer (up to 2 GiB, where GLSL's uint word indices stay far from wrapping).
size_t addressableStorageBytes() {
    const size_t reported = maxShaderStorageBlockBytes();
    constexpr size_t kAddressable = size_t(1) << 31;
    if (reported >= kAddressable) return reported;
    const size_t probeBytes = reported + (size_t(1) << 16);
    const uint32_t index = uint32_t(probeBytes / 4 - 4);
    GlBuffer buffer(probeBytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
    const uint32_t seed = 41;
    buffer.upload(&seed, sizeof seed, size_t(index - 1) * 4);
    ShaderProgram probe = ShaderProgram::compute("common/storage_probe.comp");
    probe.set("uIndex", index);
    probe.use();
    buffer.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    uint32_t words[2] = {0, 0};
    glGetNamedBufferSubData(buffer.id(), GLintptr(index) * 4, sizeof words, words);
    return words[0] == 0x5EEDu && words[1] == seed + 1 ? kAddressable : reported;
}
} // namespace

DeviceLimits currentDeviceLimits(size_t triangles) {
    const size_t reported = maxShaderStorageBlockBytes();
    // Only a scene whose largest per-triangle block (psv's 128 bytes) could pass the reported size
    // pays for the probe (its buffer is resident while it runs).
    const size_t storage = saturatingSum({saturatingMul(triangles, 128), 4096}) > reported ? addressableStorageBytes() : reported;
    return {storage, maxTextureBufferTexels(), reported};
}

std::string formatMemorySize(size_t bytes) {
    // Below a tenth of a GiB in MiB: "0.00 GiB of 0.00 GiB" hid both sides of a refusal under a
    // small ulimit (twenty-third probe).
    char s[32];
    if (bytes < (size_t(1) << 30) / 10) std::snprintf(s, sizeof s, "%.1f MiB", double(bytes) / double(size_t(1) << 20));
    else std::snprintf(s, sizeof s, "%.2f GiB", double(bytes) / double(size_t(1) << 30));
    return s;
}

Json MemoryPlan::toJson() const {
    Json parts = Json::object();
    for (const auto& [name, bytes] : held) parts[name] = bytes;
    return {{"triangles", triangles},       {"moving", moving},       {"held_bytes", parts},
            {"load_peak_bytes", loadPeak},  {"peak_bytes", peak},     {"available_bytes", available},
            {"machine_bytes", machine}};
}

std::string MemoryPlan::summary() const {
    std::string s = formatMemorySize(peak) + " estimated at the peak, of " + formatMemorySize(available) + " available (";
    bool first = true;
    // The largest parts, at most five: a plan of 2000 algorithm entries stays one short line.
    std::vector<std::pair<std::string, size_t>> parts = held;
    std::stable_sort(parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    size_t listed = 0, rest = 0;
    for (const auto& [name, bytes] : parts) {
        if (bytes < (size_t(1) << 20)) continue; // below a MiB: noise in a line about gigabytes
        if (listed == 5) {
            ++rest;
            continue;
        }
        ++listed;
        char part[96];
        std::snprintf(part, sizeof part, "%s%s %.2f", first ? "" : ", ", name.c_str(), double(bytes) / double(size_t(1) << 30));
        s += part;
        first = false;
    }
    if (rest > 0) s += ", and " + std::to_string(rest) + " more";
    return s + (first ? "nothing large" : "") + ")";
}

namespace {
std::vector<const AlgorithmEntry*> planEntries(const ExperimentConfig& cfg) {
    std::vector<const AlgorithmEntry*> entries;
    if (cfg.reference) entries.push_back(&cfg.referenceEntry);
    for (const AlgorithmEntry& e : cfg.algorithms) entries.push_back(&e);
    return entries;
}

Footprint footprintOf(const AlgorithmEntry& e, const ExperimentConfig& cfg, size_t triangles, bool moving, const DeviceLimits& limits) {
    if (!e.info->footprint) return {};
    FootprintQuery q;
    q.triangles = triangles;
    q.resolution = cfg.resolution;
    q.fovYDeg = cfg.camera.fovYDeg;
    q.nearPlane = cfg.camera.nearPlane;
    q.farPlane = cfg.camera.farPlane;
    q.moving = moving;
    q.params = &e.params;
    q.storageBlockBytes = limits.storageBlockBytes;
    q.textureBufferTexels = limits.textureBufferTexels;
    q.reportedStorageBlockBytes = limits.reportedStorageBlockBytes;
    return e.info->footprint(q);
}

/// A byte total of the plan that reached kSaturated does not fit 64 bits: the plan cannot be
/// trusted past it, so the run is refused (at `where`) instead of planned with a wrapped number.
void refuseOverflow(const ExperimentConfig& cfg, const std::string& where, const std::string& what, size_t bytes,
                    size_t triangles) {
    if (bytes != kSaturated) return;
    throw InputError(cfg.file, where, what + " for " + std::to_string(triangles) +
                                          " triangles overflows a 64-bit byte count: use fewer triangles");
}

std::string entryPath(const ExperimentConfig& cfg, const AlgorithmEntry& e) {
    if (!e.jsonPath.empty()) return e.jsonPath;
    return &e == &cfg.referenceEntry ? "/reference" : "/algorithms";
}
} // namespace

std::vector<std::string> describeFootprints(const ExperimentConfig& cfg, size_t triangles, bool moving, const DeviceLimits& limits) {
    std::vector<std::string> lines;
    for (const AlgorithmEntry* e : planEntries(cfg)) {
        const Footprint f = footprintOf(*e, cfg, triangles, moving, limits);
        lines.push_back(e->id + " (" + e->info->name + "): " +
                        (f.refusal.empty() ? formatMemorySize(f.bytes) + " held, " + formatMemorySize(f.peakBytes) + " more while it sets up" +
                                                 (e->info->sceneCheck ? " (at most; whether its structures fit this device "
                                                                        "is decided on the scene, by validate and run)"
                                                                      : "")
                                           : "refuses: " + f.refusal));
    }
    return lines;
}

InputError sceneRefusalError(const ExperimentConfig& cfg, const AlgorithmEntry& entry, std::string why) {
    if (why.starts_with(entry.info->name + ": ")) why.erase(0, entry.info->name.size() + 2);
    return InputError(cfg.file, entryPath(cfg, entry), entry.info->name + " cannot hold this scene (" +
                                                          std::to_string(cfg.scene->triangleCount()) +
                                                          " triangles) with these parameters on this device: " + why);
}

/// The first material below full opacity that a triangle uses, or -1.
long translucentMaterial(const Scene& s) {
    for (uint32_t id : s.materialIds)
        if (id < s.materials.size() && s.materials[id].opacity < 1.0f) return long(id);
    return -1;
}

void checkAlgorithmsTakeScene(const ExperimentConfig& cfg) {
    // Tenth probe: every exact algorithm but psv with transparency drew opaque shadows under
    // translucent casters, which the reference lets light through: wrong pixels, none counted.
    if (translucentMaterial(*cfg.scene) >= 0)
        for (const AlgorithmEntry* e : planEntries(cfg))
            if (e->info->exact && !(e->info->takesOpacity && e->info->takesOpacity(e->params)))
                throw InputError(cfg.file, entryPath(cfg, *e),
                                 e->info->name + " draws opaque shadows, but the scene has translucent triangles (opacity below 1), "
                                                 "which the reference lets light through: set their opacity to 1 or leave " + e->id +
                                                 " out" + (e->info->name == "psv" ? " (or give it \"transparency\": true)" : ""));
    for (const AlgorithmEntry* e : planEntries(cfg)) {
        if (!e->info->sceneCheck) continue;
        const std::string why = e->info->sceneCheck(*cfg.scene, e->params);
        if (!why.empty()) throw sceneRefusalError(cfg, *e, why);
    }
}

size_t predictedSceneBytes(const ScenePrediction& scene) {
    // Per triangle, plus one vertex of slack (Scene::append reserves it), 16 bytes a material
    // (Material), and per moving triangle its three local vertices (MovingPart::local).
    return saturatingSum({saturatingMul(scene.triangles, kSceneBytesPerTriangle), sizeof(glm::vec3),
                          saturatingMul(scene.materials, sizeof(Material)), saturatingMul(scene.movingTriangles, 3 * sizeof(glm::vec3)),
                          saturatingMul(scene.movingParts, sizeof(MovingPart))});
}

/// SceneGpu's buffers: per triangle, 16 bytes a material (RGBA32F), and per moving triangle its
/// local vertices (three vec4) and index (uvec2), per moving part its matrix.
size_t predictedSceneGpuBytes(const ScenePrediction& scene) {
    return saturatingSum({saturatingMul(scene.triangles, kSceneGpuBytesPerTriangle), saturatingMul(scene.materials, 16),
                          saturatingMul(scene.movingTriangles, kMovingGpuBytesPerTriangle),
                          saturatingMul(scene.movingParts, sizeof(glm::mat4))});
}

MemoryPlan checkMemoryPlan(const ExperimentConfig& cfg, const ScenePrediction& scene, const DeviceLimits& limits) {
    return checkMemoryPlan(cfg, scene, limits, systemMemory());
}

MemoryPlan checkMemoryPlan(const ExperimentConfig& cfg, const ScenePrediction& scene, const DeviceLimits& limits,
                           const SystemMemory& machine) {
    const size_t triangles = scene.triangles;
    const bool moving = scene.moving;
    MemoryPlan plan;
    plan.triangles = triangles;
    plan.moving = moving;
    plan.available = machine.available;
    plan.machine = machine.total;

    // Moving parts are posed by SceneGpu's update pass, which writes the positions as one storage
    // block indexed by scene triangle: past what a block addresses those writes would be lost.
    const size_t poseLimit = limits.storageBlockBytes / (9 * sizeof(float));
    if (moving && limits.storageBlockBytes > 0 && triangles > poseLimit)
        throw InputError(cfg.file, "/scene",
                         "a scene with moving parts is posed through one storage block of at most " +
                             std::to_string(limits.storageBlockBytes >> 20) + " MiB on this device, " +
                             std::to_string(poseLimit) + " triangles; this one has up to " + std::to_string(triangles));

    plan.held.emplace_back("scene", predictedSceneBytes(scene));
    plan.held.emplace_back("scene_gpu", predictedSceneGpuBytes(scene));
    // The framework's per-pixel buffers: G-buffer, its host copy, lit and covered masks, shading,
    // the visibility read back per algorithm and the images written (results/reference/memory_bounds_llvmpipe.md).
    plan.held.emplace_back("frame buffers", saturatingMul(size_t(cfg.resolution.x) * size_t(cfg.resolution.y), kFrameBytesPerPixel));
    // The largest object (a grid's copies) is made whole and then appended to the scene.
    plan.loadPeak = saturatingMul(2, plan.held[0].second);
    refuseOverflow(cfg, "/scene", "the scene", plan.loadPeak, triangles);
    // SceneGpu stages the moving parts' local vertices and indices on the host while it uploads them.
    const size_t gpuUploadPeak = saturatingSum({plan.held[0].second, plan.held[1].second,
                                                saturatingMul(scene.movingTriangles, kMovingGpuBytesPerTriangle)});

    // Algorithms set up one after the other (the reference first): each one's transient sits on
    // top of the scene and of what it and the ones before it hold, not of what comes after.
    size_t held = saturatingSum({plan.held[0].second, plan.held[1].second, plan.held[2].second}), setupPeak = 0;
    size_t buffersAgain = 0, largestSetup = 0;  // for the statistics pass, below
    const size_t cores = std::max(1u, std::thread::hardware_concurrency());
    for (const AlgorithmEntry* e : planEntries(cfg)) {
        if (!e->info->footprint) continue;
        const Footprint f = footprintOf(*e, cfg, triangles, moving, limits);
        const std::string where = entryPath(cfg, *e);
        if (!f.refusal.empty())
            throw InputError(cfg.file, where, e->info->name + " cannot run this scene (up to " + std::to_string(triangles) +
                                                  " triangles) on this device: " + f.refusal);
        // Nineteenth probe: 256 reference threads' stacks under `ulimit -v` ended a run in
        // std::terminate (Embree could not start them); those past one per core are set aside.
        if (std::string(machine.limitedBy) == "ulimit -v" && f.threads > cores)
            plan.available -= std::min(plan.available, saturatingMul(f.threads - cores, threadStackBytes()));
        plan.held.emplace_back(e->id, f.bytes);
        buffersAgain = saturatingSum({buffersAgain, f.bytes - std::min(f.bytes, f.textureBytes)});
        largestSetup = std::max(largestSetup, f.peakBytes);
        held = saturatingSum({held, f.bytes});
        setupPeak = std::max(setupPeak, saturatingSum({held, f.peakBytes}));
        refuseOverflow(cfg, where, e->info->name + "'s estimate with what is held before it", setupPeak, triangles);
    }
    // The statistics pass makes every algorithm again (instrumented) while the driver still holds
    // the timed pass's buffers: llvmpipe frees them only at the end of the run, its textures at
    // once (results/reference/memory_bounds_llvmpipe.md).
    if (!cfg.statisticsFrames().empty()) {
        plan.held.emplace_back("statistics pass", buffersAgain);
        held = saturatingSum({held, buffersAgain});
        setupPeak = std::max(setupPeak, saturatingSum({held, largestSetup}));
        refuseOverflow(cfg, "/statistics", "the statistics pass's structures with the timed pass's", setupPeak, triangles);
    }
    plan.peak = std::max({plan.loadPeak, gpuUploadPeak, held, setupPeak});
    // 0 available is unknown (no MemAvailable), except where a limit says nothing is left.
    if ((plan.available > 0 || *machine.limitedBy) && plan.peak > plan.available)
        throw InputError(cfg.file, "/scene",
                         "the run would need about " + plan.summary() + " for up to " + std::to_string(triangles) +
                             " triangles; " +
                             (*machine.limitedBy ? "this process may take " + formatMemorySize(plan.available) + " more (" + machine.limitedBy + ")"
                                                 : "this machine has " + formatMemorySize(plan.machine) + " in all") +
                             ": use fewer triangles or algorithms");
    return plan;
}

} // namespace shadowlab
