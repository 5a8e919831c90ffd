#include "algorithms/line_space/SampleClassifier.h"

#include <algorithm>
#include <atomic>
#include <limits>
#include <mutex>
#include <thread>

namespace shadowlab::ls {
namespace {

/// Parameter at which the ray leaves box lo + [0, size] (it starts inside).
float exitParameter(glm::vec3 o, glm::vec3 d, const NodeGpu& n) {
    float t = std::numeric_limits<float>::infinity();
    for (int k = 0; k < 3; ++k) {
        if (d[k] > 0.0f) t = std::min(t, (n.lo[k] + n.size[k] - o[k]) / d[k]);
        else if (d[k] < 0.0f) t = std::min(t, (n.lo[k] - o[k]) / d[k]);
    }
    return std::max(t, 0.0f);
}

void add(SampleClasses& a, const SampleClasses& b) {
    a.samples += b.samples, a.exactOccluded += b.exactOccluded, a.lineSpaceOccluded += b.lineSpaceOccluded;
    a.over += b.over, a.under += b.under, a.underInStart += b.underInStart, a.underElsewhere += b.underElsewhere;
}

} // namespace

SampleClasses classifySamples(const EmbreeTracer& tracer, const CpuGBuffer& g, const Light& light, float rayOffset,
                              const std::vector<NodeGpu>& nodes, const std::vector<uint32_t>& perPixel,
                              const StartRegion& region, int threads) {
    const bool directional = light.type == LightType::Directional;
    const std::vector<glm::vec3> samples = light.samplePoints();
    const size_t count = directional ? 1 : samples.size();
    const size_t stride = classifyStride(samples.size());
    const float inf = std::numeric_limits<float>::infinity();
    SampleClasses total;
    std::mutex mutex;
    std::atomic<int> nextRow{0};
    auto worker = [&] {
        SampleClasses c;
        for (int y = nextRow.fetch_add(1); y < g.height; y = nextRow.fetch_add(1))
            for (int x = 0; x < g.width; ++x) {
                const size_t i = size_t(y) * size_t(g.width) + size_t(x);
                if (!g.covered(i)) continue;
                const glm::vec3 p = g.positionAt(i), n = g.normalAt(i);
                if (!light.reaches(p, n)) continue;
                const glm::vec3 o = p + n * rayOffset; // the reference's ray, float for float
                const uint32_t start = perPixel[i * stride];
                for (size_t s = 0; s < count; ++s) {
                    glm::vec3 dir = -light.direction();
                    float tfar = inf;
                    if (!directional) {
                        const glm::vec3 d = samples[s] - o;
                        const float dist = glm::length(d);
                        if (!(dist > 0.0f)) continue; // the origin is on the sample: both say free
                        dir = d / dist;
                        tfar = std::max(0.0f, dist - rayOffset);
                    }
                    const bool ls = (perPixel[i * stride + 1 + s / 32] >> (s % 32)) & 1u;
                    const bool exact = tracer.occluded(o, dir, tfar);
                    ++c.samples;
                    c.exactOccluded += exact;
                    c.lineSpaceOccluded += ls;
                    if (ls && !exact) ++c.over;
                    if (!ls && exact) {
                        ++c.under;
                        bool elsewhere = true;
                        if (region.mode == StartMode::Exact || region.mode == StartMode::Bvh) {
                            elsewhere = true; // nothing is ignored: every miss is one
                        } else if (region.mode == StartMode::Distance) {
                            // Traced again from just past the region's end: the float end the shader
                            // computed may differ in its last bit.
                            const float t = region.end(glm::normalize(n), dir) * (1.0f + 1e-5f);
                            elsewhere = t < tfar && tracer.occluded(o + dir * t, dir, tfar - t);
                        } else if (start != LS_EMPTY && start < nodes.size()) {
                            const float t = exitParameter(o, dir, nodes[start]);
                            elsewhere = t < tfar && tracer.occluded(o + dir * t, dir, tfar - t);
                        }
                        (elsewhere ? c.underElsewhere : c.underInStart) += 1;
                    }
                }
            }
        std::lock_guard lock(mutex);
        add(total, c);
    };
    int n = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (int t = 1; t < n; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    return total;
}

} // namespace shadowlab::ls
