// Dynamic resolution (gi/dynamic_resolution.h) against a model frame: a fixed cost plus a cost per
// pixel (scale^2), with and without noise. It brings the frame within the budget in a few
// changes, then holds its scale; it raises the scale when the load drops; it stays at the
// smallest scale when no scale fits and at the largest when off.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gi/dynamic_resolution.h"

namespace gi {
namespace {

struct Outcome {
  int changes = 0, changesLate = 0;  // all, and in the last third
  double scale = 0.0;
};

// `frames` frames of fixed + perPixel x scale^2 ms, times (1 + noise x u), u uniform in [-1, 1].
Outcome simulate(DynamicResolution& dr, double fixed, double perPixel, int frames,
                 double noise = 0.0, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Outcome r;
  for (int f = 0; f < frames; ++f) {
    const double before = dr.scale();
    const double ms = (fixed + perPixel * before * before) * (1.0 + noise * u(rng));
    if (dr.update(ms) != before) {
      ++r.changes;
      if (f >= 2 * frames / 3) ++r.changesLate;
    }
  }
  r.scale = dr.scale();
  return r;
}

TEST(DynamicResolution, BringsTheFrameWithinTheBudgetAndHoldsIt) {
  DynamicResolution dr({66.0});
  const Outcome r = simulate(dr, 20.0, 160.0, 300);  // 180 ms at full size
  const double ms = 20.0 + 160.0 * r.scale * r.scale;
  EXPECT_LE(ms, 66.0);
  EXPECT_GE(ms, 0.7 * 66.0 * 0.8) << "settled far below the budget, scale " << r.scale;
  EXPECT_LE(r.changes, 6);
  EXPECT_EQ(r.changesLate, 0);
  EXPECT_EQ(std::fmod(r.scale * 16.0, 1.0), 0.0) << "scales are multiples of 1/16";
}

TEST(DynamicResolution, NoisyFramesDoNotMakeItOscillate) {
  DynamicResolution dr({66.0});
  const Outcome r = simulate(dr, 20.0, 160.0, 600, 0.2, 7);
  EXPECT_LE(20.0 + 160.0 * r.scale * r.scale, 66.0 * 1.1);
  EXPECT_LE(r.changesLate, 2) << "changes in the last 200 frames at +-20% noise";
}

TEST(DynamicResolution, RaisesTheScaleWhenTheLoadDrops) {
  DynamicResolution dr({66.0});
  const double loaded = simulate(dr, 20.0, 160.0, 200).scale;
  const double light = simulate(dr, 5.0, 40.0, 200).scale;  // 45 ms at full size
  EXPECT_LT(loaded, 0.75);
  EXPECT_EQ(light, 1.0);
}

TEST(DynamicResolution, ImpossibleBudgetGivesTheSmallestScaleAndOffKeepsTheLargest) {
  DynamicResolution tight({5.0, 0.25, 1.0});
  EXPECT_EQ(simulate(tight, 20.0, 160.0, 100).scale, 0.25);
  DynamicResolution off({0.0});
  EXPECT_EQ(simulate(off, 20.0, 160.0, 100).scale, 1.0);
  DynamicResolution guarded({66.0});
  for (double bad : {0.0, -1.0, std::nan(""), double(INFINITY)})
    EXPECT_EQ(guarded.update(bad), 1.0);
}

}  // namespace
}  // namespace gi
