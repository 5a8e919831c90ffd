#pragma once
// Statistics for timings on noisy machines: a median with a bootstrap confidence interval, the
// ratio of two samples' medians with its interval, and the Mann-Whitney U test. Deterministic: a
// fixed seed, so the same measurements always give the same interval and verdict.
#include <cstdint>
#include <vector>

namespace shadowlab {

struct Interval {
    double median = 0, low = 0, high = 0; ///< the estimate and its interval's ends
    double level = 0.95;
    bool valid = false;                    ///< false when there were too few values for one
};

/// The median of `x` and its percentile-bootstrap interval at `level` (at least 3 values).
Interval bootstrapMedian(const std::vector<double>& x, double level = 0.95, uint32_t seed = 1);

/// median(b) / median(a) and its bootstrap interval, a and b resampled independently (at least 2
/// values each; every value of `a` positive).
Interval bootstrapRatioOfMedians(const std::vector<double>& a, const std::vector<double>& b, double level = 0.95,
                                 uint32_t seed = 1);

/// Two-sided p-value of the Mann-Whitney U test that `a` and `b` come from one distribution
/// (normal approximation with tie and continuity corrections; exact enough from 4 values each).
/// 1 when either is empty.
double mannWhitneyP(const std::vector<double>& a, const std::vector<double>& b);

double medianOf(std::vector<double> x);

} // namespace shadowlab
