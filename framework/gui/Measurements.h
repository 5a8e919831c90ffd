#pragma once
// Rolling per-frame measurements of the active algorithm for the graphs: GPU time per stage,
// frame time, and the latest counters and memory.
#include "framework/algorithm/ShadowAlgorithm.h"

#include <deque>
#include <string>
#include <vector>

namespace shadowlab {

/// The last `capacity` values of one series, oldest first (contiguous for ImGui::PlotLines).
class RollingSeries {
public:
    RollingSeries() = default;
    explicit RollingSeries(size_t capacity) : capacity_(capacity) {}
    void push(float v);
    const std::vector<float>& values() const { return values_; }
    float last() const { return values_.empty() ? 0.0f : values_.back(); }
    float mean() const;
    float max() const;

private:
    size_t capacity_ = 240; ///< frames kept: a few seconds at interactive rates
    std::vector<float> values_;
};

struct StageSeries {
    std::string name;
    RollingSeries gpuMs;
    RollingSeries cpuMs;
};

class Measurements {
public:
    /// Records one rendered frame: the algorithm's stages, its wall time and the whole frame's time.
    /// (Counters, memory and overflow are read from the algorithm by the panel, only while it is
    /// open: reading them may download a buffer or, for line_space's classify, trace on the CPU.)
    void record(const std::vector<StageTime>& stages, double algorithmWallMs, double frameMs);
    /// Forgets the series (after switching algorithm: its stages differ).
    void clear();

    const std::vector<StageSeries>& stages() const { return stages_; }
    const RollingSeries& frameMs() const { return frameMs_; }
    const RollingSeries& algorithmGpuMs() const { return algorithmGpuMs_; }
    const RollingSeries& algorithmWallMs() const { return algorithmWallMs_; }

private:
    std::vector<StageSeries> stages_;
    RollingSeries frameMs_, algorithmGpuMs_, algorithmWallMs_;
};

} // namespace shadowlab
