// The Alchemy plugin against its declared quantity: with many taps, no filter and a guard band
// wider than the tap disk, its AO is close to the CPU reference's alchemy-disk (the screen-disk
// integral its sum converges to, reference.h) and clearly farther from the hemisphere integral
// of eq. 8-9 (reference "alchemy"), which it used to declare. Vulkan (lavapipe) + Embree.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "effect_fixture.h"
#include "gi/reference/reference.h"
#include "gi/renderer.h"
#include "quad_scene.h"

namespace gi {
namespace {

namespace ref = gi::reference;

class AlchemyReference : public test::EffectTest {
 protected:
  std::string effectName() const override { return "alchemy"; }
};

// RMS difference over the pixels where both images hold geometry, over the mean of `b` there.
double nrmse(const ImageRGBA32F& a, const ImageRGBA32F& depth, const ImageRGBA32F& b,
             size_t& pixels) {
  double se = 0.0, sum = 0.0;
  pixels = 0;
  for (size_t i = 0; i < b.pixels.size() / 4; ++i) {
    if (!(depth.pixels[i * 4] > 0.0f) || !(b.pixels[i * 4 + 3] > 0.5f)) continue;
    const double d = double(a.pixels[i * 4]) - b.pixels[i * 4];
    se += d * d;
    sum += b.pixels[i * 4];
    ++pixels;
  }
  return pixels > 0 ? std::sqrt(se / double(pixels)) / std::max(sum / double(pixels), 1e-9) : 0.0;
}

TEST_F(AlchemyReference, PluginConvergesToTheScreenDiskIntegral) {
  // The 90-degree corner with a free-standing panel in front of the wall (a depth edge and a
  // contact crease). 64 taps, no filter, a 48-pixel band (the disk of r = 0.5 is at most
  // ~20 pixels here), intensity 0.5 so that few pixels clamp at 0.
  test::Quads quads = test::cornerQuads();
  quads.push_back({glm::translate(glm::mat4(1.0f), glm::vec3(0, 0.3f, 0.4f)) *
                       glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 1, 0)) *
                       glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 0.8f)),
                   0.3f});
  const Scene scene = test::quadScene(quads, glm::vec3(2.5f, 1.6f, 0.0f), glm::vec3(0.0f));
  const uint32_t W = 128, H = 96;
  const RenderSettings rs = settingsFor(scene,
                                        {"alchemy.samples=64", "alchemy.blur_radius=0",
                                         "alchemy.guard_band=48", "alchemy.intensity=0.5"},
                                        W, H);
  Renderer renderer(ctx(), scene, rs, &registry);
  renderer.renderFrame();
  const ImageRGBA32F ao = renderer.readTarget("ao"), depth = renderer.readTarget("depth");
  ASSERT_TRUE(test::finite(ao));

  // The declaration, rendered as gi-bench renders it.
  const EstimatedQuantity q = registry.create("alchemy")->estimatedQuantity(rs.effects[0].settings);
  ASSERT_EQ(q.kind, EstimatedQuantity::Kind::AlchemyDisk);
  ASSERT_EQ(q.sigma, 0.5);
  ASSERT_EQ(q.bias, 1e-4);
  ref::Settings s;
  s.width = W;
  s.height = H;
  s.spp = 256;
  s.threads = 2;
  s.radius = float(q.radius);
  s.alchemy = ref::AlchemyParams{float(q.sigma), float(q.u), float(q.epsilon), float(q.contrast),
                                 float(q.bias)};
  s.quantity = ref::Quantity::AlchemyDisk;
  const ref::Result disk = ref::render(scene, s);
  s.quantity = ref::Quantity::Alchemy;
  const ref::Result hemisphere = ref::render(scene, s);
  size_t n = 0;
  const double toDisk = nrmse(ao, depth, disk.value, n);
  const double toHemisphere = nrmse(ao, depth, hemisphere.value, n);
  double meanAo = 0.0, meanDisk = 0.0;
  for (size_t i = 0; i < size_t(W) * H; ++i)
    if (depth.pixels[i * 4] > 0.0f && disk.value.pixels[i * 4 + 3] > 0.5f) {
      meanAo += ao.pixels[i * 4] / double(n);
      meanDisk += disk.value.pixels[i * 4] / double(n);
    }
  std::printf(
      "%zu pixels: NRMSE to alchemy-disk %.4f (reference mean se %.4f), to alchemy (hemisphere) "
      "%.4f; mean A plugin %.4f, alchemy-disk %.4f\n",
      n, toDisk, disk.meanStdError, toHemisphere, meanAo, meanDisk);
  EXPECT_GT(n, size_t(W * H / 2));
  EXPECT_LT(toDisk, 0.05);
  EXPECT_LT(std::abs(meanAo - meanDisk), 0.01);
  EXPECT_GT(toHemisphere, 3.0 * toDisk);
}

}  // namespace
}  // namespace gi
