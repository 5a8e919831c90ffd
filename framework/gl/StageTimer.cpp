#include "framework/gl/StageTimer.h"

#include "framework/core/Error.h"

#include <algorithm>

namespace shadowlab {

bool isSoftwareRenderer(const std::string& renderer) {
    for (const char* name : {"llvmpipe", "softpipe", "swrast", "SwiftShader"})
        if (renderer.find(name) != std::string::npos) return true;
    return false;
}

double sumGpuMs(const std::vector<StageTime>& stages) {
    double sum = 0;
    for (const StageTime& s : stages) sum += std::max(0.0, s.gpuMs);
    return sum;
}

TimedWork timeWork(StageTimer& timer, const std::function<void()>& work) {
    TimedWork out;
    glFinish();
    const auto start = std::chrono::steady_clock::now();
    work();
    glFinish();
    out.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    out.stages = timer.collect();
    return out;
}

StageTimer::StageTimer() = default;

void StageTimer::begin(const std::string& name, bool gpu) {
    if (open_) throw RuntimeError("StageTimer: stage '" + name + "' begun inside '" + stages_.back().time.name + "'");
    Pending p;
    p.time.name = name;
    if (gpu) {
        if (used_ == pool_.size()) {
            GLuint q = 0;
            glCreateQueries(GL_TIME_ELAPSED, 1, &q);
            pool_.emplace_back(q);
        }
        p.query = pool_[used_++].id();
        glBeginQuery(GL_TIME_ELAPSED, p.query);
    }
    stages_.push_back(p);
    open_ = true;
    start_ = std::chrono::steady_clock::now();
}

void StageTimer::end() {
    if (!open_) throw RuntimeError("StageTimer: end() without begin()");
    auto& p = stages_.back();
    if (synchronous_) glFinish();
    p.time.cpuMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    if (p.query) glEndQuery(GL_TIME_ELAPSED);
    open_ = false;
}

std::vector<StageTime> StageTimer::collect() {
    if (open_) end();
    std::vector<StageTime> out;
    for (auto& p : stages_) {
        if (p.query) {
            GLuint64 ns = 0;
            glGetQueryObjectui64v(p.query, GL_QUERY_RESULT, &ns); // blocks until available
            p.time.gpuMs = double(ns) * 1e-6;
        }
        out.push_back(p.time);
    }
    stages_.clear();
    used_ = 0;
    return out;
}

} // namespace shadowlab
