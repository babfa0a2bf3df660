// SSDO with up to four depth layers (effects/ssdo, `layers` 1..4): the frame graph runs
// layers - 1 peel passes, and the second solid interval [layer 2, layer 3] finds an occluder
// hidden behind another one (seed 000 §4, extended past its two layers).
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <fstream>
#include <string>

#include "effect_fixture.h"
#include "gi/effect_config.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "quad_scene.h"
#include "ssdo_frames.h"
#include "test_support.h"

namespace gi {
namespace {

constexpr uint32_t kW = 160, kH = 120;

class SsdoLayersTest : public test::EffectTest {
 protected:
  std::string effectName() const override { return "ssdo"; }
  RenderSettings settingsFor(const Scene& scene, const std::vector<std::string>& sets) const {
    return EffectTest::settingsFor(scene, sets, kW, kH);
  }
  test::SsdoFrame render(const Scene& scene, const std::vector<std::string>& sets,
                         std::vector<std::string>* passes = nullptr) {
    Renderer r(ctx(), scene, settingsFor(scene, sets), &registry);
    r.renderFrame();
    if (passes) *passes = r.passNames();
    // Without the bounce SSDO publishes no "indirect": an empty image stands in.
    const bool bounce = std::find(sets.begin(), sets.end(), "ssdo.bounce=false") == sets.end();
    return test::SsdoFrame(test::ssdoAmbientRadiance(r),
                           bounce ? r.readTarget("indirect") : ImageRGBA32F{},
                           r.readTarget("depth"), r.camera());
  }
  Scene jsonScene(const std::string& name, const std::string& json) {
    const std::string path = test::makeTempDir("scenes") + "/ssdo_layers_" + name + ".json";
    {
      std::ofstream f(path);
      f << json;
    }
    return loadSceneJson(path);
  }
};

TEST_F(SsdoLayersTest, TheGraphRunsLayersMinusOnePeelPasses) {
  const Scene scene = test::cornerScene();  // no lights: no shadow pass
  using V = std::vector<std::string>;
  const V peels = {"ssdo_peel", "ssdo_peel2", "ssdo_peel3"};
  for (int k = 1; k <= 4; ++k) {
    std::vector<std::string> passes;
    const test::SsdoFrame f = render(scene, {"ssdo.layers=" + std::to_string(k)}, &passes);
    EXPECT_TRUE(test::finite(f.ambient)) << k;
    EXPECT_TRUE(test::finite(f.indirect)) << k;
    V expected = {"gbuffer"};
    expected.insert(expected.end(), peels.begin(), peels.begin() + (k - 1));
    for (const char* p : {"ssdo_surface", "ssdo", "ssdo_blur", "lighting", "tonemap"})
      expected.push_back(p);
    EXPECT_EQ(passes, expected) << "layers " << k;
  }
  const SettingDesc d = registry.defaultSettings("ssdo").desc("layers");
  EXPECT_EQ(d.defaultValue, 2.0) << "seed 000 §4 and issue 12: two depth layers by default";
  EXPECT_EQ(d.minValue, 1.0);
  EXPECT_EQ(d.maxValue, 4.0);
  test::expectError([&] { settingsFor(scene, {"ssdo.layers=5"}); }, ErrorKind::InvalidData,
                    {"layers"});
}

// Two slabs in a row under the camera, over a floor: A (y 0.975..1.025) and B (y 0.2..0.3),
// both over x < 0; the camera right above x = 0 (their edges project onto the image's middle
// column), R = 0.5, a constant white environment, grey floor (open: ambient ~0.5). A floor point
// just right of x = 0 has samples over x < 0; the view ray to such a sample crosses A's top and
// bottom, B's top and bottom, then the floor: layers 0..3 are A, A, B, B. Truly (and as SSDO
// computes it without A: B is then layers 0 and 1) the samples inside B are blocked.
// - 1 layer: A is more than R in front of every sample: open (the range guard).
// - 2 layers: every sample is behind [A top, A bottom]: open. B is missed: too bright.
// - 3 layers: [B top, + R] (no fourth layer: the range guard): the samples under B, between the
//   slab and the floor, count as blocked: too dark.
// - 4 layers: [B top, B bottom]: what SSDO gives without A, within 1% per pixel (layers 2 and 3
//   are half floats: 2^-11 relative, ~2 mm here, against float 1/z without A).
TEST_F(SsdoLayersTest, TheThirdAndFourthLayersFindASlabBehindAnother) {
  auto scene = [&](bool withA) {
    const std::string a = R"(,
        { "primitive": "box", "size": [4, 0.05, 6], "translation": [-2, 1.0, 0],
          "material": { "base_color": [0.5, 0.5, 0.5] } })";
    return jsonScene(withA ? "ab" : "b", std::string(R"({
      "models": [
        { "primitive": "plane", "size": 40, "material": { "base_color": [0.5, 0.5, 0.5] } },
        { "primitive": "box", "size": [4, 0.1, 6], "translation": [-2, 0.25, 0],
          "material": { "base_color": [0.5, 0.5, 0.5] } })") +
                                             (withA ? a : "") + R"( ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 3, 1.5], "target": [0, 0, 0] },
      "environment": { "type": "constant", "color": [1, 1, 1] } })");
  };
  const Scene ab = scene(true), b = scene(false);
  const std::vector<std::string> base = {"ssdo.radius=0.5", "ssdo.bounce=false"};
  auto with = [&](int layers) {
    std::vector<std::string> s = base;
    s.push_back("ssdo.layers=" + std::to_string(layers));
    return s;
  };
  const test::SsdoFrame truth = render(b, with(2));
  // The floor band next to the slabs' edge, where the samples reach over x < 0.
  auto band = [](glm::vec3 p) {
    return std::abs(p.y) < 1e-3f && p.x > 0.02f && p.x < 0.3f && std::abs(p.z) < 1.0f;
  };
  // The open floor, 1.2 .. 2 from the edge: nothing within R (albedo 0.5 after its 8-bit sRGB
  // quantization).
  auto open = [](glm::vec3 p) {
    return std::abs(p.y) < 1e-3f && p.x > 1.2f && p.x < 2.0f && std::abs(p.z) < 1.0f;
  };
  std::vector<glm::ivec2> pixels;
  double truthMean = 0.0, openMean = 0.0;
  int nOpen = 0;
  for (int y = 0; y < truth.h; ++y)
    for (int x = 0; x < truth.w; ++x) {
      if (truth.sky(x, y)) continue;
      const float v = truth.ambient.pixels[(size_t(y) * kW + x) * 4];
      if (band(truth.worldAt(x, y))) {
        pixels.emplace_back(x, y);
        truthMean += v;
      } else if (open(truth.worldAt(x, y))) {
        openMean += v;
        ++nOpen;
      }
    }
  ASSERT_GT(pixels.size(), 100u);
  ASSERT_GT(nOpen, 100);
  truthMean /= double(pixels.size());
  openMean /= nOpen;
  double mean[5] = {0, 0, 0, 0, 0};
  float worst4 = 0.0f;
  for (int layers = 1; layers <= 4; ++layers) {
    const test::SsdoFrame f = render(ab, with(layers));
    for (const glm::ivec2& p : pixels) {
      ASSERT_EQ(f.depthAt(p.x, p.y), truth.depthAt(p.x, p.y)) << "the band must show the floor";
      const float v = f.ambient.pixels[(size_t(p.y) * kW + p.x) * 4];
      mean[layers] += v;
      if (layers == 4) {
        const float t = truth.ambient.pixels[(size_t(p.y) * kW + p.x) * 4];
        worst4 = std::max(worst4, std::abs(v - t));
      }
    }
    mean[layers] /= double(pixels.size());
  }
  std::printf(
      "floor next to the slabs (%zu px), open floor %.4f: without A %.4f; with A, layers 1: %.4f, "
      "2: %.4f, 3: %.4f, 4: %.4f (worst pixel off by %.4f)\n",
      pixels.size(), openMean, truthMean, mean[1], mean[2], mean[3], mean[4], worst4);
  // Measured: open 0.4961, without A 0.4746; with A 0.4961, 0.4961, 0.4345, 0.4746 (worst 0).
  const double shadow = openMean - truthMean;
  ASSERT_GT(shadow, 0.01) << "B must shadow the band";
  EXPECT_NEAR(mean[1], openMean, 1e-3) << "one layer: A is out of range";
  EXPECT_NEAR(mean[2], openMean, 1e-3) << "two layers: behind A's interval, B missed";
  EXPECT_LT(mean[3], truthMean - 0.5 * shadow) << "three layers: below B counts as blocked";
  EXPECT_LT(worst4, 0.005f) << "four layers: B's interval as without A";
  EXPECT_NEAR(mean[4], truthMean, 0.1 * shadow);
}

// The hard cases of test_ssdo's NoNaN test (grazing eye, extreme clip planes, looking into the
// sky) with 3 and 4 layers, the bounce, the smallest distance clamp and an additional camera:
// finite and non-negative everywhere.
TEST_F(SsdoLayersTest, ThreeAndFourLayersStayFiniteInTheHardCases) {
  for (const test::HardCornerView& k : test::hardCornerViews()) {
    const Scene s = k.scene();
    for (const char* layers : {"ssdo.layers=3", "ssdo.layers=4"}) {
      const test::SsdoFrame f =
          render(s, {layers, "ssdo.bounce=true", "ssdo.distance_clamp=1e-6", "ssdo.cameras=1"});
      EXPECT_TRUE(test::finite(f.ambient)) << layers << " near " << k.znear;
      EXPECT_TRUE(test::finite(f.indirect)) << layers << " near " << k.znear;
      for (size_t i = 0; i < f.ambient.pixels.size(); ++i) ASSERT_GE(f.ambient.pixels[i], 0.0f);
      for (size_t i = 0; i < f.indirect.pixels.size(); ++i) ASSERT_GE(f.indirect.pixels[i], 0.0f);
    }
  }
}

}  // namespace
}  // namespace gi
