#include "stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "median.h"

namespace gi::bench {

double median(std::vector<double> v) {
  return gi::cli::median(std::move(v));
}

namespace {

// P(Binomial(n, 1/2) <= j), summed in doubles (n is a repetition count: small).
double binomialCdfHalf(size_t n, size_t j) {
  double term = std::pow(0.5, double(n)), sum = 0.0;  // C(n, 0) / 2^n
  for (size_t i = 0; i <= j && i <= n; ++i) {
    sum += term;
    term = term * double(n - i) / double(i + 1);
  }
  return sum;
}

}  // namespace

Interval medianInterval(std::vector<double> v, double confidence) {
  Interval r;
  r.samples = v.size();
  r.values = v;
  if (v.empty()) return r;
  std::sort(v.begin(), v.end());
  r.median = median(v);
  const size_t n = v.size();
  // [x_(k), x_(n+1-k)] (1-based) covers the median with 1 - 2 P(Bin(n, 1/2) <= k - 1).
  size_t k = 1;
  while (2 * (k + 1) <= n + 1 && 1.0 - 2.0 * binomialCdfHalf(n, k) >= confidence) ++k;
  r.lo = v[k - 1];
  r.hi = v[n - k];
  r.coverage = n > 1 ? 1.0 - 2.0 * binomialCdfHalf(n, k - 1) : 0.0;
  return r;
}

std::vector<size_t> paretoFront(const std::vector<TradeoffPoint>& p) {
  auto dominates = [&](size_t a, size_t b) {
    if (clearlyLess(p[b].time, p[a].time) || p[a].error > p[b].error) return false;
    if (clearlyLess(p[a].time, p[b].time) || p[a].error < p[b].error) return true;
    // Equal error, times within the noise: the cheaper median (then the earlier index).
    return p[a].time.median != p[b].time.median ? p[a].time.median < p[b].time.median : a < b;
  };
  std::vector<size_t> front;
  for (size_t b = 0; b < p.size(); ++b) {
    bool dominated = false;
    for (size_t a = 0; a < p.size() && !dominated; ++a) dominated = a != b && dominates(a, b);
    if (!dominated) front.push_back(b);
  }
  std::stable_sort(front.begin(), front.end(),
                   [&](size_t a, size_t b) { return p[a].time.median < p[b].time.median; });
  return front;
}

CalibrationChoice chooseCalibrated(const std::vector<CalibrationCandidate>& c, double limitMs,
                                   double scoreTolerance) {
  CalibrationChoice out;
  const size_t n = c.size();
  auto below = [&](size_t a, size_t b) {  // a's counts <= b's, componentwise, a != b
    if (a == b || c[a].counts.size() != c[b].counts.size()) return false;
    for (size_t k = 0; k < c[a].counts.size(); ++k)
      if (c[a].counts[k] > c[b].counts[k]) return false;
    return true;
  };
  // Bounds in order of the count sum: every candidate below another comes first.
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t(0));
  auto total = [&](size_t i) {
    long s = 0;
    for (int v : c[i].counts) s += v;
    return s;
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return total(a) < total(b); });
  out.boundMs.assign(n, 0.0);
  for (size_t pos = 0; pos < n; ++pos) {
    const size_t i = order[pos];
    double bound = c[i].ms.hi;
    for (size_t q = 0; q < pos; ++q) {
      const size_t j = order[q];
      if (below(j, i) && !clearlyLess(c[i].ms, c[j].ms)) bound = std::max(bound, out.boundMs[j]);
    }
    out.boundMs[i] = bound;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!(out.boundMs[i] <= limitMs)) continue;
    if (!out.index) {
      out.index = i;
      continue;
    }
    const size_t b = *out.index;
    const double tol = scoreTolerance * std::max({1.0, std::abs(c[i].score), std::abs(c[b].score)});
    if (c[i].score < c[b].score - tol ||
        (std::abs(c[i].score - c[b].score) <= tol && out.boundMs[i] < out.boundMs[b]))
      out.index = i;
  }
  if (out.index) {
    out.marginMs = limitMs - out.boundMs[*out.index];
    out.noiseMarginMs = out.boundMs[*out.index] - c[*out.index].ms.median;
  }
  return out;
}

}  // namespace gi::bench
