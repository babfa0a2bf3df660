// The CPU reference and the lighting pass evaluate one light model: the same BRDF (Lambert plus
// the normalised Blinn-Phong lobe for the punctual lights) and the same emitters (one-sided
// unless the material is double-sided). Compared per pixel, raster "lit" against the
// reference's Direct quantity, on scenes where the reference has no noise (punctual lights and
// a constant environment over an unoccluded hemisphere: every sample gives the same value).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "gi/reference/reference.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

namespace ref = gi::reference;
constexpr uint32_t kW = 160, kH = 120;

class ReferenceLightModel : public test::VulkanTest {
 protected:
  static Scene sceneFrom(const std::string& json) {
    const std::string path = test::makeTempDir("light_model") + "/scene.json";
    std::ofstream(path) << json;
    return loadSceneJson(path);
  }
  static ImageRGBA32F rasterLit(const Scene& scene) {
    RenderSettings rs;
    rs.width = kW;
    rs.height = kH;
    Renderer renderer(ctx(), scene, rs);
    renderer.renderFrame();
    return renderer.readTarget("lit");
  }
  static ref::Result reference(const Scene& scene, ref::Quantity q, uint32_t spp) {
    ref::Settings s;
    s.quantity = q;
    s.width = kW;
    s.height = kH;
    s.spp = spp;
    s.threads = 2;
    return ref::render(scene, s);
  }

  // Per-pixel agreement on the reference's geometry pixels: |raster - reference| <= 2% of the
  // reference + 0.003 (the G-buffer's 8-bit sRGB albedo and roughness, octahedral normals).
  // At most 0.5% of them may lie outside: silhouette pixels, where rasterisation and the ray
  // through the pixel centre can see different surfaces.
  struct Agreement {
    size_t compared = 0, outside = 0;
    double worst = 0.0;  // largest |difference| / (0.02 reference + 0.003)
  };
  static Agreement agree(const ImageRGBA32F& lit, const ref::Result& r) {
    Agreement a;
    for (size_t i = 0; i < size_t(kW) * kH; ++i) {
      if (r.value.pixels[i * 4 + 3] <= 0.0f) continue;
      ++a.compared;
      double worst = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double want = r.value.pixels[i * 4 + c];
        const double got = lit.pixels[i * 4 + c];
        EXPECT_TRUE(std::isfinite(got) && std::isfinite(want)) << "pixel " << i;
        worst = std::max(worst, std::abs(got - want) / (0.02 * want + 0.003));
      }
      a.worst = std::max(a.worst, worst);
      a.outside += worst > 1.0 ? 1 : 0;
    }
    return a;
  }
};

// A glossy plane under a point light, seen at an angle so the highlight is in view; once
// dielectric (f0 0.04) and once metallic (f0 = albedo, no diffuse term at all).
TEST_F(ReferenceLightModel, AGlossyPlaneUnderAPointLightMatchesPerPixel) {
  for (const char* material :
       {R"("base_color": [0.7, 0.5, 0.3], "roughness": 0.45, "metallic": 0.0)",
        R"("base_color": [0.9, 0.6, 0.2], "roughness": 0.6, "metallic": 1.0)"}) {
    SCOPED_TRACE(material);
    const Scene scene = sceneFrom(std::string(R"({ "models": [
        { "primitive": "plane", "size": 6, "material": { )") +
                                  material + R"( } } ],
      "lights": [ { "type": "point", "position": [0, 1.2, -0.5], "intensity": 3,
                    "casts_shadows": false } ],
      "camera": { "position": [0, 1.5, 3], "target": [0, 0, -0.5] },
      "environment": { "type": "constant", "color": [1, 1, 1], "intensity": 0.2 } })");
    const ImageRGBA32F lit = rasterLit(scene);
    const ref::Result r = reference(scene, ref::Quantity::Direct, 4);
    const Agreement a = agree(lit, r);
    float peak = 0.0f;
    for (size_t i = 0; i < size_t(kW) * kH; ++i) peak = std::max(peak, r.value.pixels[i * 4 + 1]);
    std::printf("compared %zu pixels, %zu outside, worst %.2f of the tolerance; peak %.3f\n",
                a.compared, a.outside, a.worst, peak);
    EXPECT_GT(a.compared, size_t(kW) * kH / 2);
    EXPECT_LE(a.outside, a.compared / 200);
    // The metal has no diffuse term: all it shows is the lobe (a diffuse-only model: black).
    if (std::string(material).find("\"metallic\": 1.0") != std::string::npos) {
      EXPECT_GT(peak, 0.3);
    }
  }
}

// A lamp: an emissive quad facing down (its normal, -y) under a ceiling 5 mm above it, a floor
// below, seen from below and from above the ceiling-less side. One-sided: the lamp shows its
// emission from below only, and in the reference's direct + indirect light the ceiling strip
// above it gets nothing from it while the floor under it does. Double-sided: both.
TEST_F(ReferenceLightModel, ALampLightsOnlyItsFrontSideUnlessDoubleSided) {
  for (const bool doubleSided : {false, true}) {
    SCOPED_TRACE(doubleSided ? "double-sided" : "one-sided");
    const std::string lamp = std::string(R"(
        { "primitive": "plane", "size": [0.6, 0.6], "translation": [0, 1, 0],
          "rotation": [180, 0, 0],
          "material": { "base_color": [0.5, 0.5, 0.5], "emission": [6, 6, 6],
                        "double_sided": )") +
                             (doubleSided ? "true" : "false") + " } }";
    // Seen from below: the lamp's front; from above: its back (no ceiling in this one).
    for (const bool fromBelow : {true, false}) {
      SCOPED_TRACE(fromBelow ? "from below" : "from above");
      const Scene scene = sceneFrom(
          R"({ "models": [ { "primitive": "plane", "size": 4,
                             "material": { "base_color": [0.8, 0.8, 0.8] } },)" +
          lamp + "], " +
          (fromBelow ? R"("camera": { "position": [0, 0.3, 1.2], "target": [0, 1, 0] },)"
                     : R"("camera": { "position": [0, 2.2, 1.2], "target": [0, 1, 0] },)") +
          R"( "lights": [ { "type": "point", "position": [0, 0.8, 0], "intensity": 1,
                          "casts_shadows": false } ],
            "environment": { "type": "constant", "color": [0, 0, 0], "intensity": 0 } })");
      const ImageRGBA32F lit = rasterLit(scene);
      const ref::Result r = reference(scene, ref::Quantity::Direct, 4);
      // The image centre is the lamp (the camera aims at it).
      const size_t centre = (size_t(kH / 2) * kW + kW / 2) * 4;
      const bool emits = fromBelow || doubleSided;
      std::printf("lamp centre: raster %.3f, reference %.3f\n", lit.pixels[centre],
                  r.value.pixels[centre]);
      EXPECT_EQ(r.value.pixels[centre] > 5.0f, emits);  // else about 0.005 (the light's lobe)
      EXPECT_EQ(lit.pixels[centre] > 5.0f, emits);
      const Agreement a = agree(lit, r);
      EXPECT_LE(a.outside, a.compared / 200) << "worst " << a.worst;
    }
    // The lamp's other side: a ceiling 30 cm above it, seen from below over the lamp. Only the
    // double-sided lamp lights it (the room's lamp, 5 mm under its ceiling, lit a strip of it
    // in the reference alone when emitters were two-sided there).
    const Scene room = sceneFrom(
        R"({ "models": [ { "primitive": "plane", "size": 4,
                           "material": { "base_color": [0.8, 0.8, 0.8] } },
                         { "primitive": "plane", "size": 4, "translation": [0, 1.3, 0],
                           "rotation": [180, 0, 0],
                           "material": { "base_color": [0.8, 0.8, 0.8] } },)" +
        lamp + R"(], "camera": { "position": [0, 0.5, 2.5], "target": [0, 0.9, 0] },
          "lights": [ { "type": "point", "position": [0, 0.8, 0], "intensity": 0 } ],
          "environment": { "type": "constant", "color": [0, 0, 0], "intensity": 0 } })");
    const ref::Result r = reference(room, ref::Quantity::DirectIndirect, 64);
    // Mean over the ceiling's pixels within 1 of the lamp (not the lamp's) and over the
    // floor's.
    double ceiling = 0.0, floor = 0.0;
    size_t nc = 0, nf = 0;
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        const size_t i = size_t(y) * kW + x;
        if (r.value.pixels[i * 4 + 3] <= 0.0f || r.value.pixels[i * 4] > 5.0f) continue;
        const float worldY = r.position.pixels[i * 4 + 1];
        const float worldX = r.position.pixels[i * 4], worldZ = r.position.pixels[i * 4 + 2];
        if (worldY > 1.2f && worldX * worldX + worldZ * worldZ < 1.0f) {
          ceiling += r.value.pixels[i * 4];
          ++nc;
        } else if (worldY < 0.01f) {
          floor += r.value.pixels[i * 4];
          ++nf;
        }
      }
    ASSERT_GT(nc, 100u);
    ASSERT_GT(nf, 100u);
    ceiling /= double(nc);
    floor /= double(nf);
    std::printf("lamp light: ceiling %.4f, floor %.4f\n", ceiling, floor);
    EXPECT_GT(floor, 0.05);
    if (doubleSided)
      EXPECT_GT(ceiling, 0.05);
    else
      EXPECT_LT(ceiling, 0.01 * floor);
  }
}

}  // namespace
}  // namespace gi
