#pragma once
// Named per-frame stages timed with GL timer queries (GPU time) and the CPU clock (CPU time
// spent issuing the stage, or computing it for CPU algorithms). Stages do not nest.
#include "framework/gl/GlObjects.h"

#include <chrono>
#include <functional>
#include <string>
#include <vector>

namespace shadowlab {

struct StageTime {
    std::string name;
    double gpuMs = -1; ///< GPU time; negative when the stage ran no GPU work worth timing (CPU stages)
    double cpuMs = 0;  ///< CPU wall time between begin() and end()
};

/// True for CPU rasterisers (llvmpipe, softpipe, swrast). Their GL_TIME_ELAPSED queries misattribute
/// compute work (a 1 s dispatch can read 0.03 ms while the next stage absorbs it), but they run each
/// dispatch to completion, so the wall clock of a synchronous stage is the honest figure there.
bool isSoftwareRenderer(const std::string& renderer);

class StageTimer {
public:
    StageTimer();
    /// Starts a stage. `gpu` = false for stages that run on the CPU only (no timer query).
    void begin(const std::string& name, bool gpu = true);
    void end();
    /// Waits for the queries of this frame and returns the stages in order; resets for the next frame.
    std::vector<StageTime> collect();
    /// Synchronous: end() waits for the GL (glFinish), so a stage's CPU time is its wall time.
    /// Used where timer queries cannot be trusted (see isSoftwareRenderer()).
    void setSynchronous(bool on) { synchronous_ = on; }
    bool synchronous() const { return synchronous_; }

private:
    struct Pending {
        StageTime time;
        GLuint query = 0;
    };
    std::vector<GlQuery> pool_;
    size_t used_ = 0;
    std::vector<Pending> stages_;
    bool open_ = false;
    bool synchronous_ = false;
    std::chrono::steady_clock::time_point start_;
};

/// Sum of the stages' GPU times (CPU-only stages, gpuMs < 0, add nothing).
double sumGpuMs(const std::vector<StageTime>& stages);

struct TimedWork {
    std::vector<StageTime> stages; ///< what `work` timed through the timer
    double wallMs = 0;             ///< wall time of `work`, the GL finished on both sides
};
/// Runs `work` (an algorithm's frame) bracketed by glFinish, so the wall time is its own, and
/// collects the stages it timed. The runner and the GUI measure frames this one way.
TimedWork timeWork(StageTimer& timer, const std::function<void()>& work);

} // namespace shadowlab
