// gi-bench's timing statistics: a median with a distribution-free confidence interval, the
// interval-aware Pareto front and the calibration choice. Pure functions, tested on synthetic
// timings (tests/test_bench_stats.cpp).
//
// Timing model. A configuration is measured in R repetitions, interleaved round-robin with the
// other configurations (rep 1 of all, then rep 2 of all, ...), so slow drift of the device hits
// all alike; each repetition's value is the median over its frames. The reported time is the
// median of the R repetition values, and its interval is the order-statistics (binomial)
// confidence interval of the population median: [x_(k), x_(R+1-k)] with the largest k whose
// coverage 1 - 2 P(Binomial(R, 1/2) < k) reaches the confidence asked for. It assumes only
// independent repetitions of a continuous distribution. With R < 6 no k reaches 95%: the
// interval is then [min, max], whose coverage (93.75% for R = 5) is reported with it.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace gi::bench {

double median(std::vector<double> values);  // 0 for none

struct Interval {
  double median = 0.0, lo = 0.0, hi = 0.0;
  double coverage = 0.0;  // the interval's exact coverage of the population median
  size_t samples = 0;
  // The repetition values in measurement order: repetition r of interleaved configurations ran
  // back to back, so per-repetition ratios pair them under the same load (results.json).
  std::vector<double> values;
  double width() const { return hi - lo; }
};

// Median of `values` and the order-statistics interval of at least `confidence` when the
// sample size allows (see above). One value: [v, v] with coverage 0.
Interval medianInterval(std::vector<double> values, double confidence = 0.95);

// A is faster than B beyond the noise: A's interval lies wholly below B's.
inline bool clearlyLess(const Interval& a, const Interval& b) {
  return a.hi < b.lo;
}

// One point of a (time, error) trade-off: the time with its interval, the error exact (the
// reference is fixed, so the error of one image against it has no timing noise).
struct TradeoffPoint {
  Interval time;
  double error = 0.0;
};

// Indices of the points no other point dominates, ordered by median time. A dominates B when
// A is not clearly slower (!clearlyLess(B, A)), has no larger error, and is better somewhere:
// clearly faster, smaller error, or (equal error, times within the noise) cheaper by median,
// the earlier index on a tie. So a time difference inside the intervals is no reason to keep a
// less accurate point on the front.
std::vector<size_t> paretoFront(const std::vector<TradeoffPoint>& points);

// --calibrate. Candidates are vectors of sample counts with their measured time and a score
// (lower is better). Cost is assumed not to fall when counts rise: a candidate's cost bound is
// the upper end of its interval, raised to the bound of any candidate with componentwise
// smaller or equal counts, unless it was measured clearly cheaper than that one (its upper end
// below the other's lower end). The choice is the best-scoring candidate whose bound fits
// `limitMs`; scores within `scoreTolerance` (relative) are ties, won by the smaller bound.
struct CalibrationCandidate {
  std::vector<int> counts;
  Interval ms;
  double score = 0.0;
};
struct CalibrationChoice {
  std::optional<size_t> index;  // none when nothing fits
  std::vector<double> boundMs;  // per candidate: the monotone cost bound used
  double marginMs = 0.0;        // limit - bound of the choice (>= 0)
  double noiseMarginMs = 0.0;   // bound - median of the choice: what the noise took
};
CalibrationChoice chooseCalibrated(const std::vector<CalibrationCandidate>& candidates,
                                   double limitMs, double scoreTolerance = 1e-9);

}  // namespace gi::bench
