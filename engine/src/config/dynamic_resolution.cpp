#include "gi/dynamic_resolution.h"

#include <algorithm>
#include <cmath>

namespace gi {
namespace {

double quantize(double scale, const DynamicResolution::Options& o) {
  const double q = std::round(scale * 16.0) / 16.0;
  return std::clamp(q, o.minScale, o.maxScale);
}

}  // namespace

DynamicResolution::DynamicResolution(const Options& options) {
  setOptions(options);
}

void DynamicResolution::setOptions(const Options& options) {
  options_ = options;
  options_.minScale = std::clamp(options_.minScale, 1.0 / 16.0, 1.0);
  options_.maxScale = std::clamp(options_.maxScale, options_.minScale, 1.0);
  options_.dwell = std::max(options_.dwell, 1);
  scale_ = options_.budgetMs > 0.0 ? std::clamp(scale_, options_.minScale, options_.maxScale)
                                   : options_.maxScale;
  samples_.clear();
}

double DynamicResolution::update(double frameMs) {
  if (!(options_.budgetMs > 0.0) || !std::isfinite(frameMs) || frameMs <= 0.0) return scale_;
  samples_.push_back(frameMs);
  if (int(samples_.size()) < options_.dwell) return scale_;
  std::nth_element(samples_.begin(), samples_.begin() + samples_.size() / 2, samples_.end());
  const double median = samples_[samples_.size() / 2];
  samples_.clear();
  const double budget = options_.budgetMs;
  double next = scale_;
  if (median > budget) {
    // Time ~ pixels: scale by sqrt(budget / median), with a margin; at least one step down.
    next = std::min(quantize(scale_ * std::sqrt(budget / median) * 0.95, options_),
                    scale_ - 1.0 / 16.0);
  } else if (median < options_.raiseBelow * budget) {
    // Up towards the budget's raise threshold, at most a quarter more per change.
    const double target = scale_ * std::sqrt(options_.raiseBelow * budget / median);
    next = std::max(quantize(std::min(target, scale_ * 1.25), options_), scale_ + 1.0 / 16.0);
  }
  scale_ = std::clamp(next, options_.minScale, options_.maxScale);
  return scale_;
}

}  // namespace gi
