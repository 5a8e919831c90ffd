#pragma once
// CPU ray tracer (Embree 3) that computes the ground-truth visibility of every experiment.
// GL-free, so the tests can run it on synthetic G-buffers without a context.
//
// Ground-truth convention (every algorithm is measured against exactly this):
//   For each pixel i of the G-buffer:
//   * background (not covered)                               → visibility 1 (nothing to shadow).
//   * !light.reaches(p, n) (outside a spot cone, behind an
//     area light's plane, or n facing away from the light
//     or its centre; n is the camera-facing normal; decided
//     by the same float operations as the shaders' lightReaches) → visibility 0 (unlit by geometry;
//                                                                the metrics ignore such pixels).
//   * otherwise, for each sample point s of light.samplePoints() (a single point for point and spot
//     lights; for a directional light one ray along -direction() with tfar = +inf), one occlusion
//     ray from o = p + n * rayOffset (rounded as the shaders round it: Watertight.h): to a point or
//     spot light the segment o + t (s - o), t in (0, 1] (validate keeps every surface 1.25 ray
//     offsets from such a light, so nothing lies at its end); to an area light's sample, unit
//     direction, t in (0, |s - o| - rayOffset] (an area light may sit on a surface). Each triangle
//     is decided by the shaders' own watertight test (Watertight.h, common/watertight.glsl), so
//     that the GPU algorithms and the reference agree on every ray–triangle pair, ties included;
//     Embree's BVH only finds the candidates. Visibility = mean over the samples of the
//     sample's transmission: 1 unoccluded, 0 blocked by an opaque triangle, and for scenes with
//     transparent materials the product of (1 - opacity) over the distinct surface crossings:
//     a triangle reported twice counts once, and so do
//     hits at the same distance (relative 1e-5, kSameHitDistance) on different triangles, which
//     are one surface crossed exactly at a shared edge or vertex (otherwise the diagonal of every
//     transparent quad would cast a darker line). A product below kOpaqueTransmission counts as 0
//     and stops the ray.
//   The result is deterministic and independent of the thread count (pixels are independent).
#include "framework/render/GBuffer.h"
#include "framework/scene/Scene.h"
#include "framework/view/Light.h"

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace shadowlab {

class EmbreeTracer {
public:
    /// Transmission below which a ray counts as fully blocked (and Embree may stop traversal).
    static constexpr float kOpaqueTransmission = 1e-6f;
    /// Relative distance under which two transparent hits are one surface crossing (see above).
    static constexpr float kSameHitDistance = 1e-5f;

    /// Builds the BVH (RTC_BUILD_QUALITY_HIGH) over a copy of the scene's triangles, so the tracer
    /// does not depend on the Scene's lifetime. Throws RuntimeError when Embree fails (e.g. out of memory).
    explicit EmbreeTracer(const Scene& scene);
    /// How moveTriangles() updates the BVH of a scene whose parts move.
    enum class MotionUpdate { Refit, Rebuild };
    /// As above; for a scene with moving parts the BVH is built to be updated (RTC_SCENE_FLAG_DYNAMIC):
    /// by refitting its boxes (RTC_BUILD_QUALITY_REFIT: fast, the tree's quality degrades as parts
    /// travel) or by a full rebuild.
    EmbreeTracer(const Scene& scene, MotionUpdate update);
    /// How the tracer holds the vertices. Copy: its own (the Scene may go away). Share: a static
    /// scene's Scene::positions are read in place, no second copy (36 bytes a triangle); the Scene
    /// must then outlive the tracer and not change.
    enum class Vertices { Copy, Share };
    /// `compact`: Embree's memory-conservative node layout (RTC_SCENE_FLAG_COMPACT), for scenes
    /// whose BVH would crowd memory.
    EmbreeTracer(const Scene& scene, MotionUpdate update, Vertices vertices, bool compact = false);
    /// Whether the vertices are the Scene's own (Vertices::Share took effect).
    bool sharesVertices() const { return sharesVertices_; }
    ~EmbreeTracer();
    EmbreeTracer(const EmbreeTracer&) = delete;
    EmbreeTracer& operator=(const EmbreeTracer&) = delete;

    /// Visibility per pixel of `g` (width * height values, row-major) by the convention above.
    /// `threads` = 0: threadsFor(0, pixels). Resizes `visibility`.
    void traceVisibility(const CpuGBuffer& g, const Light& light, float rayOffset, int threads,
                         std::vector<float>& visibility) const;

    /// Whether any triangle (whatever its opacity) lies on the segment origin + t * dir, t in (0, tfar],
    /// by the shaders' watertight test.
    bool occluded(glm::vec3 origin, glm::vec3 dir, float tfar) const;
    /// Fraction of light passing along the segment: product of (1 - opacity) of the distinct triangles
    /// crossed (0 or 1 in opaque scenes). `dir` need not be unit length; t is in units of |dir|.
    float transmission(glm::vec3 origin, glm::vec3 dir, float tfar) const;

    /// Replaces the vertices of triangles [firstTriangle, firstTriangle + count) (3 per triangle);
    /// commitMoves() then updates the BVH once for all moves.
    void moveTriangles(size_t firstTriangle, const glm::vec3* positions, size_t count);
    void commitMoves();

    /// The threads a frame of `pixels` is traced on: `requested` when positive; for 0, one per
    /// kPixelsPerThread pixels, at most the hardware's threads. Threads are started for each
    /// frame, and on a shared machine the join waits for the latest of them: a small frame traced
    /// on every hardware thread was slower and noisier than on one (results/reference/
    /// compare_noise_llvmpipe.md).
    static int threadsFor(int requested, size_t pixels);
    static constexpr size_t kPixelsPerThread = 65536;

    /// Rays cast by the last traceVisibility() call.
    uint64_t lastRayCount() const { return lastRays_; }
    /// Whether some material has opacity < 1 (the slower filtered path is used).
    bool hasTransparency() const { return transparent_; }
    size_t triangleCount() const { return triangleCount_; }

    /// Bytes Embree holds for this scene: measured with Embree's device memory monitor
    /// (rtcSetDeviceMemoryMonitorFunction counts every allocation of the device: the vertex and
    /// index buffers and the BVH nodes), plus the per-triangle material copy kept for the filter.
    /// Embree 3 has no device property reporting BVH size, hence the monitor.
    size_t memoryBytes() const;

    /// A transparent hit already multiplied into a ray's transmission (for the filter function).
    struct CountedHit {
        unsigned prim;
        float t;
    };

private:
    struct DeviceState;
    /// Transmission along one segment; `seen` is the caller's scratch list (reused across rays).
    float traceSegment(glm::vec3 origin, glm::vec3 dir, float tfar, std::vector<CountedHit>& seen) const;

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    RTCGeometry geometry_ = nullptr; ///< the one user geometry of triangles (owned by scene_)
    std::vector<glm::vec3> ownVertices_; ///< the copy, unless the Scene's are shared
    const glm::vec3* vertices_ = nullptr; ///< 3 per triangle: the Scene's or ownVertices_
    size_t triangleCount_ = 0;
    bool transparent_ = false;
    bool sharesVertices_ = false;
    std::vector<uint32_t> materialIds_;   ///< only when transparent_: primID → material
    std::vector<float> materialTransmit_; ///< 1 - opacity per material
    // Memory counter and last error of the device: heap-allocated so the pointer handed to
    // Embree's callbacks stays valid whatever happens to this object.
    std::unique_ptr<DeviceState> state_;
    mutable uint64_t lastRays_ = 0;
};

} // namespace shadowlab
