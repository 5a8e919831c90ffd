#include "framework/reference/EmbreeTracer.h"

#include "framework/core/Error.h"

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

// The per-ray state of the transparent path travels with the intersect context: Embree hands the
// same pointer to the filter, so the context is the first member and the filter casts back.
struct FilterContext {
    RTCIntersectContext rtc;
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

// Occlusion filter of the transparent path: multiplies in each distinct crossing's transmission and
// rejects the hit so traversal goes on, unless the ray is (numerically) fully blocked. Hits arrive
// in no particular order; the product and the duplicate test do not depend on it.
void transparencyFilter(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<FilterContext*>(args->context);
    // Only rtcOccluded1 is used, so every valid lane belongs to the one ray of this context.
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        float t = RTCRayN_tfar(args->ray, args->N, i); // Embree passes the hit distance in tfar
        if (!alreadyCounted(*ctx->seen, prim, t)) {
            ctx->seen->push_back({prim, t});
            ctx->transmission *= ctx->materialTransmit[ctx->materialIds[prim]];
        }
        if (ctx->transmission > EmbreeTracer::kOpaqueTransmission) args->valid[i] = 0;
    }
}

RTCRay makeRay(glm::vec3 o, glm::vec3 d, float tfar) {
    RTCRay r{};
    r.org_x = o.x, r.org_y = o.y, r.org_z = o.z;
    r.dir_x = d.x, r.dir_y = d.y, r.dir_z = d.z;
    r.tnear = std::numeric_limits<float>::min(); // hits count on (0, tfar], as in common/watertight.glsl: Embree takes t >= tnear
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
    if (transparent_) {
        materialIds_ = scene.materialIds;
        if (!rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED))
            fail("tracing transparent casters", "this Embree build has no filter function support");
    }

    // ROBUST: turns off Embree's accuracy-reducing shortcuts; the ground truth must not lose hits at
    // shared edges or grazing angles to speed. CONTEXT_FILTER_FUNCTION: only the transparent path sets a
    // context filter, so occluded() can still ask plain opaque questions of the same BVH.
    RTCSceneFlags flags = RTC_SCENE_FLAG_ROBUST;
    if (transparent_) flags = RTCSceneFlags(flags | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    const bool dynamic = scene.dynamic();
    if (dynamic) flags = RTCSceneFlags(flags | RTC_SCENE_FLAG_DYNAMIC);
    if (compact) flags = RTCSceneFlags(flags | RTC_SCENE_FLAG_COMPACT);
    scene_ = rtcNewScene(device_);
    if (!scene_) fail("rtcNewScene");
    rtcSetSceneFlags(scene_, flags);
    rtcSetSceneBuildQuality(scene_, dynamic ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH);

    if (triangleCount_ > 0) {
        if (triangleCount_ * 3 > std::numeric_limits<uint32_t>::max())
            fail("indexing the scene", "too many triangles for 32-bit indices");
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (!geom) fail("rtcNewGeometry");
        size_t nv = scene.positions.size();
        // Shared: the Scene's floats in place, when nothing will move them and the vector's spare
        // capacity covers Embree's read past the last vertex. Otherwise copied into Embree-allocated
        // buffers, which carry that padding, and the Scene need not outlive us.
        sharesVertices_ = vertices == Vertices::Share && !dynamic && scene.positions.capacity() > nv;
        float* verts = nullptr;
        if (sharesVertices_)
            rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, scene.positions.data(), 0,
                                       3 * sizeof(float), nv);
        else
            verts = static_cast<float*>(
                rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
        auto* index = static_cast<uint32_t*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangleCount_));
        if ((!verts && !sharesVertices_) || !index) {
            rtcReleaseGeometry(geom);
            fail("allocating geometry buffers");
        }
        static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
        if (verts) std::memcpy(verts, scene.positions.data(), nv * sizeof(glm::vec3));
        for (uint32_t i = 0; i < uint32_t(nv); ++i) index[i] = i; // triangle soup: triangle t = vertices 3t..3t+2
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
    auto* verts = static_cast<glm::vec3*>(rtcGetGeometryBufferData(geometry_, RTC_BUFFER_TYPE_VERTEX, 0));
    std::memcpy(verts + 3 * firstTriangle, positions, 3 * count * sizeof(glm::vec3));
}

void EmbreeTracer::commitMoves() {
    if (!geometry_) return;
    rtcUpdateGeometryBuffer(geometry_, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geometry_);
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw RuntimeError("Embree: updating the BVH failed");
}

EmbreeTracer::~EmbreeTracer() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

size_t EmbreeTracer::memoryBytes() const {
    int64_t embree = std::max<int64_t>(0, state_->bytes.load(std::memory_order_relaxed));
    return size_t(embree) + materialIds_.size() * sizeof(uint32_t) + materialTransmit_.size() * sizeof(float);
}

bool EmbreeTracer::occluded(glm::vec3 origin, glm::vec3 dir, float tfar) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx); // no filter: any triangle blocks, whatever its opacity
    RTCRay ray = makeRay(origin, dir, tfar);
    rtcOccluded1(scene_, &ctx, &ray);
    return ray.tfar < 0.0f; // Embree sets tfar = -inf on an occlusion hit
}

float EmbreeTracer::transmission(glm::vec3 origin, glm::vec3 dir, float tfar) const {
    std::vector<CountedHit> seen;
    return traceSegment(origin, dir, tfar, seen);
}

float EmbreeTracer::traceSegment(glm::vec3 origin, glm::vec3 dir, float tfar, std::vector<CountedHit>& seen) const {
    RTCRay ray = makeRay(origin, dir, tfar);
    if (!transparent_) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        rtcOccluded1(scene_, &ctx, &ray);
        return ray.tfar < 0.0f ? 0.0f : 1.0f;
    }
    seen.clear();
    FilterContext ctx{};
    rtcInitIntersectContext(&ctx.rtc);
    ctx.rtc.filter = transparencyFilter;
    ctx.materialIds = materialIds_.data();
    ctx.materialTransmit = materialTransmit_.data();
    ctx.seen = &seen;
    ctx.transmission = 1.0f;
    rtcOccluded1(scene_, &ctx.rtc, &ray);
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
    const bool directional = light.type == LightType::Directional;
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
                const glm::vec3 o = p + n * rayOffset;
                if (directional) {
                    visibility[i] = traceSegment(o, dirToLight, inf, seen);
                    ++localRays;
                    continue;
                }
                float sum = 0.0f;
                for (const glm::vec3& s : samples) {
                    glm::vec3 d = s - o;
                    float dist = glm::length(d);
                    ++localRays;
                    if (!(dist > 0.0f)) { // the origin is on the sample point: nothing in between
                        sum += 1.0f;
                        continue;
                    }
                    sum += traceSegment(o, d / dist, std::max(0.0f, dist - rayOffset), seen);
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
