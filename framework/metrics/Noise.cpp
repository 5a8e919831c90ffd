#include "framework/metrics/Noise.h"

#include <algorithm>
#include <cmath>

namespace shadowlab {

namespace {

constexpr int kResamples = 4000;

/// SplitMix64: small, fast, and the same sequence on every machine.
struct SplitMix {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    size_t below(size_t n) { return size_t(next() % n); }
};

double medianOfResample(const std::vector<double>& x, SplitMix& rng, std::vector<double>& scratch) {
    scratch.resize(x.size());
    for (double& v : scratch) v = x[rng.below(x.size())];
    const size_t mid = scratch.size() / 2;
    std::nth_element(scratch.begin(), scratch.begin() + long(mid), scratch.end());
    if (scratch.size() % 2) return scratch[mid];
    const double upper = scratch[mid];
    return 0.5 * (upper + *std::max_element(scratch.begin(), scratch.begin() + long(mid)));
}

Interval percentiles(std::vector<double> estimates, double median, double level) {
    std::sort(estimates.begin(), estimates.end());
    const double tail = 0.5 * (1.0 - level);
    const auto at = [&](double q) { return estimates[std::min(estimates.size() - 1, size_t(q * double(estimates.size() - 1) + 0.5))]; };
    return {median, at(tail), at(1.0 - tail), level, true};
}

} // namespace

double medianOf(std::vector<double> x) {
    if (x.empty()) return 0;
    std::sort(x.begin(), x.end());
    const size_t mid = x.size() / 2;
    return x.size() % 2 ? x[mid] : 0.5 * (x[mid - 1] + x[mid]);
}

Interval bootstrapMedian(const std::vector<double>& x, double level, uint32_t seed) {
    Interval out;
    out.median = medianOf(x);
    out.level = level;
    if (x.size() < 3) return out;
    SplitMix rng{seed};
    std::vector<double> estimates(kResamples), scratch;
    for (double& e : estimates) e = medianOfResample(x, rng, scratch);
    return percentiles(std::move(estimates), out.median, level);
}

Interval bootstrapRatioOfMedians(const std::vector<double>& a, const std::vector<double>& b, double level, uint32_t seed) {
    Interval out;
    out.level = level;
    const double ma = medianOf(a);
    if (a.empty() || b.empty() || !(ma > 0)) return out;
    out.median = medianOf(b) / ma;
    if (a.size() < 2 || b.size() < 2) return out;
    SplitMix rng{seed};
    std::vector<double> estimates(kResamples), sa, sb;
    for (double& e : estimates) {
        const double da = medianOfResample(a, rng, sa), db = medianOfResample(b, rng, sb);
        e = da > 0 ? db / da : out.median;
    }
    return percentiles(std::move(estimates), out.median, level);
}

double mannWhitneyP(const std::vector<double>& a, const std::vector<double>& b) {
    if (a.empty() || b.empty()) return 1.0;
    struct Item {
        double v;
        int group;
    };
    std::vector<Item> all;
    for (double v : a) all.push_back({v, 0});
    for (double v : b) all.push_back({v, 1});
    std::sort(all.begin(), all.end(), [](const Item& x, const Item& y) { return x.v < y.v; });
    // Ranks with ties averaged; the tie correction of the variance from each tied group.
    double rankSumA = 0, tieTerm = 0;
    for (size_t i = 0; i < all.size();) {
        size_t j = i;
        while (j < all.size() && all[j].v == all[i].v) ++j;
        const double rank = 0.5 * double(i + 1 + j);  // mean of ranks i+1 .. j
        for (size_t k = i; k < j; ++k)
            if (all[k].group == 0) rankSumA += rank;
        const double t = double(j - i);
        tieTerm += t * t * t - t;
        i = j;
    }
    const double n1 = double(a.size()), n2 = double(b.size()), n = n1 + n2;
    const double u = rankSumA - n1 * (n1 + 1) / 2;
    const double mean = n1 * n2 / 2;
    const double variance = n1 * n2 / 12 * ((n + 1) - tieTerm / (n * (n - 1)));
    if (!(variance > 0)) return 1.0;
    const double z = std::max(0.0, std::fabs(u - mean) - 0.5) / std::sqrt(variance);
    return std::erfc(z / std::sqrt(2.0));
}

} // namespace shadowlab
