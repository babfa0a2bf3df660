// gi-bench's error metrics: identity, known noise, masking and degenerate inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "metrics.h"

namespace gi::bench {
namespace {

Plane ramp(int w, int h) {
  Plane p{w, h, std::vector<float>(size_t(w) * size_t(h))};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      p.values[size_t(y * w + x)] =
          0.25f + 0.5f * float(x) / float(w) + 0.1f * std::sin(0.3f * float(y));
  return p;
}

double mean(const Plane& p) {
  double s = 0;
  for (float v : p.values) s += v;
  return s / double(p.values.size());
}

TEST(BenchMetrics, IdentityIsPerfect) {
  const Plane a = ramp(64, 48);
  const Metrics m = compare(a, a, {});
  EXPECT_EQ(m.nrmse, 0.0);
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);
  EXPECT_EQ(m.pixels, 64u * 48u);
}

TEST(BenchMetrics, GaussianNoiseGivesExpectedNrmse) {
  const Plane ref = ramp(256, 256);
  for (double sigma : {0.01, 0.05, 0.2}) {
    Plane noisy = ref;
    std::mt19937 rng(42);
    std::normal_distribution<float> noise(0.0f, float(sigma));
    for (float& v : noisy.values) v += noise(rng);
    const double expected = sigma / mean(ref);
    const Metrics m = compare(noisy, ref, {});
    EXPECT_NEAR(m.nrmse, expected, 0.03 * expected) << "sigma " << sigma;
    EXPECT_NEAR(m.rmse, sigma, 0.03 * sigma);
    EXPECT_LT(m.ssim, 1.0);
    EXPECT_GT(m.ssim, -1.0);
  }
  // More noise, lower SSIM.
  Plane a = ref, b = ref;
  std::mt19937 rng(7);
  std::normal_distribution<float> n1(0.0f, 0.02f), n2(0.0f, 0.2f);
  for (size_t i = 0; i < a.values.size(); ++i) {
    a.values[i] += n1(rng);
    b.values[i] += n2(rng);
  }
  EXPECT_GT(ssim(a, ref, {}), ssim(b, ref, {}));
}

TEST(BenchMetrics, MaskExcludesPixels) {
  const Plane ref = ramp(64, 48);
  Plane test = ref;
  std::vector<unsigned char> mask(ref.values.size(), 1);
  // Garbage (including NaN and inf) in the right half, masked out.
  for (int y = 0; y < 48; ++y)
    for (int x = 32; x < 64; ++x) {
      const size_t i = size_t(y * 64 + x);
      test.values[i] = (x % 3 == 0) ? NAN : (x % 3 == 1) ? INFINITY : 100.0f;
      mask[i] = 0;
    }
  const Metrics m = compare(test, ref, mask);
  EXPECT_EQ(m.nrmse, 0.0);
  EXPECT_NEAR(m.ssim, 1.0, 1e-12);
  EXPECT_EQ(m.pixels, 32u * 48u);
  // Unmasked, the same garbage is a large, finite error.
  const Metrics u = compare(test, ref, {});
  EXPECT_TRUE(std::isfinite(u.nrmse));
  EXPECT_TRUE(std::isfinite(u.ssim));
  EXPECT_GT(u.nrmse, 1.0);
}

TEST(BenchMetrics, DegenerateInputsAreFinite) {
  const Plane zero{16, 16, std::vector<float>(256, 0.0f)};
  const Plane one{16, 16, std::vector<float>(256, 1.0f)};
  const Plane half{16, 16, std::vector<float>(256, 0.5f)};
  for (const Plane* a : {&zero, &one, &half})
    for (const Plane* b : {&zero, &one, &half}) {
      const Metrics m = compare(*a, *b, {});
      EXPECT_TRUE(std::isfinite(m.nrmse));
      EXPECT_TRUE(std::isfinite(m.ssim));
    }
  EXPECT_NEAR(compare(one, one, {}).ssim, 1.0, 1e-12);
  EXPECT_NEAR(compare(half, one, {}).nrmse, 0.5, 1e-9);
  EXPECT_NEAR(compare(one, zero, {}).nrmse, 1.0, 1e-9);  // reference mean 0: divided by 1
  // An empty comparison is no result: the parts stay finite, compare() refuses it.
  const std::vector<unsigned char> none(256, 0);
  EXPECT_EQ(nrmse(half, one, none), 0.0);
  EXPECT_EQ(ssim(half, one, none), 1.0);
  EXPECT_THROW(compare(half, one, none), std::invalid_argument);
}

// The normaliser: the mean over the normaliser's pixels among the scored ones (the scored ones
// when it keeps none of them); the noise floor on the same scale.
TEST(BenchMetrics, NormaliserLeavesOutPixelsAndNoiseFloorSharesItsScale) {
  // 16 x 16: a bright 2 x 2 "emitter" (10) on a 0.5 background; the test image is 0.1 off
  // everywhere; the reference's standard error is 0.02 everywhere.
  Plane ref{16, 16, std::vector<float>(256, 0.5f)};
  std::vector<unsigned char> notEmitter(256, 1);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      ref.values[size_t(y) * 16 + size_t(x)] = 10.0f;
      notEmitter[size_t(y) * 16 + size_t(x)] = 0;
    }
  Plane test = ref;
  for (float& v : test.values) v += 0.1f;
  const Plane stdError{16, 16, std::vector<float>(256, 0.02f)};
  const Metrics all = compare(test, ref, {}, 1.0, nullptr, &stdError);
  EXPECT_NEAR(all.normaliser, (252 * 0.5 + 4 * 10.0) / 256, 1e-6);
  EXPECT_EQ(all.normaliserPixels, 256u);
  const Metrics m = compare(test, ref, {}, 1.0, &notEmitter, &stdError);
  EXPECT_EQ(m.pixels, 256u);  // still scored
  EXPECT_EQ(m.normaliserPixels, 252u);
  EXPECT_NEAR(m.normaliser, 0.5, 1e-6);
  EXPECT_NEAR(m.nrmse, 0.1 / 0.5, 1e-5);
  EXPECT_NEAR(m.noiseFloor, 0.02 / 0.5, 1e-6);
  EXPECT_GT(m.nrmse, all.nrmse * 1.2);  // the emitter's pixels had hidden a quarter of it
  // A normaliser keeping none of the scored pixels falls back to them.
  const std::vector<unsigned char> none(256, 0);
  EXPECT_EQ(compare(test, ref, {}, 1.0, &none).normaliserPixels, 256u);
}

// e = S - T splits into the declared quantity's gap D - T and the estimator's S - D.
TEST(BenchMetrics, QuantityGapSplitsTheErrorAgainstTheTarget) {
  const Plane target{2, 1, {0.5f, 0.5f}}, declared{2, 1, {0.7f, 0.7f}};
  // S = D: all of the error is the gap; gap NRMSE = 0.2 / 0.5.
  QuantityGap g = quantityGap(declared, target, declared, {});
  EXPECT_NEAR(g.gapNrmse, 0.4, 1e-6);
  EXPECT_NEAR(g.gapShare, 1.0, 1e-6);
  // S = 0.8: e = 0.3 of which the gap 0.2 -> share 0.2 * 0.3 / 0.09 = 2/3.
  g = quantityGap(Plane{2, 1, {0.8f, 0.8f}}, target, declared, {});
  EXPECT_NEAR(g.gapShare, 2.0 / 3.0, 1e-6);
  // An estimator below the target cancels the gap: the gap's share is negative.
  g = quantityGap(Plane{2, 1, {0.4f, 0.4f}}, target, declared, {});
  EXPECT_NEAR(g.gapShare, 0.2 * -0.1 / 0.01, 1e-5);
  // S = T: no error to split (share 0, not NaN); the mask drops every pixel: all 0.
  g = quantityGap(target, target, declared, {});
  EXPECT_EQ(g.gapShare, 0.0);
  g = quantityGap(declared, target, declared, {0, 0});
  EXPECT_EQ(g.gapNrmse, 0.0);
  EXPECT_EQ(g.gapShare, 0.0);
}

TEST(BenchMetrics, ChannelAndLuminance) {
  const std::vector<float> rgba = {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1};
  const Plane r = channel(2, 2, rgba, 0), l = channel(2, 2, rgba, -1);
  EXPECT_EQ(r.values, (std::vector<float>{1, 0, 0, 1}));
  EXPECT_NEAR(l.values[3], 1.0f, 1e-6f);
  EXPECT_NEAR(l.values[1], 0.7152f, 1e-6f);
  EXPECT_NEAR(reinhard(r).values[0], 0.5f, 1e-6f);
}

}  // namespace
}  // namespace gi::bench
