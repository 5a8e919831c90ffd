#pragma once
// The scene as every algorithm sees it: one world-space triangle soup with per-triangle normals
// and materials, plus bounds. Built once from the config (glTF files and procedural generators).
// Some triangle ranges may move rigidly (MovingPart); their positions here are the rest pose, the
// pose at time 0, and SceneGpu poses them per frame.
#include "framework/scene/Motion.h"
#include "framework/scene/TriangleNormal.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

struct Material {
    glm::vec3 albedo{0.8f};  ///< diffuse reflectance, linear RGB in [0, 1]
    float opacity = 1.0f;    ///< 1 = opaque caster; < 1 lets light through ("x-ray" casters), in [0, 1]
};

/// An axis-aligned box. extend() keeps a NaN: glm::min / glm::max (and std::min) return the other
/// operand when one is NaN, so a posed point that became NaN would silently vanish from the box and
/// every range check on it would pass. Here a NaN coordinate makes the box NaN, which finite() and
/// any `!(|x| <= limit)` check catch.
struct Bounds {
    glm::vec3 min{1e30f}, max{-1e30f};
    void extend(glm::vec3 p) {
        for (int a = 0; a < 3; ++a) min[a] = lowest(min[a], p[a]), max[a] = highest(max[a], p[a]);
    }
    void extend(const Bounds& b) {
        for (int a = 0; a < 3; ++a) min[a] = lowest(min[a], b.min[a]), max[a] = highest(max[a], b.max[a]);
    }
    /// Every coordinate of both corners is finite (an empty box counts as finite).
    bool finite() const {
        for (int a = 0; a < 3; ++a)
            if (!std::isfinite(min[a]) || !std::isfinite(max[a])) return false;
        return true;
    }
    bool empty() const { return min.x > max.x; }
    glm::vec3 center() const { return 0.5f * (min + max); }
    glm::vec3 extent() const { return max - min; }
    float radius() const { return 0.5f * glm::length(max - min); } ///< of the bounding sphere around center()

private:
    static float lowest(float a, float b) { return std::isnan(a) || std::isnan(b) ? std::nanf("") : (b < a ? b : a); }
    static float highest(float a, float b) { return std::isnan(a) || std::isnan(b) ? std::nanf("") : (b > a ? b : a); }
};

/// "" when what lies in `b` keeps its shape in float (a float's spacing at its farthest coordinate
/// at most 1 % of its size); else why not, as "N units across, would be drawn distorted: ...".
std::string floatDistortion(const Bounds& b);
/// "coordinates up to X, where a float's spacing is Y" for what lies in `b`.
std::string floatPrecisionAt(const Bounds& b);

/// One part's world matrix at `time`, checked as poseAt() checks it.
glm::mat4 poseOf(const MovingPart& part, double time);
/// A box around `part`'s triangles posed by `m`: its local box's corners under `m`.
Bounds partBoundsAt(const MovingPart& part, const glm::mat4& m);
/// floatDistortion() of the first of a grid part's copies (MovingPart::copyBoxes) that the pose `m`
/// would draw distorted, named "copy I of the grid's N (its innermost object), ..."; "" when none.
std::string copyDistortion(const MovingPart& part, const glm::mat4& m);

/// Bytes a triangle takes in a Scene (3 positions 36, normal 12, material id 4), and in SceneGpu
/// (positions 36, normal + material 16), which a software renderer keeps in host memory too.
constexpr size_t kSceneBytesPerTriangle = 52;
constexpr size_t kSceneGpuBytesPerTriangle = 52;
/// Bytes a moving triangle adds in SceneGpu: its three local vertices (vec4 each) and its index.
constexpr size_t kMovingGpuBytesPerTriangle = 3 * 16 + 8;
/// The least a triangle costs a run: the scene on the host and on the GPU, nothing else.
constexpr size_t kMinBytesPerTriangle = kSceneBytesPerTriangle + kSceneGpuBytesPerTriangle;

/// A triangle soup in world space: triangle i has vertices positions[3i..3i+2].
struct Scene {
    std::vector<glm::vec3> positions;     ///< 3 per triangle
    std::vector<glm::vec3> normals;       ///< 1 per triangle, unit length (geometric, from the winding)
    std::vector<uint32_t> materialIds;    ///< 1 per triangle, index into materials
    std::vector<Material> materials;
    Bounds bounds;            ///< of every triangle as posed in `positions`
    Bounds staticBounds;      ///< of the triangles outside moving parts
    std::vector<MovingPart> moving; ///< disjoint, by increasing firstTriangle
    bool hasTimeRange = false;       ///< the config's "time_range": the clock the frames sample
    glm::dvec2 timeRange{0.0};

    size_t triangleCount() const { return normals.size(); }
    /// Host bytes the scene holds (capacities, moving parts' object-space copies included).
    size_t bytes() const;
    bool dynamic() const { return !moving.empty(); }
    size_t movingTriangleCount() const;
    /// The ranges [from, to) of triangles outside every moving part, in order.
    std::vector<std::pair<size_t, size_t>> staticRuns() const;
    /// Each moving part's world matrix at `time`; InputError (naming where the motion was given and
    /// the time) when one is not finite.
    std::vector<glm::mat4> poseAt(double time) const;
    /// Rewrites the moving parts' positions and normals for `pose` (poseAt()), and the bounds.
    void applyPose(const std::vector<glm::mat4>& pose);
    /// The bounds with the parts at `pose`: the static bounds joined with each part's local box
    /// under its matrix (a box around the posed triangles, cheap enough for every frame).
    Bounds boundsAt(const std::vector<glm::mat4>& pose) const;
    /// [start, end] of all motion (both 0 for a static scene).
    glm::dvec2 motionTimeRange() const;
    /// Turns every triangle outside a moving part into parts moving with `motion` (their current
    /// positions are their local ones) and composes `motion` onto the existing parts; then poses
    /// the scene at time 0.
    /// `sourceFile` and `sourcePath` name the motion (a config's path) in errors about its poses.
    void attachMotion(const MotionFn& motion, double startTime, double endTime, const std::string& sourceFile = {},
                      const std::string& sourcePath = {});

    /// Appends triangles (already in world space) using `material`; degenerate triangles
    /// (zero area) are dropped since they cast no shadow and have no normal.
    void addTriangles(const std::vector<glm::vec3>& triPositions, const Material& material);
    /// Appends another scene, transformed by `m`.
    void append(const Scene& other, const glm::mat4& m);
    /// Recomputes bounds (and staticBounds) from positions.
    void updateBounds();
    /// A 64-bit content hash (positions and materials), for on-disk caches keyed by scene content.
    uint64_t contentHash() const;
};

} // namespace shadowlab
