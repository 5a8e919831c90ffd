#include "framework/scene/Motion.h"

#include "framework/core/JsonParse.h"
#include "framework/core/Spline.h"
#include "framework/scene/TriangleNormal.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace shadowlab {

glm::mat4 composeTransform(glm::vec3 translate, glm::vec3 rotateDeg, glm::vec3 scale) {
    glm::vec3 rot = glm::radians(rotateDeg);
    glm::mat4 r = glm::rotate(glm::mat4(1.0f), rot.z, {0, 0, 1}) * glm::rotate(glm::mat4(1.0f), rot.y, {0, 1, 0}) *
                  glm::rotate(glm::mat4(1.0f), rot.x, {1, 0, 0});
    return glm::translate(glm::mat4(1.0f), translate) * r * glm::scale(glm::mat4(1.0f), scale);
}

glm::vec3 readScale(JsonNode& node) {
    // A number or three numbers; JsonNode has no getter for "either", so dispatch on the type.
    const Json* raw = node.has("scale") ? &node.raw().at("scale") : nullptr;
    if (!raw || raw->is_number()) return glm::vec3(float(node.getFloat("scale", 1.0)));
    if (!raw->is_array()) node.fail("scale", "expected a number or an array of 3 numbers, got " + shortDump(*raw));
    return node.getVec3("scale", glm::vec3(1.0f));
}

bool isFinite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

bool isFinite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string atTimeText(double time) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "at time %.6g s", time);
    return buf;
}

RigidPath::RigidPath(std::vector<RigidKey> keys, Interpolation interpolation)
    : keys_(std::move(keys)), interpolation_(interpolation) {}

glm::mat4 RigidPath::at(double time) const {
    if (keys_.empty()) return glm::mat4(1.0f);
    auto fail = [&](const std::string& what) {
        throw InputError(file, jsonPath, what + " " + atTimeText(time));
    };
    auto pose = [&](const RigidKey& k) {
        const glm::mat4 m = composeTransform(k.translate, k.rotateDeg, k.scale);
        if (!isFinite(m)) fail("the path's pose matrix is not finite");
        return m;
    };
    if (keys_.size() == 1 || !(time > keys_.front().time)) return pose(keys_.front());
    if (time >= keys_.back().time) return pose(keys_.back());
    auto it = std::upper_bound(keys_.begin(), keys_.end(), time, [](double t, const RigidKey& k) { return t < k.time; });
    size_t i1 = size_t(it - keys_.begin()) - 1, i2 = i1 + 1;
    if (interpolation_ == Interpolation::Step) return pose(keys_[i1]);
    // In double: keys near the float limit (a scale of 3e38) overflow a float spline's weighted sums
    // into inf - inf = NaN. What does not fit a float afterwards is bad input, never a NaN pose.
    const double u = (time - keys_[i1].time) / (keys_[i2].time - keys_[i1].time);
    auto toFloat = [&](glm::dvec3 v, const char* what) {
        for (int a = 0; a < 3; ++a)
            if (!(std::abs(v[a]) <= double(std::numeric_limits<float>::max())))
                fail(std::string("the path's interpolated ") + what + " is not finite in float range (" +
                     (interpolation_ == Interpolation::CatmullRom ? "the catmull_rom spline through its keys overshoots; "
                                                                    "use \"linear\" or keys of nearer values"
                                                                  : "check its keys") + ")");
        return glm::vec3(v);
    };
    RigidKey k;
    glm::dvec3 t, r, sc;
    if (interpolation_ == Interpolation::Linear) {
        t = glm::mix(glm::dvec3(keys_[i1].translate), glm::dvec3(keys_[i2].translate), u);
        r = glm::mix(glm::dvec3(keys_[i1].rotateDeg), glm::dvec3(keys_[i2].rotateDeg), u);
        sc = glm::mix(glm::dvec3(keys_[i1].scale), glm::dvec3(keys_[i2].scale), u);
    } else {
        size_t i0 = i1 == 0 ? 0 : i1 - 1, i3 = std::min(i2 + 1, keys_.size() - 1);
        auto spline = [&](glm::vec3 RigidKey::*member) {
            return catmullRom(glm::dvec3(keys_[i0].*member), glm::dvec3(keys_[i1].*member), glm::dvec3(keys_[i2].*member),
                              glm::dvec3(keys_[i3].*member), u);
        };
        t = spline(&RigidKey::translate);
        r = spline(&RigidKey::rotateDeg);
        sc = spline(&RigidKey::scale);
        // A spline through positive scales can dip below zero between them; a scale is never mirrored here.
        // (glm::max would pass a NaN through silently; toFloat below refuses it.)
        const glm::dvec3 floor = 1e-6 * glm::min(glm::dvec3(keys_[i1].scale), glm::dvec3(keys_[i2].scale));
        for (int a = 0; a < 3; ++a)
            if (sc[a] < floor[a]) sc[a] = floor[a];
    }
    k.translate = toFloat(t, "translate");
    k.rotateDeg = toFloat(r, "rotate_deg");
    k.scale = toFloat(sc, "scale");
    return pose(k);
}

RigidPath RigidPath::parse(JsonNode node) {
    Interpolation interp = Interpolation::CatmullRom;
    std::string name = node.getEnum("interpolation", "catmull_rom", {"catmull_rom", "linear", "step"});
    if (name == "linear") interp = Interpolation::Linear;
    if (name == "step") interp = Interpolation::Step;
    std::vector<RigidKey> keys;
    for (JsonNode& k : node.objectArray("keyframes")) {
        RigidKey key;
        if (!k.has("time")) k.fail("time", "required key is missing");
        key.time = k.getFloat("time", 0);
        key.translate = k.getPoint("translate", glm::vec3(0.0f));
        key.rotateDeg = k.getVec3("rotate_deg", glm::vec3(0.0f));
        if (glm::any(glm::greaterThan(glm::abs(key.rotateDeg), glm::vec3(1e6f))))
            k.fail("rotate_deg", "angles must lie within ±1e6 degrees (float precision)");
        key.scale = readScale(k);
        if (!glm::all(glm::greaterThan(key.scale, glm::vec3(0.0f))))
            k.fail("scale", "path scales must be greater than 0 (mirror the object in its \"transform\")");
        if (!keys.empty() && key.time <= keys.back().time)
            k.fail("time", "keyframe times must increase strictly (previous is " + std::to_string(keys.back().time) + ")");
        k.finish();
        keys.push_back(key);
    }
    if (keys.empty()) node.fail("keyframes", "a path needs at least one keyframe");
    node.finish();
    RigidPath path(std::move(keys), interp);
    path.file = node.file();
    path.jsonPath = node.path();
    return path;
}

MotionFn RigidPath::motion() const {
    return [path = *this](double time) { return path.at(time); };
}

MotionFn composeMotion(MotionFn outer, MotionFn inner, std::string file, std::string jsonPath) {
    return [outer = std::move(outer), inner = std::move(inner), file = std::move(file), jsonPath = std::move(jsonPath)](double time) {
        const glm::mat4 m = outer(time) * inner(time);
        if (!isFinite(m))
            throw InputError(file, jsonPath,
                             "the pose composed with the motion inside this object overflows a float " + atTimeText(time));
        return m;
    };
}

void MovingPart::setCopies(size_t trianglesPerCopy) {
    copyBoxes.clear();
    if (trianglesPerCopy == 0 || triangleCount <= trianglesPerCopy || triangleCount % trianglesPerCopy != 0 ||
        local.size() != 3 * triangleCount)
        return;
    for (size_t first = 0; first < local.size(); first += 3 * trianglesPerCopy) {
        glm::vec3 lo = local[first], hi = local[first];
        for (size_t v = first; v < first + 3 * trianglesPerCopy; ++v) lo = glm::min(lo, local[v]), hi = glm::max(hi, local[v]);
        copyBoxes.emplace_back(lo, hi);
    }
}

void MovingPart::setLocal(std::vector<glm::vec3> vertices) {
    local = std::move(vertices);
    localMin = glm::vec3(0.0f), localMax = glm::vec3(0.0f);
    if (local.empty()) return;
    localMin = localMax = local.front();
    // Not glm::min / glm::max, which drop a NaN operand: a NaN vertex must show in the box.
    for (const glm::vec3& v : local)
        for (int a = 0; a < 3; ++a) {
            if (std::isnan(v[a]) || std::isnan(localMin[a])) localMin[a] = localMax[a] = std::nanf("");
            else localMin[a] = std::min(localMin[a], v[a]), localMax[a] = std::max(localMax[a], v[a]);
        }
}

void poseTriangle(const glm::mat4& m, const glm::vec3* local, glm::vec3* out, glm::vec3& normal) {
    for (int k = 0; k < 3; ++k) out[k] = glm::vec3(m * glm::vec4(local[k], 1.0f));
    if (glm::determinant(glm::mat3(m)) < 0.0f) std::swap(out[1], out[2]);
    if (!unitNormal(out[0], out[1], out[2], normal)) normal = glm::vec3(0, 1, 0);
}

} // namespace shadowlab
