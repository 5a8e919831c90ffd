#include "framework/metrics/Accuracy.h"

#include <cmath>

namespace shadowlab {

std::vector<uint8_t> litMask(const CpuGBuffer& g, const Light& light) {
    size_t n = size_t(g.width) * g.height;
    std::vector<uint8_t> mask(n, 0);
    for (size_t i = 0; i < n; ++i) {
        if (!g.covered(i)) continue;
        glm::vec3 p = g.positionAt(i);
        mask[i] = light.reaches(p, g.normalAt(i));
    }
    return mask;
}

std::vector<uint8_t> coveredMask(const CpuGBuffer& g) {
    std::vector<uint8_t> mask(size_t(g.width) * g.height);
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = g.covered(i);
    return mask;
}

Accuracy compareVisibility(const std::vector<float>& vis, const std::vector<float>& ref, const std::vector<uint8_t>& lit) {
    Accuracy a;
    size_t falseLit = 0, falseShadowed = 0;
    double sq = 0;
    for (size_t i = 0; i < lit.size(); ++i) {
        if (!lit[i]) continue;
        ++a.litPixels;
        bool v = vis[i] >= 0.5f, r = ref[i] >= 0.5f;
        if (v && !r) ++falseLit;
        if (!v && r) ++falseShadowed;
        if (v != r && a.firstWrongPixel < 0) a.firstWrongPixel = int64_t(i);
        double d = double(vis[i]) - double(ref[i]);
        sq += d * d;
    }
    a.falseLitPixels = falseLit;
    a.falseShadowedPixels = falseShadowed;
    if (a.litPixels) {
        double n = double(a.litPixels);
        a.falseLit = double(falseLit) / n;
        a.falseShadowed = double(falseShadowed) / n;
        a.mismatchRatio = a.falseLit + a.falseShadowed;
        a.rmse = std::sqrt(sq / n);
    }
    return a;
}

} // namespace shadowlab
