#include "framework/experiment/LightClearance.h"

#include "framework/algorithm/SharedParams.h"
#include "framework/core/Error.h"
#include "framework/scene/Motion.h"
#include "framework/scene/Scene.h"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace shadowlab {

namespace {

using dvec3 = glm::dvec3;

/// The clearance in ray offsets. The offset is at least 64 float steps of the scene's largest
/// coordinate (rayOffsetLength()); a quarter more, 16 steps, stays above the rounding of a hit's
/// distance and of the ray's end, which are a few steps each.
constexpr double kClearance = 1.25;

/// The point of triangle (a, b, c) nearest to p (the Voronoi-region walk of Ericson, Real-Time
/// Collision Detection 5.1.5), in double so that a light 1e-7 from a surface at 1e5 is measured.
dvec3 nearestOnTriangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
    const dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    const dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

/// Whether p lies within `r` of the box (a cheap test before the exact distance).
bool nearBox(dvec3 p, const Bounds& b, double r) {
    for (int k = 0; k < 3; ++k)
        if (p[k] < double(b.min[k]) - r || p[k] > double(b.max[k]) + r) return false;
    return true;
}

struct Closest {
    double distance = std::numeric_limits<double>::infinity();
    size_t triangle = 0;
    dvec3 point{0.0};
};

void consider(dvec3 light, const glm::vec3* v, size_t triangle, double r, Closest& closest) {
    Bounds box;
    for (int k = 0; k < 3; ++k) box.extend(v[k]);
    if (!nearBox(light, box, r)) return;
    const dvec3 q = nearestOnTriangle(light, dvec3(v[0]), dvec3(v[1]), dvec3(v[2]));
    const double d = glm::length(light - q);
    if (d < closest.distance) closest = {d, triangle, q};
}

/// The static triangles in runs of kChunk, each with its box, and the runs in groups of kGroup with
/// theirs: a light far from a box skips what it holds (a moving light over 74 M static triangles
/// tests 18,000 group boxes a frame).
struct StaticChunks {
    static constexpr size_t kChunk = 64, kGroup = 64;
    std::vector<std::pair<size_t, size_t>> ranges;
    std::vector<Bounds> boxes, groupBoxes;
    explicit StaticChunks(const Scene& s) {
        for (auto [from, to] : s.staticRuns())
            for (size_t i = from; i < to; i += kChunk) {
                const size_t end = std::min(to, i + kChunk);
                Bounds b;
                for (size_t k = 3 * i; k < 3 * end; ++k) b.extend(s.positions[k]);
                ranges.emplace_back(i, end);
                boxes.push_back(b);
            }
        for (size_t g = 0; g < boxes.size(); g += kGroup) {
            Bounds b;
            for (size_t k = g; k < std::min(boxes.size(), g + kGroup); ++k) b.extend(boxes[k]);
            groupBoxes.push_back(b);
        }
    }
    template <class Fn> void near(dvec3 p, double r, Fn&& visit) const {
        for (size_t g = 0; g < groupBoxes.size(); ++g) {
            if (!nearBox(p, groupBoxes[g], r)) continue;
            for (size_t k = g * kGroup; k < std::min(boxes.size(), (g + 1) * kGroup); ++k)
                if (nearBox(p, boxes[k], r)) visit(ranges[k].first, ranges[k].second);
        }
    }
};

/// The largest ray offset (in scene radii) of the reference and the exact algorithms.
double largestRayOffset(const ExperimentConfig& c) {
    double offset = c.reference ? rayOffsetOf(c.referenceEntry.params) : 0.0;
    for (const AlgorithmEntry& e : c.algorithms)
        if (e.info->exact) offset = std::max(offset, rayOffsetOf(e.params));
    return offset;
}

std::string number(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", x);
    return text;
}

} // namespace

void checkLightClearance(const ExperimentConfig& c) {
    if (!c.scene || (c.light.type != LightType::Point && c.light.type != LightType::Spot)) return;
    bool compared = c.reference;
    for (const AlgorithmEntry& e : c.algorithms) compared = compared || e.info->exact;
    if (!compared) return;
    const Scene& scene = *c.scene;
    const double offset = largestRayOffset(c);
    const StaticChunks chunks(scene);
    const bool changes = !c.lightPath.empty() || scene.dynamic();
    for (int f = 0;; ++f) {  // every frame, as checkPoses() visits them
        std::vector<glm::mat4> pose;
        if (scene.dynamic()) pose = scene.poseAt(c.sceneTimeAt(f));  // checked finite by checkPoses()
        const Bounds bounds = scene.dynamic() ? scene.boundsAt(pose) : scene.bounds;
        const double clearance = kClearance * double(rayOffsetLength(float(offset), bounds));
        const dvec3 light(c.lightAt(f).position);
        Closest closest;
        chunks.near(light, clearance, [&](size_t from, size_t to) {
            for (size_t i = from; i < to; ++i) consider(light, &scene.positions[3 * i], i, clearance, closest);
        });
        for (size_t p = 0; p < scene.moving.size(); ++p) {
            const MovingPart& part = scene.moving[p];
            if (!nearBox(light, partBoundsAt(part, pose[p]), clearance)) continue;
            for (size_t i = 0; i < part.triangleCount; ++i) {
                glm::vec3 v[3], n;
                poseTriangle(pose[p], &part.local[3 * i], v, n);
                consider(light, v, part.firstTriangle + i, clearance, closest);
            }
        }
        if (closest.distance < clearance)
            throw InputError(c.file, c.lightPath.empty() ? "/light/position" : "/light/path",
                             "the light is " + number(closest.distance) + " from triangle " + std::to_string(closest.triangle) +
                                 " (nearest point [" + number(closest.point.x) + ", " + number(closest.point.y) + ", " +
                                 number(closest.point.z) + "]) at " + frameText(c, f) + ": keep it 1.25 x the ray offset (" +
                                 number(clearance / kClearance) + ") from every surface or lower ray_offset (the "
                                 "shadow rays and the shadow volumes meet at the light, and the exact algorithms are compared "
                                 "with the reference only where nothing lies that near it)");
        if (!changes || f == c.frames - 1) break;
    }
}

} // namespace shadowlab
