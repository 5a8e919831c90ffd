#include "framework/gui/Measurements.h"

#include <algorithm>
#include <numeric>

namespace shadowlab {

void RollingSeries::push(float v) {
    // A vector shifted by one per frame: 240 floats are cheaper to move than a ring buffer is to
    // unroll for PlotLines every frame.
    if (values_.size() == capacity_) values_.erase(values_.begin());
    values_.push_back(v);
}

float RollingSeries::mean() const {
    return values_.empty() ? 0.0f : std::accumulate(values_.begin(), values_.end(), 0.0f) / float(values_.size());
}

float RollingSeries::max() const { return values_.empty() ? 0.0f : *std::max_element(values_.begin(), values_.end()); }

void Measurements::record(const std::vector<StageTime>& stages, double algorithmWallMs, double frameMs) {
    for (const StageTime& s : stages) {
        auto it = std::find_if(stages_.begin(), stages_.end(), [&](const StageSeries& x) { return x.name == s.name; });
        if (it == stages_.end()) it = stages_.insert(stages_.end(), StageSeries{s.name, {}, {}});
        it->gpuMs.push(float(std::max(0.0, s.gpuMs)));
        it->cpuMs.push(float(s.cpuMs));
    }
    algorithmGpuMs_.push(float(sumGpuMs(stages))); // as in the runner's total
    algorithmWallMs_.push(float(algorithmWallMs));
    frameMs_.push(float(frameMs));
}

void Measurements::clear() { *this = Measurements(); }

} // namespace shadowlab
