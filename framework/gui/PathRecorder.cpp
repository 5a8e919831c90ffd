#include "framework/gui/PathRecorder.h"

#include <cmath>

namespace shadowlab {

void PathRecorder::append(const Camera& camera, double time) {
    // Configs require strictly increasing times; a non-positive step must not produce an invalid path.
    if (!keys_.empty() && !(time > keys_.back().time)) time = keys_.back().time + 1e-3;
    keys_.push_back({time, camera.position, camera.target});
}

void PathRecorder::addKeyframe(const Camera& camera) {
    append(camera, keys_.empty() ? 0.0 : keys_.back().time + double(step));
    sinceSample_ = 0;
}

void PathRecorder::update(const Camera& camera, double dt) {
    if (!continuous) {
        sinceSample_ = 0;
        return;
    }
    sinceSample_ += dt;
    if (!keys_.empty() && sinceSample_ < interval) return;
    append(camera, keys_.empty() ? 0.0 : keys_.back().time + sinceSample_);
    sinceSample_ = 0;
}

void PathRecorder::removeLast() {
    if (!keys_.empty()) keys_.pop_back();
}

void PathRecorder::clear() {
    keys_.clear();
    sinceSample_ = 0;
}

} // namespace shadowlab
