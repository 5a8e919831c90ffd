#include "framework/reference/EmbreeTracer.h"

#include "framework/core/Error.h"
#include "framework/reference/Watertight.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

namespace shadowlab {

struct EmbreeTracer::DeviceState {
    std::atomic<int64_t> bytes{0};
    std::mutex errorMutex;
    std::string error; ///< first error reported by Embree since the last check
};

namespace {

// Embree reports allocations (bytes > 0) and frees (bytes < 0) of the device through this callback;
// the running sum is the memory the BVH and the geometry buffers hold.
bool memoryMonitor(void* user, ssize_t bytes, bool /*post*/) {
    static_cast<std::atomic<int64_t>*>(user)->fetch_add(int64_t(bytes), std::memory_order_relaxed);
    return true; // never veto: running out is reported as an error on the commit instead
}

const char* errorName(RTCError code) {
    switch (code) {
    case RTC_ERROR_NONE: return "none";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
    }
}

// The per-ray state travels with the intersect context: Embree hands the same pointer to the
// triangles' occlusion callback, so the context is the first member and the callback casts back.
struct TraceContext {
    RTCIntersectContext rtc;
    watertight::Ray ray; ///< the ray in the triangle test's frame, set up once
    const glm::vec3* vertices;
    // The transparent path only (materialIds null otherwise):
    const uint32_t* materialIds;
    const float* materialTransmit;
    std::vector<EmbreeTracer::CountedHit>* seen;
    float transmission;
};

// Whether a hit (prim, t) is one already counted: the same triangle reported again, or the same
// surface crossing reported by the other triangle of a shared edge/vertex (same distance).
bool alreadyCounted(const std::vector<EmbreeTracer::CountedHit>& seen, unsigned prim, float t) {
    for (const auto& h : seen)
        if (h.prim == prim || std::abs(h.t - t) <= EmbreeTracer::kSameHitDistance * std::max(h.t, t)) return true;
    return false;
}

// The triangles are Embree user primitives: Embree's BVH finds the candidates, and the shaders'
// watertight test (Watertight.h) decides each, so the reference's decision on every ray–triangle
// pair is the GPU algorithms' own. A hit occludes the ray (tfar = -inf); on the transparent path
// each distinct crossing multiplies in its transmission, and the ray goes on unless (numerically)
// fully blocked. Hits arrive in no particular order; the product and the duplicate test do not
// depend on it. Only rtcOccluded1 is used, so every valid lane is the context's one ray.
void occludedTriangle(const RTCOccludedFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<TraceContext*>(args->context);
    const glm::vec3* v = ctx->vertices + 3 * size_t(args->primID);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        float t = 0.0f;
        if (!watertight::hit(ctx->ray, v[0], v[1], v[2], &t)) continue;
        if (ctx->materialIds) {
            if (!alreadyCounted(*ctx->seen, args->primID, t)) {
                ctx->seen->push_back({args->primID, t});
                ctx->transmission *= ctx->materialTransmit[ctx->materialIds[args->primID]];
            }
            if (ctx->transmission > EmbreeTracer::kOpaqueTransmission) continue;
        }
        RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
    }
}

// A triangle's box, widened by a few float steps so that Embree's box test can drop no ray the
// watertight test would let hit it (the test decides within rounding of the triangle's edges).
void triangleBounds(const RTCBoundsFunctionArguments* args) {
    const glm::vec3* v = static_cast<const glm::vec3*>(args->geometryUserPtr) + 3 * size_t(args->primID);
    glm::vec3 lo = glm::min(v[0], glm::min(v[1], v[2])), hi = glm::max(v[0], glm::max(v[1], v[2]));
    const glm::vec3 pad = glm::max(glm::abs(lo), glm::abs(hi)) * 0x1p-20f + glm::vec3(std::numeric_limits<float>::min());
    lo -= pad, hi += pad;
    *args->bounds_o = RTCBounds{lo.x, lo.y, lo.z, 0.0f, hi.x, hi.y, hi.z, 0.0f};
}

RTCRay makeRay(glm::vec3 o, glm::vec3 d, float tfar) {
    RTCRay r{};
    r.org_x = o.x, r.org_y = o.y, r.org_z = o.z;
    r.dir_x = d.x, r.dir_y = d.y, r.dir_z = d.z;
    r.tnear = 0.0f; // the watertight test takes hits on (0, tfar]
    r.tfar = tfar;
    r.time = 0.0f;
    r.mask = 0xFFFFFFFFu; // the geometry's default mask is all ones; a zero ray mask would hit nothing
    r.id = 0;
    r.flags = 0;
    return r;
}

} // namespace

EmbreeTracer::EmbreeTracer(const Scene& scene) : EmbreeTracer(scene, MotionUpdate::Refit) {}

EmbreeTracer::EmbreeTracer(const Scene& scene, MotionUpdate update) : EmbreeTracer(scene, update, Vertices::Copy) {}

EmbreeTracer::EmbreeTracer(const Scene& scene, MotionUpdate update, Vertices vertices, bool compact)
    : state_(std::make_unique<DeviceState>()) {
    device_ = rtcNewDevice("verbose=0");
    if (!device_) throw RuntimeError("Embree: cannot create a device (" + std::string(errorName(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(
        device_,
        [](void* user, RTCError code, const char* str) {
            auto* st = static_cast<DeviceState*>(user);
            std::lock_guard lock(st->errorMutex);
            if (st->error.empty()) st->error = std::string(errorName(code)) + (str ? std::string(": ") + str : "");
        },
        state_.get());
    rtcSetDeviceMemoryMonitorFunction(device_, memoryMonitor, &state_->bytes);

    // Releases what was made and throws: the destructor does not run for a throwing constructor.
    auto fail = [this](const std::string& what, std::string cause = {}) {
        if (cause.empty()) {
            std::lock_guard lock(state_->errorMutex);
            cause = state_->error.empty() ? std::string("unknown error") : state_->error;
        }
        if (scene_) rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
        scene_ = nullptr, device_ = nullptr;
        throw RuntimeError("Embree: " + what + " failed: " + cause);
    };

    triangleCount_ = scene.triangleCount();
    for (const auto& m : scene.materials) {
        materialTransmit_.push_back(std::clamp(1.0f - m.opacity, 0.0f, 1.0f));
        if (m.opacity < 1.0f) transparent_ = true;
    }
    if (transparent_) materialIds_ = scene.materialIds;

    // ROBUST: turns off Embree's accuracy-reducing shortcuts in its box tests; the ground truth must
    // not lose a candidate triangle at a grazing angle to speed.
    RTCSceneFlags flags = RTC_SCENE_FLAG_ROBUST;
    const bool dynamic = scene.dynamic();
    if (dynamic) flags = RTCSceneFlags(flags | RTC_SCENE_FLAG_DYNAMIC);
    if (compact) flags = RTCSceneFlags(flags | RTC_SCENE_FLAG_COMPACT);
    scene_ = rtcNewScene(device_);
    if (!scene_) fail("rtcNewScene");
    rtcSetSceneFlags(scene_, flags);
    rtcSetSceneBuildQuality(scene_, dynamic ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH);

    if (triangleCount_ > 0) {
        if (triangleCount_ > std::numeric_limits<uint32_t>::max())
            fail("indexing the scene", "too many triangles for 32-bit primitive ids");
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
        if (!geom) fail("rtcNewGeometry");
        // Shared: the Scene's floats in place, when nothing will move them. Otherwise a copy, and
        // the Scene need not outlive us.
        sharesVertices_ = vertices == Vertices::Share && !dynamic;
        if (!sharesVertices_) ownVertices_ = scene.positions;
        vertices_ = sharesVertices_ ? scene.positions.data() : ownVertices_.data();
        rtcSetGeometryUserPrimitiveCount(geom, unsigned(triangleCount_));
        rtcSetGeometryUserData(geom, const_cast<glm::vec3*>(vertices_));
        rtcSetGeometryBoundsFunction(geom, triangleBounds, const_cast<glm::vec3*>(vertices_));
        rtcSetGeometryOccludedFunction(geom, occludedTriangle);
        if (dynamic && update == MotionUpdate::Refit) rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_REFIT);
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene_, geom);
        geometry_ = geom;
        rtcReleaseGeometry(geom); // the scene keeps its own reference
    }
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) fail("building the BVH");
}

void EmbreeTracer::moveTriangles(size_t firstTriangle, const glm::vec3* positions, size_t count) {
    if (!geometry_ || firstTriangle + count > triangleCount_) throw RuntimeError("Embree: moved triangles out of range");
    std::memcpy(ownVertices_.data() + 3 * firstTriangle, positions, 3 * count * sizeof(glm::vec3));
}

void EmbreeTracer::commitMoves() {
    if (!geometry_) return;
    rtcCommitGeometry(geometry_); // the bounds callback reads the moved vertices
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw RuntimeError("Embree: updating the BVH failed");
}

EmbreeTracer::~EmbreeTracer() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

size_t EmbreeTracer::memoryBytes() const {
    int64_t embree = std::max<int64_t>(0, state_->bytes.load(std::memory_order_relaxed));
    return size_t(embree) + ownVertices_.size() * sizeof(glm::vec3) + materialIds_.size() * sizeof(uint32_t) +
           materialTransmit_.size() * sizeof(float);
}

bool EmbreeTracer::occluded(glm::vec3 origin, glm::vec3 dir, float tfar) const {
    TraceContext ctx{};
    rtcInitIntersectContext(&ctx.rtc); // no materials: any triangle blocks, whatever its opacity
    ctx.ray = watertight::makeRay(origin, dir, tfar);
    ctx.vertices = vertices_;
    RTCRay ray = makeRay(origin, dir, tfar);
    if (triangleCount_ > 0) rtcOccluded1(scene_, &ctx.rtc, &ray);
    return ray.tfar < 0.0f; // tfar = -inf on an occlusion hit
}

float EmbreeTracer::transmission(glm::vec3 origin, glm::vec3 dir, float tfar) const {
    std::vector<CountedHit> seen;
    return traceSegment(origin, dir, tfar, seen);
}

float EmbreeTracer::traceSegment(glm::vec3 origin, glm::vec3 dir, float tfar, std::vector<CountedHit>& seen) const {
    if (!transparent_) return occluded(origin, dir, tfar) ? 0.0f : 1.0f;
    seen.clear();
    TraceContext ctx{};
    rtcInitIntersectContext(&ctx.rtc);
    ctx.ray = watertight::makeRay(origin, dir, tfar);
    ctx.vertices = vertices_;
    ctx.materialIds = materialIds_.data();
    ctx.materialTransmit = materialTransmit_.data();
    ctx.seen = &seen;
    ctx.transmission = 1.0f;
    RTCRay ray = makeRay(origin, dir, tfar);
    if (triangleCount_ > 0) rtcOccluded1(scene_, &ctx.rtc, &ray);
    return ray.tfar < 0.0f ? 0.0f : ctx.transmission;
}

int EmbreeTracer::threadsFor(int requested, size_t pixels) {
    if (requested > 0) return requested;
    const size_t byWork = std::max<size_t>(1, pixels / kPixelsPerThread);
    return int(std::min<size_t>(byWork, std::max(1u, std::thread::hardware_concurrency())));
}

void EmbreeTracer::traceVisibility(const CpuGBuffer& g, const Light& light, float rayOffset, int threads,
                                   std::vector<float>& visibility) const {
    const size_t pixels = size_t(std::max(g.width, 0)) * size_t(std::max(g.height, 0));
    visibility.assign(pixels, 1.0f);
    if (pixels == 0) {
        lastRays_ = 0;
        return;
    }
    const bool directional = light.type == LightType::Directional, area = light.type == LightType::Area;
    const std::vector<glm::vec3> samples = light.samplePoints();
    const glm::vec3 dirToLight = directional ? -light.direction() : glm::vec3(0.0f);
    const float inf = std::numeric_limits<float>::infinity();

    std::atomic<int> nextRow{0};
    std::atomic<uint64_t> rays{0};
    // Rows are handed out one at a time (dynamic scheduling): shadowed and lit regions cost very
    // different amounts, so static blocks would leave threads idle. Each pixel is computed the same
    // way whichever thread takes it, so the result does not depend on the thread count.
    auto worker = [&]() {
        std::vector<CountedHit> seen;
        uint64_t localRays = 0;
        for (int y = nextRow.fetch_add(1); y < g.height; y = nextRow.fetch_add(1)) {
            for (int x = 0; x < g.width; ++x) {
                const size_t i = size_t(y) * size_t(g.width) + size_t(x);
                if (!g.covered(i)) continue; // background stays 1
                const glm::vec3 p = g.positionAt(i), n = g.normalAt(i);
                if (!light.reaches(p, n)) {
                    visibility[i] = 0.0f;
                    continue;
                }
                const glm::vec3 o = watertight::origin(p, n, rayOffset);
                if (directional) {
                    visibility[i] = traceSegment(o, dirToLight, inf, seen);
                    ++localRays;
                    continue;
                }
                float sum = 0.0f;
                for (const glm::vec3& s : samples) {
                    ++localRays;
                    const watertight::Segment seg = watertight::towardsSample(o, s, rayOffset, area);
                    sum += seg.d == glm::vec3(0.0f) ? 1.0f : traceSegment(o, seg.d, seg.tfar, seen); // origin on the sample: nothing between
                }
                visibility[i] = sum / float(samples.size());
            }
        }
        rays.fetch_add(localRays, std::memory_order_relaxed);
    };

    const int n = std::min(threadsFor(threads, pixels), g.height);
    std::vector<std::thread> pool;
    pool.reserve(size_t(n - 1));
    for (int t = 1; t < n; ++t) pool.emplace_back(worker);
    worker(); // the calling thread works too
    for (auto& t : pool) t.join();
    lastRays_ = rays.load();
}

} // namespace shadowlab
