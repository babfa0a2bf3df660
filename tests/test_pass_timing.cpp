// Per-pass GPU timing: every executed pass gets a finite, non-negative time that fits inside
// the frame's wall-clock time; --isolate-passes (one submission per pass) renders exactly the
// same image and the same passes.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

class PassTimingTest : public VulkanTest {};

struct Result {
  ImageRGBA8 image;
  std::vector<std::string> passes;
  std::vector<PassTiming> timings;
  double wallMs = 0.0;
};

Result renderOnce(vk::Context& ctx, bool isolate) {
  const Scene scene = makeDefaultScene();
  RenderSettings rs;
  rs.width = 96;
  rs.height = 72;
  rs.isolatePasses = isolate;
  rs.floorPass = true;
  Renderer r(ctx, scene, rs);
  r.renderFrame();  // warm-up (pipeline compilation on first use)
  const auto start = std::chrono::steady_clock::now();
  r.renderFrame();
  const double wall =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return {r.readOutput(), r.passNames(), r.lastTimings(), wall};
}

TEST_F(PassTimingTest, EveryPassIsTimedWithinTheFrame) {
  for (bool isolate : {false, true}) {
    const Result res = renderOnce(ctx(), isolate);
    ASSERT_EQ(res.timings.size(), res.passes.size());
    double sum = 0.0;
    for (size_t i = 0; i < res.timings.size(); ++i) {
      EXPECT_EQ(res.timings[i].name, res.passes[i]);
      EXPECT_TRUE(std::isfinite(res.timings[i].ms) && res.timings[i].ms >= 0.0)
          << res.timings[i].name;
      sum += res.timings[i].ms;
    }
    // Timestamps of work inside one submitted frame cannot add up to more than its wall time.
    EXPECT_LE(sum, res.wallMs + 0.5) << "isolate " << isolate;
  }
}

TEST_F(PassTimingTest, IsolatedPassesRenderTheSameImage) {
  const Result together = renderOnce(ctx(), false), isolated = renderOnce(ctx(), true);
  EXPECT_EQ(together.passes, isolated.passes);
  ASSERT_EQ(together.image.pixels.size(), isolated.image.pixels.size());
  EXPECT_EQ(together.image.pixels, isolated.image.pixels);
}

}  // namespace
}  // namespace gi
