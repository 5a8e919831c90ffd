#pragma once
// Records a camera path in the viewer: keyframes added by a button (spaced `step` path seconds
// apart) or sampled continuously while the camera moves (spaced by the real time between samples).
#include "framework/view/Camera.h"
#include "framework/view/Path.h"

#include <vector>

namespace shadowlab {

class PathRecorder {
public:
    float step = 1.0f;        ///< path seconds between keyframes added with addKeyframe()
    bool continuous = false;  ///< sample the camera while recording
    float interval = 0.25f;   ///< seconds of real time between continuous samples

    /// Appends the camera's pose `step` seconds after the last keyframe (at 0 for the first).
    void addKeyframe(const Camera& camera);
    /// While `continuous`, appends the pose every `interval` seconds of real time; `dt` = seconds since the last call.
    void update(const Camera& camera, double dt);
    void removeLast();
    void clear();

    const std::vector<Keyframe>& keyframes() const { return keys_; }
    /// The recorded path (valid for a config once it has at least one keyframe).
    Path path() const { return Path(keys_); }

private:
    void append(const Camera& camera, double time);
    std::vector<Keyframe> keys_;
    double sinceSample_ = 0;
};

} // namespace shadowlab
