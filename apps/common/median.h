// The median of a sample (the mean of the two middle values for an even count; 0 for none):
// one definition for gi-render's --timings, gi-bench's statistics and gi-demo's frame times.
#pragma once

#include <algorithm>
#include <vector>

namespace gi::cli {

inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace gi::cli
