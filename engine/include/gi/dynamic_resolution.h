// Dynamic resolution: the render scale (fraction of the output's width and height) that keeps
// a frame within a time budget. Fed each frame's measured time, it changes the scale only after
// `dwell` frames at the current one, from their median: down when it is over the budget, up
// when it is under `raiseBelow` x the budget (the band between is the hysteresis that stops it
// from oscillating). The step assumes time grows with the pixels (scale^2), so fixed costs make
// it undershoot and it converges over a few changes. Scales are multiples of 1/16 within
// [minScale, maxScale]. No device: the app applies the scale (gi-demo resizes its renderer).
#pragma once

#include <vector>

namespace gi {

class DynamicResolution {
 public:
  struct Options {
    double budgetMs = 0.0;  // <= 0: off (the scale stays at maxScale)
    double minScale = 0.25, maxScale = 1.0;
    int dwell = 6;            // frames measured at a scale before it may change
    double raiseBelow = 0.7;  // raise only when the median is below this x the budget
  };
  explicit DynamicResolution(const Options& options);
  // One frame's time at the current scale; returns the scale for the next frames.
  double update(double frameMs);
  double scale() const { return scale_; }
  const Options& options() const { return options_; }
  // A new budget (or limits) from now on; the frames measured so far are dropped.
  void setOptions(const Options& options);

 private:
  Options options_;
  double scale_ = 1.0;
  std::vector<double> samples_;
};

}  // namespace gi
