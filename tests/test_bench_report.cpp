// gi-bench's report pieces that need no measurement: the plots' layout (the error axis from 0,
// a logarithmic time axis once times span more than 10x, labels that would overlap left out)
// and the rows' share of the engine alone's error they remove.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bench.h"
#include "plot.h"

namespace gi::bench {
namespace {

PlotPoint point(double ms, double error, const std::string& label) {
  PlotPoint p;
  p.time = ms;
  p.timeLo = 0.9 * ms;
  p.timeHi = 1.1 * ms;
  p.error = error;
  p.label = label;
  return p;
}

TEST(BenchReport, TimeAxisTurnsLogarithmicBeyondTenfoldAndErrorAxisStartsAtZero) {
  Plot narrow;
  narrow.xLabel = "ms";
  narrow.series.push_back({"a", {point(10, 0.2, "low"), point(40, 0.18, "high")}});
  const PlotLayout n = layoutFor(narrow);
  EXPECT_FALSE(n.logX);
  EXPECT_EQ(n.xTicks.front(), 0.0);
  EXPECT_EQ(n.yTicks.front(), 0.0);
  EXPECT_EQ(n.xLabel(narrow), "ms");

  Plot wide = narrow;
  wide.series[0].points.push_back(point(700, 0.17, "ultra"));
  const PlotLayout w = layoutFor(wide);
  EXPECT_TRUE(w.logX);
  EXPECT_EQ(w.xMin, 1.0);  // the decade below 9 ms
  EXPECT_EQ(w.xMax, 1000.0);
  EXPECT_EQ(w.xLabel(wide), "ms, log scale");
  EXPECT_EQ(w.yTicks.front(), 0.0);
  // Decades map to equal widths; the points keep their order.
  EXPECT_NEAR(w.x(10) - w.x(1), w.x(100) - w.x(10), 1e-9);
  EXPECT_LT(w.x(10), w.x(40));
  EXPECT_LT(w.x(40), w.x(700));
  EXPECT_DOUBLE_EQ(w.x(0.0), w.x(1.0));  // clamped to the axis
}

TEST(BenchReport, OverlappingLabelsAreLeftOut) {
  Plot p;
  p.series.push_back(
      {"a", {point(10, 0.2, "low"), point(10.1, 0.2005, "medium"), point(80, 0.1, "high")}});
  p.series.push_back({"b", {point(10.05, 0.2002, "other")}});
  const PlotLayout l = layoutFor(p);
  ASSERT_EQ(l.labelShown.size(), 2u);
  EXPECT_EQ(l.labelShown[0], (std::vector<bool>{true, false, true}));
  EXPECT_EQ(l.labelShown[1], (std::vector<bool>{false}));
}

Row row(const std::string& effect, const std::string& preset, double nrmse, double testMean) {
  Row r;
  r.scene = "room";
  r.effect = effect;
  r.preset = preset;
  r.reference = "direct+indirect spp=256";
  r.declared = effect == "none" ? "direct spp=256" : "direct+indirect spp=256";
  r.nrmse = nrmse;
  r.testMean = testMean;
  r.targetMean = 0.6;
  r.declaredMean = 0.4;  // the engine alone's: the direct reference
  return r;
}

TEST(BenchReport, RowsMeasureWhatTheyRecoverAgainstTheEngineAloneOfTheirPreset) {
  std::vector<Row> rows = {row("none", "low", 0.4, 0.45),  row("ism", "low", 0.1, 0.55),
                           row("gtao", "low", 0.5, 0.40),  row("none", "high", 0.5, 0.45),
                           row("ism", "high", 0.25, 0.50), row("ism", "ultra", 0.2, 0.5)};
  fillRecovered(rows);
  EXPECT_TRUE(rows[0].recoveredPresent);
  EXPECT_DOUBLE_EQ(rows[0].errorRemoved, 0.0);
  EXPECT_DOUBLE_EQ(rows[1].errorRemoved, 0.75);        // 1 - 0.1 / 0.4
  EXPECT_DOUBLE_EQ(rows[1].indirectDelivered, 0.5);    // (0.55 - 0.45) / (0.6 - 0.4)
  EXPECT_DOUBLE_EQ(rows[2].errorRemoved, -0.25);       // adds error
  EXPECT_DOUBLE_EQ(rows[2].indirectDelivered, -0.25);  // takes light away
  EXPECT_DOUBLE_EQ(rows[4].errorRemoved, 0.5);         // against high's engine alone
  EXPECT_FALSE(rows[5].recoveredPresent);              // no engine alone at ultra
}

}  // namespace
}  // namespace gi::bench
