#include "framework/view/Path.h"

#include "framework/core/Spline.h"

#include <algorithm>

namespace shadowlab {

Path::Path(std::vector<Keyframe> keys) : keys_(std::move(keys)) {}

PathSample Path::at(double time) const {
    if (keys_.empty()) return {glm::vec3(0), glm::vec3(0, 0, -1)};
    if (keys_.size() == 1 || time <= keys_.front().time) return {keys_.front().position, keys_.front().target};
    if (time >= keys_.back().time) return {keys_.back().position, keys_.back().target};
    auto it = std::upper_bound(keys_.begin(), keys_.end(), time, [](double t, const Keyframe& k) { return t < k.time; });
    size_t i1 = size_t(it - keys_.begin()) - 1, i2 = i1 + 1;
    size_t i0 = i1 == 0 ? 0 : i1 - 1, i3 = std::min(i2 + 1, keys_.size() - 1);
    float u = float((time - keys_[i1].time) / (keys_[i2].time - keys_[i1].time));
    return {catmullRom(keys_[i0].position, keys_[i1].position, keys_[i2].position, keys_[i3].position, u),
            catmullRom(keys_[i0].target, keys_[i1].target, keys_[i2].target, keys_[i3].target, u)};
}

double Path::frameTime(int i, int frameCount) const {
    if (frameCount <= 1) return startTime();
    return startTime() + (endTime() - startTime()) * double(i) / double(frameCount - 1);
}

Path Path::parse(JsonNode node, glm::vec3 fixedTarget) {
    std::vector<Keyframe> keys;
    auto items = node.objectArray("keyframes");
    // A path without keys would be ignored silently (the static pose used): bad input, as an object's.
    if (items.empty()) node.fail("keyframes", "a path needs at least one keyframe");
    for (auto& k : items) {
        Keyframe kf;
        if (!k.has("time")) k.fail("time", "required key is missing");
        if (!k.has("position")) k.fail("position", "required key is missing");
        kf.time = k.getFloat("time", 0);
        kf.position = k.getPoint("position", glm::vec3(0));
        kf.target = k.getPoint("target", fixedTarget);
        if (!keys.empty() && kf.time <= keys.back().time)
            k.fail("time", "keyframe times must increase strictly (previous is " + std::to_string(keys.back().time) + ")");
        k.finish();
        keys.push_back(kf);
    }
    node.finish();
    return Path(std::move(keys));
}

Json Path::toJson() const {
    Json keys = Json::array();
    for (const auto& k : keys_)
        keys.push_back({{"time", k.time},
                        {"position", {k.position.x, k.position.y, k.position.z}},
                        {"target", {k.target.x, k.target.y, k.target.z}}});
    return {{"keyframes", keys}};
}

} // namespace shadowlab
