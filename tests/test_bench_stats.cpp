// gi-bench's measurement: order-statistics intervals cover a synthetic timing source's true
// median at their stated rate; the Pareto front and the calibration ignore differences inside
// the intervals (and calibration assumes monotone cost); an effect's declared quantity and its
// parameters reach the reference it is compared with (the cache key follows the radius).
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "quantity.h"
#include "stats.h"
#include "test_support.h"

namespace gi::bench {
namespace {

namespace fs = std::filesystem;
namespace ref = gi::reference;

// A repetition of a synthetic configuration: the median over `frames` frames of a true time
// plus Gaussian noise (symmetric, so the repetition medians have the true time as median).
double repetition(std::mt19937_64& rng, double truth, double sigma, int frames) {
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> f;
  for (int i = 0; i < frames; ++i) f.push_back(truth + noise(rng));
  return median(f);
}

TEST(BenchStats, IntervalCoverageIsTheBinomialOne) {
  EXPECT_DOUBLE_EQ(medianInterval({1, 2, 3, 4, 5}).coverage, 1.0 - 2.0 / 32.0);  // [min, max]
  EXPECT_DOUBLE_EQ(medianInterval({1, 2, 3, 4, 5, 6}).coverage, 1.0 - 2.0 / 64.0);
  const Interval ten = medianInterval({10, 9, 8, 7, 6, 5, 4, 3, 2, 1});
  EXPECT_DOUBLE_EQ(ten.coverage, 1.0 - 2.0 * 11.0 / 1024.0);  // [x_(2), x_(9)]
  EXPECT_DOUBLE_EQ(ten.lo, 2.0);
  EXPECT_DOUBLE_EQ(ten.hi, 9.0);
  EXPECT_DOUBLE_EQ(ten.median, 5.5);
  const Interval one = medianInterval({3.0});
  EXPECT_EQ(one.lo, 3.0);
  EXPECT_EQ(one.hi, 3.0);
  EXPECT_EQ(one.coverage, 0.0);
  EXPECT_EQ(medianInterval({}).samples, 0u);
}

TEST(BenchStats, IntervalsCoverTheTrueTimeAtTheStatedRate) {
  std::mt19937_64 rng(7);
  for (int reps : {5, 7, 12}) {
    const double truth = 4.0;
    int covered = 0;
    double coverage = 0.0;
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<double> r;
      for (int k = 0; k < reps; ++k) r.push_back(repetition(rng, truth, 0.3, 5));
      const Interval i = medianInterval(r);
      covered += i.lo <= truth && truth <= i.hi;
      coverage = i.coverage;
      EXPECT_LE(i.lo, i.median);
      EXPECT_LE(i.median, i.hi);
    }
    EXPECT_GE(coverage, reps >= 6 ? 0.95 : 0.93);
    // 200 Bernoulli trials at p >= 0.9375: >= 180 unless 4+ sigma unlucky (fixed seed anyway).
    EXPECT_GE(covered, 180) << reps << " repetitions, stated coverage " << coverage;
  }
}

Interval around(double median, double halfWidth) {
  return Interval{median, median - halfWidth, median + halfWidth, 0.9375, 5};
}

TEST(BenchStats, ParetoFrontIgnoresTimeDifferencesInsideTheIntervals) {
  // A is faster by median but within B's interval and less accurate: B dominates it.
  std::vector<TradeoffPoint> p = {{around(1.00, 0.2), 0.30}, {around(1.10, 0.2), 0.20}};
  EXPECT_EQ(paretoFront(p), std::vector<size_t>({1}));
  // Clearly faster (intervals disjoint): both stay, in time order.
  p = {{around(2.0, 0.1), 0.20}, {around(1.0, 0.1), 0.30}};
  EXPECT_EQ(paretoFront(p), std::vector<size_t>({1, 0}));
  // Equal error, overlapping times: the cheaper median only.
  p = {{around(1.05, 0.2), 0.25}, {around(1.00, 0.2), 0.25}};
  EXPECT_EQ(paretoFront(p), std::vector<size_t>({1}));
  // A clearly slower, more accurate point stays; a slower, less accurate one goes.
  p = {{around(1.0, 0.1), 0.3}, {around(3.0, 0.1), 0.1}, {around(3.1, 0.3), 0.2}};
  EXPECT_EQ(paretoFront(p), std::vector<size_t>({0, 1}));
}

TEST(BenchStats, CalibrationAssumesMonotoneCostAndKeepsTheNoiseMargin) {
  // Sample counts 1..64, true cost 0.5 ms per sample, accuracy improving with the count;
  // limit 18 ms: 32 samples (16 ms) is the right choice.
  std::vector<CalibrationCandidate> c;
  for (int n = 1; n <= 64; n *= 2) c.push_back({{n}, around(0.5 * n, 0.2), 1.0 / n});
  const double limit = 18.0;
  CalibrationChoice pick = chooseCalibrated(c, limit);
  ASSERT_TRUE(pick.index);
  EXPECT_EQ(c[*pick.index].counts[0], 32);
  EXPECT_NEAR(pick.marginMs, limit - 16.2, 1e-12);
  EXPECT_NEAR(pick.noiseMarginMs, 0.2, 1e-12);

  // One noisy outlier: 64 samples measured far too cheap, its interval overlapping the
  // 32-sample one. Naively it would fit and win on accuracy; cost does not fall when the count
  // rises unless measured clearly lower, so its bound is 32's and 32 stays the choice.
  c.back().ms = Interval{16.0, 14.0, 17.5, 0.9375, 5};
  c[5].ms = Interval{18.2, 17.0, 19.0, 0.9375, 5};  // 32 samples, upper end above the limit
  pick = chooseCalibrated(c, limit);
  ASSERT_TRUE(pick.index);
  EXPECT_EQ(c[*pick.index].counts[0], 16) << "32 does not fit, 64 is bounded by 32";
  EXPECT_DOUBLE_EQ(pick.boundMs[6], 19.0);
  // Measured clearly cheaper (interval wholly below 32's): the measurement is believed.
  c.back().ms = Interval{15.0, 14.5, 15.5, 0.9375, 5};
  c[5].ms = Interval{18.2, 17.0, 19.0, 0.9375, 5};
  pick = chooseCalibrated(c, limit);
  EXPECT_EQ(c[*pick.index].counts[0], 64);

  // Equal accuracy within the tolerance: the smaller bound wins (the cheaper, safer option).
  std::vector<CalibrationCandidate> tie = {{{4}, around(4.0, 0.5), 0.1},
                                           {{2}, around(2.0, 0.5), 0.1 + 1e-13}};
  pick = chooseCalibrated(tie, 10.0);
  EXPECT_EQ(*pick.index, 1u);
  // Nothing fits.
  EXPECT_FALSE(chooseCalibrated(tie, 1.0).index);
}

// An effect that declares obscurance with the linear membership of its `radius` setting.
class LinearObscurance : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    gi::EffectInfo i;
    i.name = "linear_obscurance";
    i.writes = {gi::resources::kAO};
    i.estimates = gi::GroundTruth::AmbientOcclusion;
    return i;
  }
  std::vector<gi::SettingDesc> settings() const override {
    return {gi::SettingDesc::length("radius", 0.5, 1e-6, 1e9, "R")};
  }
  void prepare(gi::EffectContext&, const gi::SettingValues&) override {}
  void addPasses(gi::FrameGraph&, gi::EffectContext&, const gi::SettingValues&) override {}
  gi::EstimatedQuantity estimatedQuantity(const gi::SettingValues& s) const override {
    gi::EstimatedQuantity q;
    q.kind = gi::EstimatedQuantity::Kind::Obscurance;
    q.radius = s.number("radius");
    q.membership = "linear";
    return q;
  }
};

TEST(BenchQuantity, DeclaredObscuranceAndItsSettingsReachTheReference) {
  const LinearObscurance effect;
  gi::SettingValues s("linear_obscurance", effect.settings());
  s.setFromString("radius", "0.25", "test");
  const gi::EstimatedQuantity q = effect.estimatedQuantity(s);
  const ReferenceSpec declared = declaredSpec(q);
  EXPECT_EQ(declared.quantity, ref::Quantity::Obscurance);
  EXPECT_EQ(declared.membership, ref::Membership::Linear);
  EXPECT_EQ(declared.radius, 0.25f);
  EXPECT_EQ(label(declared), "obscurance linear r=0.25");
  ref::Settings rs;
  apply(declared, rs);
  EXPECT_EQ(rs.quantity, ref::Quantity::Obscurance);
  EXPECT_EQ(rs.membership, ref::Membership::Linear);
  EXPECT_EQ(rs.radius, 0.25f);
  // The target beside it: AO of the same radius.
  const ReferenceSpec target = targetSpec(effect.info().estimates, q, false);
  EXPECT_EQ(target.quantity, ref::Quantity::AO);
  EXPECT_EQ(target.radius, 0.25f);
  EXPECT_NE(keyText(target), keyText(declared));
  // Another radius: another reference (the cache key holds it).
  s.setFromString("radius", "0.3", "test");
  const ReferenceSpec other = declaredSpec(effect.estimatedQuantity(s));
  EXPECT_NE(keyText(other), keyText(declared));
  EXPECT_TRUE(other < declared || declared < other);
  // Parameters a quantity does not use do not split the cache.
  ReferenceSpec direct, direct2;
  direct2.radius = 3.0f;
  EXPECT_EQ(keyText(direct), keyText(direct2));
  // Unknown memberships and bad radii are errors, not silent defaults.
  gi::EstimatedQuantity bad = q;
  bad.membership = "cubic";
  EXPECT_THROW(declaredSpec(bad), gi::Error);
  bad = q;
  bad.radius = 0.0;
  EXPECT_THROW(declaredSpec(bad), gi::Error);
}

TEST(BenchQuantity, PluginsDeclareWhatTheyEstimate) {
  const std::string dir = test::binPath("plugins");
  if (!fs::exists(dir + "/gi_effect_ssao.so")) GTEST_SKIP() << "plugins not built";
  gi::EffectRegistry registry;
  registry.scanDirectory(dir);
  auto spec = [&](const std::string& name, const std::vector<std::string>& sets) {
    gi::SettingValues s = registry.defaultSettings(name);
    for (const std::string& kv : sets) {
      const size_t eq = kv.find('=');
      s.setFromString(kv.substr(0, eq), kv.substr(eq + 1), "test");
    }
    return declaredSpec(registry.create(name)->estimatedQuantity(s));
  };
  ASSERT_TRUE(registry.has("ssao"));
  const ReferenceSpec ssao = spec("ssao", {"radius=0.7"});
  EXPECT_EQ(label(ssao), "obscurance linear r=0.7");
  EXPECT_NE(keyText(ssao), keyText(spec("ssao", {"radius=0.8"})));
  if (registry.has("obscurance")) {
    EXPECT_EQ(label(spec("obscurance", {"membership=smoothstep"})), "obscurance smoothstep r=0.5");
    EXPECT_EQ(spec("obscurance", {"transfer=albedo"}).quantity, ref::Quantity::AO);
  }
  if (registry.has("alchemy")) {
    const ReferenceSpec a =
        spec("alchemy", {"intensity=2", "contrast=1.5", "epsilon=0.001", "bias=0.002"});
    EXPECT_EQ(a.quantity, ref::Quantity::AlchemyDisk);  // the screen-disk integral
    EXPECT_EQ(a.alchemy.sigma, 2.0f);
    EXPECT_EQ(a.alchemy.contrast, 1.5f);
    EXPECT_EQ(a.alchemy.epsilon, float(0.001 * 0.5 * 0.5));  // the setting is relative to r^2
    EXPECT_EQ(a.alchemy.u, 0.0f);
    EXPECT_EQ(a.alchemy.bias, 0.002f);
    EXPECT_EQ(label(a), "alchemy-disk r=0.5 sigma=2 u=0 eps=0.00025 k=1.5 bias=0.002");
    EXPECT_NE(
        keyText(a),
        keyText(spec("alchemy", {"intensity=2", "contrast=1.5", "epsilon=0.001", "bias=0.003"})));
  }
  for (const char* ao : {"hbao", "gtao"})
    if (registry.has(ao)) {
      EXPECT_EQ(label(spec(ao, {"radius=0.4"})), "ao r=0.4") << ao;
    }
}

}  // namespace
}  // namespace gi::bench
