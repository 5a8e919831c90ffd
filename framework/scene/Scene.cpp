#include "framework/scene/Scene.h"

#include "framework/core/Error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace shadowlab {

namespace {

/// The largest absolute coordinate of `b`: where its float precision is coarsest.
float farthestCoordinate(const Bounds& b) {
    return std::max({std::abs(b.min.x), std::abs(b.min.y), std::abs(b.min.z), std::abs(b.max.x), std::abs(b.max.y), std::abs(b.max.z)});
}

} // namespace

std::string floatPrecisionAt(const Bounds& b) {
    const float far = farthestCoordinate(b);
    char text[160];
    std::snprintf(text, sizeof text, "coordinates up to %.3g, where a float's spacing is %.3g", double(far),
                  double(std::nextafter(far, INFINITY) - far));
    return text;
}

std::string floatDistortion(const Bounds& b) {
    const glm::vec3 extent = b.extent();
    const float size = std::max({extent.x, extent.y, extent.z});
    const float far = farthestCoordinate(b);
    const float spacing = std::nextafter(far, INFINITY) - far;
    if (!(size > 0.0f && spacing > 0.01f * size)) return "";
    char text[160];
    std::snprintf(text, sizeof text, "%.3g units across, would be drawn distorted: ", double(size));
    char ratio[48];
    std::snprintf(ratio, sizeof ratio, ", %.3g %% of its size (at most 1 %%)", 100.0 * double(spacing) / double(size));
    return text + floatPrecisionAt(b) + ratio;
}

void Scene::addTriangles(const std::vector<glm::vec3>& tri, const Material& material) {
    uint32_t mat = static_cast<uint32_t>(materials.size());
    bool used = false;
    for (size_t i = 0; i + 2 < tri.size(); i += 3) {
        glm::vec3 n;
        if (!unitNormal(tri[i], tri[i + 1], tri[i + 2], n)) continue;
        positions.insert(positions.end(), {tri[i], tri[i + 1], tri[i + 2]});
        normals.push_back(n);
        materialIds.push_back(mat);
        for (int k = 0; k < 3; ++k) bounds.extend(tri[i + k]);
        used = true;
    }
    if (used) materials.push_back(material);
}

void Scene::append(const Scene& other, const glm::mat4& m) {
    uint32_t matBase = static_cast<uint32_t>(materials.size());
    materials.insert(materials.end(), other.materials.begin(), other.materials.end());
    // A mirroring transform flips the winding; keep normals consistent with the winding.
    bool mirrored = glm::determinant(glm::mat3(m)) < 0.0f;
    // Grow geometrically (at least doubling): appending many objects one by one stays linear.
    if (positions.capacity() < positions.size() + other.positions.size()) {
        const size_t want = std::max(positions.size() + other.positions.size(), 2 * positions.capacity());
        positions.reserve(want);
        normals.reserve(want / 3);
        materialIds.reserve(want / 3);
    }
    // Moving triangles are always kept (their local copies are what they are) and their parts
    // carried over with `m` composed onto their motion; they are posed at time 0 at the end.
    std::vector<int> partOf(other.triangleCount(), -1);
    for (size_t p = 0; p < other.moving.size(); ++p)
        std::fill_n(partOf.begin() + ptrdiff_t(other.moving[p].firstTriangle), other.moving[p].triangleCount, int(p));
    std::vector<size_t> partStart(other.moving.size(), 0);
    for (size_t t = 0; t < other.triangleCount(); ++t) {
        glm::vec3 v[3];
        for (int k = 0; k < 3; ++k) v[k] = glm::vec3(m * glm::vec4(other.positions[3 * t + k], 1.0f));
        if (mirrored) std::swap(v[1], v[2]);
        glm::vec3 n;
        const bool hasArea = unitNormal(v[0], v[1], v[2], n);
        const bool moves = partOf[t] >= 0;
        if (!moves && !hasArea) continue;
        if (moves && other.moving[size_t(partOf[t])].firstTriangle == t) partStart[size_t(partOf[t])] = triangleCount();
        positions.insert(positions.end(), {v[0], v[1], v[2]});
        normals.push_back(hasArea ? n : glm::vec3(0, 1, 0));
        materialIds.push_back(matBase + other.materialIds[t]);
        for (auto& p : v) {
            bounds.extend(p);
            if (!moves) staticBounds.extend(p);
        }
    }
    if (other.moving.empty()) return;
    for (size_t p = 0; p < other.moving.size(); ++p) {
        MovingPart part = other.moving[p];
        part.firstTriangle = partStart[p];
        MotionFn inner = part.worldFromLocal;
        part.worldFromLocal = [inner, m, file = part.sourceFile, path = part.sourcePath](double time) {
            const glm::mat4 r = m * inner(time);
            if (!isFinite(r))
                throw InputError(file, path, "the pose, placed by the transforms around it, overflows a float " + atTimeText(time));
            return r;
        };
        // Posed from its local copy with the composed matrix, exactly as every later frame is.
        const glm::mat4 rest = poseOf(part, 0.0);
        for (size_t i = 0; i < part.triangleCount; ++i) {
            const size_t t = part.firstTriangle + i;
            poseTriangle(rest, &part.local[3 * i], &positions[3 * t], normals[t]);
            for (int k = 0; k < 3; ++k) bounds.extend(positions[3 * t + size_t(k)]);
        }
        moving.push_back(std::move(part));
    }
}

void Scene::updateBounds() {
    bounds = Bounds{};
    for (const auto& p : positions) bounds.extend(p);
    staticBounds = Bounds{};
    for (auto [from, to] : staticRuns())
        for (size_t i = 3 * from; i < 3 * to; ++i) staticBounds.extend(positions[i]);
}

std::vector<std::pair<size_t, size_t>> Scene::staticRuns() const {
    std::vector<std::pair<size_t, size_t>> runs;
    size_t next = 0;  // triangles before moving[k] are static
    for (const MovingPart& part : moving) {
        if (part.firstTriangle > next) runs.emplace_back(next, part.firstTriangle);
        next = part.firstTriangle + part.triangleCount;
    }
    if (triangleCount() > next) runs.emplace_back(next, triangleCount());
    return runs;
}

size_t Scene::movingTriangleCount() const {
    size_t n = 0;
    for (const MovingPart& part : moving) n += part.triangleCount;
    return n;
}

glm::mat4 poseOf(const MovingPart& part, double time) {
    // The motions check themselves and name their own key or channel; this is the last guard, for
    // a motion function written without such checks: a NaN pose would make the part vanish.
    const glm::mat4 m = part.worldFromLocal(time);
    if (!isFinite(m)) throw InputError(part.sourceFile, part.sourcePath, "the moving object's pose is not finite " + atTimeText(time));
    return m;
}

std::vector<glm::mat4> Scene::poseAt(double time) const {
    std::vector<glm::mat4> pose;
    pose.reserve(moving.size());
    for (const MovingPart& part : moving) pose.push_back(poseOf(part, time));
    return pose;
}

void Scene::applyPose(const std::vector<glm::mat4>& pose) {
    for (size_t p = 0; p < moving.size(); ++p) {
        const MovingPart& part = moving[p];
        for (size_t i = 0; i < part.triangleCount; ++i) {
            const size_t t = part.firstTriangle + i;
            poseTriangle(pose[p], &part.local[3 * i], &positions[3 * t], normals[t]);
        }
    }
    updateBounds();
}

Bounds partBoundsAt(const MovingPart& part, const glm::mat4& m) {
    Bounds b;
    const glm::vec3 lo = part.localMin, hi = part.localMax;
    for (int c = 0; c < 8; ++c) {
        const glm::vec3 corner((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        b.extend(glm::vec3(m * glm::vec4(corner, 1.0f)));
    }
    return b;
}

std::string copyDistortion(const MovingPart& part, const glm::mat4& m) {
    if (part.copyBoxes.empty()) return "";
    // Every copy passes when the smallest could not be distorted at the part's farthest coordinate:
    // a box of largest side L keeps a side of at least sigma_min(M) L / sqrt(3) under M, and
    // 1 / |M^-1|_F bounds sigma_min(M) from below. Only a part that fails this is checked copy by copy.
    const float far = farthestCoordinate(partBoundsAt(part, m));
    const double spacing = double(std::nextafter(far, INFINITY) - far);
    float smallest = INFINITY;
    for (const auto& [lo, hi] : part.copyBoxes) {
        const glm::vec3 e = hi - lo;
        smallest = std::min(smallest, std::max({e.x, e.y, e.z}));
    }
    const glm::dmat3 inverse = glm::inverse(glm::dmat3(glm::mat3(m)));
    double frobenius = 0.0;
    for (int c = 0; c < 3; ++c) frobenius += glm::dot(inverse[c], inverse[c]);
    const double lower = double(smallest) / (std::sqrt(frobenius) * std::sqrt(3.0));
    if (std::isfinite(lower) && spacing <= 0.01 * lower) return "";
    for (size_t i = 0; i < part.copyBoxes.size(); ++i) {
        MovingPart copy;
        copy.localMin = part.copyBoxes[i].first, copy.localMax = part.copyBoxes[i].second;
        if (const std::string why = floatDistortion(partBoundsAt(copy, m)); !why.empty())
            return "copy " + std::to_string(i + 1) + " of the grid's " + std::to_string(part.copyBoxes.size()) +
                   " (its innermost object), " + why;
    }
    return "";
}

Bounds Scene::boundsAt(const std::vector<glm::mat4>& pose) const {
    Bounds b = staticBounds;
    for (size_t p = 0; p < moving.size(); ++p) b.extend(partBoundsAt(moving[p], pose[p]));
    return b;
}

glm::dvec2 Scene::motionTimeRange() const {
    if (moving.empty()) return {0, 0};
    glm::dvec2 r(moving.front().startTime, moving.front().endTime);
    for (const MovingPart& part : moving) r = {std::min(r.x, part.startTime), std::max(r.y, part.endTime)};
    return r;
}

void Scene::attachMotion(const MotionFn& motion, double startTime, double endTime, const std::string& sourceFile,
                         const std::string& sourcePath) {
    std::vector<MovingPart> parts;
    for (auto [from, to] : staticRuns()) {
        MovingPart part;
        part.firstTriangle = from;
        part.triangleCount = to - from;
        part.setLocal({positions.begin() + ptrdiff_t(3 * from), positions.begin() + ptrdiff_t(3 * to)});
        part.worldFromLocal = motion;
        part.sourceFile = sourceFile;
        part.sourcePath = sourcePath;
        part.startTime = startTime;
        part.endTime = endTime;
        parts.push_back(std::move(part));
    }
    for (MovingPart& part : moving) {
        part.worldFromLocal = composeMotion(motion, part.worldFromLocal, sourceFile, sourcePath);
        part.startTime = std::min(part.startTime, startTime);
        part.endTime = std::max(part.endTime, endTime);
        parts.push_back(std::move(part));
    }
    std::sort(parts.begin(), parts.end(),
              [](const MovingPart& a, const MovingPart& b) { return a.firstTriangle < b.firstTriangle; });
    moving = std::move(parts);
    applyPose(poseAt(0.0));
}

size_t Scene::bytes() const {
    size_t b = positions.capacity() * sizeof(glm::vec3) + normals.capacity() * sizeof(glm::vec3) +
               materialIds.capacity() * sizeof(uint32_t) + materials.capacity() * sizeof(Material);
    for (const MovingPart& p : moving) b += p.local.capacity() * sizeof(glm::vec3);
    return b;
}

uint64_t Scene::contentHash() const {
    // FNV-1a over the raw bytes: stable across runs and platforms of the same endianness.
    uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* data, size_t n) {
        const auto* b = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    };
    mix(positions.data(), positions.size() * sizeof(glm::vec3));
    mix(materialIds.data(), materialIds.size() * sizeof(uint32_t));
    mix(materials.data(), materials.size() * sizeof(Material));
    // Which triangles move changes what may be precomputed over them (clusters never span parts).
    for (const MovingPart& part : moving) {
        mix(&part.firstTriangle, sizeof part.firstTriangle);
        mix(&part.triangleCount, sizeof part.triangleCount);
    }
    return h;
}

} // namespace shadowlab
