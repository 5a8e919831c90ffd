#include "framework/scene/Motion.h"

#include "framework/core/JsonParse.h"
#include "framework/core/Spline.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
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

RigidPath::RigidPath(std::vector<RigidKey> keys, Interpolation interpolation)
    : keys_(std::move(keys)), interpolation_(interpolation) {}

glm::mat4 RigidPath::at(double time) const {
    if (keys_.empty()) return glm::mat4(1.0f);
    auto pose = [](const RigidKey& k) { return composeTransform(k.translate, k.rotateDeg, k.scale); };
    if (keys_.size() == 1 || time <= keys_.front().time) return pose(keys_.front());
    if (time >= keys_.back().time) return pose(keys_.back());
    auto it = std::upper_bound(keys_.begin(), keys_.end(), time, [](double t, const RigidKey& k) { return t < k.time; });
    size_t i1 = size_t(it - keys_.begin()) - 1, i2 = i1 + 1;
    if (interpolation_ == Interpolation::Step) return pose(keys_[i1]);
    float u = float((time - keys_[i1].time) / (keys_[i2].time - keys_[i1].time));
    RigidKey k;
    if (interpolation_ == Interpolation::Linear) {
        k.translate = glm::mix(keys_[i1].translate, keys_[i2].translate, u);
        k.rotateDeg = glm::mix(keys_[i1].rotateDeg, keys_[i2].rotateDeg, u);
        k.scale = glm::mix(keys_[i1].scale, keys_[i2].scale, u);
    } else {
        size_t i0 = i1 == 0 ? 0 : i1 - 1, i3 = std::min(i2 + 1, keys_.size() - 1);
        k.translate = catmullRom(keys_[i0].translate, keys_[i1].translate, keys_[i2].translate, keys_[i3].translate, u);
        k.rotateDeg = catmullRom(keys_[i0].rotateDeg, keys_[i1].rotateDeg, keys_[i2].rotateDeg, keys_[i3].rotateDeg, u);
        k.scale = catmullRom(keys_[i0].scale, keys_[i1].scale, keys_[i2].scale, keys_[i3].scale, u);
        // A spline through positive scales can dip below zero between them; a scale is never mirrored here.
        k.scale = glm::max(k.scale, 1e-6f * glm::min(keys_[i1].scale, keys_[i2].scale));
    }
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
    return RigidPath(std::move(keys), interp);
}

MotionFn RigidPath::motion() const {
    return [path = *this](double time) { return path.at(time); };
}

void MovingPart::setLocal(std::vector<glm::vec3> vertices) {
    local = std::move(vertices);
    localMin = glm::vec3(0.0f), localMax = glm::vec3(0.0f);
    if (local.empty()) return;
    localMin = localMax = local.front();
    for (const glm::vec3& v : local) localMin = glm::min(localMin, v), localMax = glm::max(localMax, v);
}

void poseTriangle(const glm::mat4& m, const glm::vec3* local, glm::vec3* out, glm::vec3& normal) {
    for (int k = 0; k < 3; ++k) out[k] = glm::vec3(m * glm::vec4(local[k], 1.0f));
    if (glm::determinant(glm::mat3(m)) < 0.0f) std::swap(out[1], out[2]);
    glm::vec3 n = glm::cross(out[1] - out[0], out[2] - out[0]);
    float len = glm::length(n);
    normal = len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0, 1, 0);
}

} // namespace shadowlab
