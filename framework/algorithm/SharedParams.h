#pragma once
// Parameter rows that several algorithms share, declared once: the same key, default, range, unit
// and meaning wherever they appear, so configs, the GUI and results compare like with like.
#include "framework/core/Params.h"
#include "framework/render/SceneGpu.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace shadowlab {

/// Default of ray_offset, in scene radii: 1e-4 of the radius clears the float error of the
/// G-buffer positions without visibly detaching contact shadows, at any scene scale.
constexpr double kDefaultRayOffset = 1e-4;

/// `ray_offset`: the shadow query point (the reference's ray origin) is the G-buffer point moved
/// this far along its normal. Every algorithm that has it uses the reference's definition, so an
/// algorithm and the reference trace from the same points and only their tests differ.
template <class T> auto rayOffsetRow(float T::*member) {
    return [member](ParamStruct<T>& s) {
        s.real("ray_offset", member, kDefaultRayOffset, 0.0, 1e-2, "× scene radius",
               "shadow query point (ray origin) offset along the surface normal, against self-shadowing", ParamChange::Update);
    };
}

/// The float steps of the scene's largest coordinate that the ray offset never falls below. A
/// G-buffer point is interpolated from those coordinates and lies off its own triangle's plane by a
/// few of their steps; an origin moved less than that along the normal can land behind its own
/// triangle, where the reference's ray and an algorithm's test of the same triangle may round the
/// other way (far from the origin, where a scene's coordinates are large beside its radius).
constexpr float kRayOffsetFloatSteps = 64.0f;

/// The ray offset in scene units: `offset` radii of the scene `b` as currently posed (1 for an empty
/// scene), and at least kRayOffsetFloatSteps float steps of its largest coordinate. Every algorithm
/// and the reference read it per frame, so all trace from the same points even as parts move.
inline float rayOffsetLength(float offset, const Bounds& b) {
    if (b.empty()) return offset;
    const glm::vec3 largest = glm::max(glm::abs(b.min), glm::abs(b.max));
    const float magnitude = std::max(largest.x, std::max(largest.y, largest.z));
    return std::max(offset * b.radius(), kRayOffsetFloatSteps * std::ldexp(magnitude, -23));
}
inline float rayOffsetLength(float offset, const SceneGpu& scene) { return rayOffsetLength(offset, scene.bounds()); }

/// `stack_size`: a fixed-size traversal stack, compiled into the shader. Overflow is never silent:
/// the pixel (or ray) is written shadowed (blocked) and counted in the overflow.
template <class T> auto stackSizeRow(int T::*member, int def) {
    return [member, def](ParamStruct<T>& s) {
        s.integer("stack_size", member, def, 1, 256, "nodes",
                  "traversal stack; a pixel or ray that overflows it is written shadowed and counted as overflow",
                  ParamChange::Recompile);
    };
}

/// `samples_per_dispatch`: the most light samples per pixel one compute dispatch traces. A frame
/// with more (an area light's samples) runs ceil(samples / this) dispatches over the image, each
/// adding its samples to a per-pixel accumulation image; the last writes visibility, bit-identical
/// to a single dispatch. A GPU driver kills a dispatch that runs past its watchdog (about 2 s on
/// Windows), and an area light's 1,024 samples at 4K in one dispatch would; each algorithm's
/// default keeps one dispatch far under it (the arithmetic is on its page in docs/algorithms/).
/// 1,024 is the most samples a light may have (configlimits::kAreaSamplesMax).
template <class T> auto samplesPerDispatchRow(int T::*member, int def) {
    return [member, def](ParamStruct<T>& s) {
        s.integer("samples_per_dispatch", member, def, 1, 1024, "samples",
                  "most light samples per pixel traced by one compute dispatch; more samples take several "
                  "dispatches (same image), so none runs into a GPU driver's watchdog",
                  ParamChange::Update);
    };
}

/// `cache`: reuse the algorithm's per-scene preprocessing from the disk cache
/// ($XDG_CACHE_HOME or ~/.cache, /shadowlab/<folder>), keyed and checked by the scene's content.
template <class T> auto cacheRow(bool T::*member, const std::string& folder) {
    return [member, folder](ParamStruct<T>& s) {
        s.boolean("cache", member, true,
                  "reuse the preprocessing from the disk cache ($XDG_CACHE_HOME or ~/.cache /shadowlab/" + folder +
                      "), keyed by the scene's content",
                  ParamChange::Rebuild);
    };
}

/// The ray offset of an algorithm's values (kDefaultRayOffset where its schema has no such row):
/// the tests trace the reference from the algorithm's own query points.
inline double rayOffsetOf(const ParamValues& values) {
    const ParamSchema* s = values.schema();
    return s && s->find("ray_offset") ? std::get<double>(values.get("ray_offset")) : kDefaultRayOffset;
}

} // namespace shadowlab
