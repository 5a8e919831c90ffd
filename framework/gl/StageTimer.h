#pragma once
// Named per-frame stages timed with GL timer queries (GPU time) and the CPU clock (CPU time
// spent issuing the stage, or computing it for CPU algorithms). Stages do not nest.
#include "framework/gl/GlObjects.h"

#include <chrono>
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

} // namespace shadowlab
