#pragma once
// Keyframed paths for the camera and the lights: (time, position, target), Catmull-Rom between
// keyframes. An experiment samples the path uniformly in time, one sample per frame, so every
// algorithm of the experiment sees exactly the same views.
#include "framework/core/JsonNode.h"

#include <glm/glm.hpp>
#include <vector>

namespace shadowlab {

struct Keyframe {
    double time = 0;       ///< seconds, strictly increasing along the path
    glm::vec3 position{0};
    glm::vec3 target{0, 0, -1};
};

struct PathSample {
    glm::vec3 position;
    glm::vec3 target;
};

class Path {
public:
    Path() = default;
    explicit Path(std::vector<Keyframe> keys); ///< keys sorted by strictly increasing time

    bool empty() const { return keys_.empty(); }
    const std::vector<Keyframe>& keyframes() const { return keys_; }
    double startTime() const { return keys_.empty() ? 0 : keys_.front().time; }
    double endTime() const { return keys_.empty() ? 0 : keys_.back().time; }

    /// Catmull-Rom through the keyframes (clamped at the ends); passes exactly through every keyframe.
    PathSample at(double time) const;
    /// The time of frame `i` of `frameCount`, uniformly from the first to the last keyframe.
    double frameTime(int i, int frameCount) const;

    /// Reads {"keyframes": [{"time", "position", "target"}, ...]}; validates ordering. A keyframe
    /// without "target" aims at `fixedTarget` (its owner's static target), so a light or camera
    /// moving along a path keeps looking at the point the config names.
    static Path parse(JsonNode node, glm::vec3 fixedTarget);
    Json toJson() const;

private:
    std::vector<Keyframe> keys_;
};

} // namespace shadowlab
