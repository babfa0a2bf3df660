// The SSDO plugin (effects/ssdo) on analytic scenes: the directional term of an open plane
// under a constant environment is albedo x radiance; next to a box under a two-colour sky the
// shadow takes the colour of the unblocked sky where SSAO's shadow is grey; the bounce tints a
// white floor with a yellow emissive wall's colour, fading with distance, and a back-facing
// platform's top gives nothing; everything stays finite at grazing angles, extreme clip planes, sky
// pixels and touching occluders; the pass list follows the bounce and blur settings.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>

#include "../effects/ssdo/ssdo_samples.h"
#include "effect_fixture.h"
#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "quad_scene.h"
#include "ssdo_frames.h"
#include "test_support.h"

namespace gi {
namespace {

// A w x h Radiance .hdr (flat RGBE texels, rows top to bottom: row 0 looks up) of texel(x, y).
using Rgbe = std::array<unsigned char, 4>;
void writeRgbeMap(const std::string& path, int w, int h,
                  const std::function<Rgbe(int, int)>& texel) {
  std::ofstream out(path, std::ios::binary);
  out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " << h << " +X " << w << "\n";
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgbe t = texel(x, y);
      out.write(reinterpret_cast<const char*>(t.data()), 4);
    }
}

constexpr uint32_t kW = 160, kH = 120;

using test::finite;

class SsdoTest : public test::EffectTest {
 protected:
  std::string effectName() const override { return "ssdo"; }
  struct Result {
    // ambient: as radiance (albedo applied, as the lighting pass does); ambientRaw: as SSDO
    // publishes it, per unit diffuse albedo (alpha 2).
    ImageRGBA32F ambient, ambientRaw, indirect, lit, depth;
    CameraView camera;
    int w = 0, h = 0;
    glm::vec3 px(const ImageRGBA32F& img, int x, int y) const {
      const float* p = &img.pixels[(size_t(y) * w + x) * 4];
      return {p[0], p[1], p[2]};
    }
    float depthAt(int x, int y) const { return depth.pixels[(size_t(y) * w + x) * 4]; }
    bool sky(int x, int y) const { return depthAt(x, y) <= 0.0f; }
    glm::vec3 worldAt(int x, int y) const {
      glm::vec4 v = glm::inverse(camera.proj) *
                    glm::vec4((x + 0.5f) / w * 2 - 1, (y + 0.5f) / h * 2 - 1, depthAt(x, y), 1.0f);
      return glm::vec3(glm::inverse(camera.view) * glm::vec4(glm::vec3(v) / v.w, 1.0f));
    }
  };
  // The settings of SSDO, of `effect` instead ("ssao") or, for "", of no effect.
  RenderSettings settingsFor(const Scene& scene, const std::string& effect,
                             const std::vector<std::string>& sets) const {
    return EffectTest::settingsFor(
        effect.empty() ? std::vector<std::string>{} : std::vector<std::string>{effect}, scene, sets,
        kW, kH);
  }
  // Renders one frame; `ambient` is read only when SSDO ran, `indirect` only when it ran with
  // the bounce (without it SSDO publishes none).
  Result render(const Scene& scene, const std::vector<std::string>& sets,
                const std::string& effect = "ssdo") {
    Renderer r(ctx(), scene, settingsFor(scene, effect, sets), &registry);
    r.renderFrame();
    Result res;
    if (effect == "ssdo") {
      res.ambient = test::ssdoAmbientRadiance(r);
      res.ambientRaw = r.readTarget("ambient");
      if (std::find(sets.begin(), sets.end(), "ssdo.bounce=false") == sets.end())
        res.indirect = r.readTarget("indirect");
    }
    res.lit = r.readTarget("lit");
    res.depth = r.readTarget("depth");
    res.camera = r.camera();
    res.w = int(kW);
    res.h = int(kH);
    return res;
  }
  // JSON scenes: a scene without lights gets a default sun, so each names one of intensity 0
  // (the environment and emission are then the only light).
  Scene jsonScene(const std::string& name, const std::string& json) {
    const std::string path = test::makeTempDir("scenes") + "/ssdo_" + name + ".json";
    {
      std::ofstream f(path);
      f << json;
    }
    return loadSceneJson(path);
  }
  // A yellow emissive wall (emission 1; x = 0, y in [0, 2], z in [-1, 1], facing +x) on a
  // white floor, no other light, seen from (3, 2.5, 0).
  Scene yellowWall(const std::string& name) {
    return jsonScene(name, R"({
      "models": [
        { "primitive": "plane", "size": 40, "material": { "base_color": [1, 1, 1] } },
        { "primitive": "plane", "size": 2, "translation": [0, 1, 0], "rotation": [0, 0, -90],
          "material": { "base_color": [1, 1, 0], "emission": [1, 1, 0] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [3, 2.5, 0], "target": [0.5, 0, 0] },
      "environment": { "type": "constant", "color": [0, 0, 0] } })");
  }
  // Mean of `img` over the pixels whose world position satisfies `pick`; `count` the pixels.
  template <class Pick>
  glm::dvec3 mean(const Result& r, const ImageRGBA32F& img, Pick pick, int* count = nullptr) {
    glm::dvec3 sum(0.0);
    int n = 0;
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x)
        if (!r.sky(x, y) && pick(r.worldAt(x, y))) {
          sum += glm::dvec3(r.px(img, x, y));
          ++n;
        }
    if (count) *count = n;
    return n > 0 ? sum / double(n) : sum;
  }
};

// An open plane under a constant environment: nothing is blocked, so the directional term is
// (1/N) sum L = L exactly and ambient = albedo x L, which is also the engine's own environment
// term (its SH9 is exact for a constant environment). Tolerance 1%: rgb9e5 (2^-9) and half
// float rounding, the albedo's 8-bit sRGB quantization.
TEST_F(SsdoTest, OpenPlaneUnderAConstantEnvironmentIsAlbedoTimesRadiance) {
  const Scene s = jsonScene("plane", R"({
      "models": [ { "primitive": "plane", "size": 40, "material": { "base_color": [0.5, 0.5, 0.5] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 2, 3], "target": [0, 0, 0] },
      "environment": { "type": "constant", "color": [0.6, 0.4, 0.2], "intensity": 1.5 } })");
  const Result ssdo = render(s, {});
  const Result none = render(s, {}, "");
  const glm::vec3 expected = 0.5f * 1.5f * glm::vec3(0.6f, 0.4f, 0.2f);
  int checked = 0;
  for (int y = 0; y < ssdo.h; ++y)
    for (int x = 0; x < ssdo.w; ++x) {
      if (ssdo.sky(x, y)) continue;
      ++checked;
      const glm::vec3 a = ssdo.px(ssdo.ambient, x, y), engine = none.px(none.lit, x, y);
      // Per unit albedo SSDO's own value is L itself: only the rgb9e5 packing (2^-9 of the
      // largest channel, exact rounding) and the half-float output (2^-11) stand between.
      const glm::vec3 raw = ssdo.px(ssdo.ambientRaw, x, y), L = 1.5f * glm::vec3(0.6f, 0.4f, 0.2f);
      ASSERT_EQ(ssdo.ambientRaw.pixels[(size_t(y) * ssdo.w + x) * 4 + 3], 2.0f) << "alpha 2";
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(raw[c], L[c], 0.9f / 512.0f) << x << "," << y;
      for (int c = 0; c < 3; ++c) {
        ASSERT_NEAR(a[c], expected[c], 0.01f * expected[c]) << x << "," << y << " channel " << c;
        ASSERT_NEAR(ssdo.px(ssdo.lit, x, y)[c], engine[c], 0.01f * engine[c]) << x << "," << y;
      }
      ASSERT_EQ(ssdo.px(ssdo.indirect, x, y), glm::vec3(0.0f)) << "no occluder, no bounce";
    }
  EXPECT_GT(checked, int(kW * kH) / 3);
}

// The same under a constant equirect map (environment kind 2, whose samples the shader sums
// through the SH9's moments): the SH of a constant map is that constant, so ambient = albedo x
// L again. Tolerance 2%: the map's RGBE quantization and the SH projection's quadrature.
TEST_F(SsdoTest, OpenPlaneUnderAConstantMapIsAlbedoTimesRadiance) {
  const std::string dir = ::testing::TempDir();
  writeRgbeMap(dir + "/ssdo_flat.hdr", 16, 8, [](int, int) {
    return Rgbe{128, 96, 64, 128};  // (0.5, 0.375, 0.25)
  });
  const Scene s = jsonScene("map", R"({
      "models": [ { "primitive": "plane", "size": 40, "material": { "base_color": [0.5, 0.5, 0.5] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 2, 3], "target": [0, 0, 0] },
      "environment": { "type": "map", "file": ")" +
                                       dir + R"(/ssdo_flat.hdr" } })");
  const glm::vec3 expected = 0.5f * glm::vec3(0.5f, 0.375f, 0.25f);
  // Each way of reading the map (SH9, the map per direction, and with multiple importance
  // sampling, whose per-sample weights vary even under a constant map: 3%, and 2 px from the
  // border where the blur cannot average all 16 sets).
  for (const char* mode : {"sh9", "map", "mis"}) {
    const Result r = render(s, {std::string("ssdo.environment_sampling=") + mode});
    int checked = 0;
    for (int y = 2; y < r.h - 2; ++y)
      for (int x = 2; x < r.w - 2; ++x) {
        if (r.sky(x, y)) continue;
        ++checked;
        const float tolerance = std::string(mode) == "mis" ? 0.03f : 0.02f;
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(r.px(r.ambient, x, y)[c], expected[c], tolerance * expected[c])
              << mode << " " << x << "," << y;
      }
    EXPECT_GT(checked, int(kW * kH) / 3) << mode;
  }
}

// A box on a floor under a map that is dim (0.05) but for a small bright sun (1000, 2x2
// texels of 64 x 32, 45 degrees up toward +x): the floor beside the box's -x face is in the
// sun's shadow, the floor beside its +x face is not. With multiple importance sampling
// (`environment_sampling=mis`) the open floor matches the exact (1 / pi) int L cos within 3%
// (measured +0.5%) and the shadow side is dark (ratio 0.36 with the default two layers, 0.25
// with one: SSDO's point test lets the steps that stop short of the box through, and with two
// layers those beyond its back faces too); the map's SH9 spreads the sun over the sky (open
// floor -28%, ratio 0.81; 0.71 with one layer), and the cosine samples alone, one fixed set per 4x4
// block, hit the tiny sun too often or not at all (+27% here; +156% / +28% / -36% at 8 / 16 / 32
// samples).
TEST_F(SsdoTest, SunInAMapCastsItsShadowWhenTheMapIsReadPerDirection) {
  const std::string dir = ::testing::TempDir();
  // RGBE (mantissa + 0.5) / 256 x 2^(exponent - 128): 0.05 ~ 205.5 / 256 x 2^-4, the sun
  // 1000 ~ 250.5 / 256 x 2^10, in direction (1, 1, 0) / sqrt 2: v = acos(y) / pi = 0.25 (rows
  // 7-8), u = 0 (columns 63 and 0).
  writeRgbeMap(dir + "/ssdo_sun.hdr", 64, 32, [](int x, int y) {
    const bool sun = (y == 7 || y == 8) && (x == 63 || x == 0);
    return sun ? Rgbe{250, 250, 250, 138} : Rgbe{205, 205, 205, 124};
  });
  const Scene s = jsonScene("sun", R"({
      "models": [ { "primitive": "plane", "size": 40, "material": { "base_color": [0.5, 0.5, 0.5] } },
                  { "primitive": "box", "size": [1, 1, 1], "translation": [0, 0.5, 0],
                    "material": { "base_color": [0.5, 0.5, 0.5] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 4, 2.5], "target": [0, 0, 0] },
      "environment": { "type": "map", "file": ")" +
                                       dir + R"(/ssdo_sun.hdr" } })");
  // Mean luminance of the floor pixels with x in [x0, x1], |z| < 0.3.
  auto band = [](const Result& r, float x0, float x1) {
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x) {
        if (r.sky(x, y)) continue;
        const glm::vec3 p = r.worldAt(x, y);
        if (std::abs(p.y) > 1e-3f || p.x < x0 || p.x > x1 || std::abs(p.z) > 0.3f) continue;
        const glm::vec3 a = r.px(r.ambient, x, y);
        sum += 0.2126 * a.x + 0.7152 * a.y + 0.0722 * a.z;
        ++n;
      }
    EXPECT_GT(n, 20) << x0 << ".." << x1;
    return n > 0 ? sum / n : 0.0;
  };
  // The open floor's exact value: albedo x (1 / pi) int L cos over the upper hemisphere (of the
  // bilinear map, whose integral is the texels'), midpoint rule on a fine grid.
  const double exact = 0.5 * test::upperHemisphereIrradianceOverPi(s.environment);
  double ratio[3], open[3];
  const char* modes[3] = {"sh9", "map", "mis"};
  for (int m = 0; m < 3; ++m) {
    const Result r = render(s, {std::string("ssdo.environment_sampling=") + modes[m],
                                "ssdo.radius=1.5", "ssdo.bounce=false", "ssdo.samples=16"});
    for (float v : r.ambient.pixels) ASSERT_TRUE(std::isfinite(v)) << modes[m];
    const double shade = band(r, -0.9f, -0.6f), sunlit = band(r, 0.6f, 0.9f);
    ratio[m] = shade / std::max(sunlit, 1e-12);
    open[m] = band(r, 1.6f, 2.2f);
    std::printf(
        "%s: floor in the sun's shadow %.4f, in the sun %.4f, ratio %.3f; open floor "
        "%.4f (exact %.4f)\n",
        modes[m], shade, sunlit, ratio[m], open[m], exact);
  }
  EXPECT_NEAR(open[2], exact, 0.03 * exact) << "MIS against the exact open floor";
  EXPECT_LT(ratio[2], 0.4) << "MIS must show the sun's shadow";
  EXPECT_GT(ratio[0], ratio[2] + 0.2) << "SH9 spreads the sun: a weaker shadow";
  EXPECT_GT(std::abs(open[0] - exact), 0.2 * exact) << "SH9 is far off for a small sun";
  EXPECT_GT(std::abs(open[1] - exact), std::abs(open[2] - exact))
      << "cosine samples alone must be the worse estimate for a small sun";
}

// Open planes (floor, and a wall facing the camera) under the procedural sky: SSDO integrates
// the sky per direction, the engine uses its SH9 irradiance, which approximates the same
// integral to a few percent (gi/environment.h). Tolerance 2.5% of the brightest channel.
TEST_F(SsdoTest, OpenPlanesUnderTheSkyMatchTheEnginesEnvironmentTerm) {
  for (const char* rotation : {"[0, 0, 0]", "[90, 0, 0]"}) {
    const Scene s = jsonScene("sky", std::string(R"({
      "models": [ { "primitive": "plane", "size": 400, "rotation": )") +
                                         rotation + R"(,
                    "material": { "base_color": [0.8, 0.8, 0.8] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0.5, 2, 3], "target": [0, 0, 0] },
      "environment": { "type": "sky", "intensity": 1, "zenith_color": [0.2, 0.4, 1.0],
                       "horizon_color": [1.0, 0.8, 0.6], "ground_color": [0.3, 0.25, 0.2] } })");
    const Result ssdo = render(s, {"ssdo.bounce=false"});
    const Result none = render(s, {}, "");
    int checked = 0;
    double worst = 0.0;
    // Not within the blur radius of the border: there the blur cannot average all 16 sets.
    for (int y = 2; y < ssdo.h - 2; ++y)
      for (int x = 2; x < ssdo.w - 2; ++x) {
        if (ssdo.sky(x, y)) continue;
        ++checked;
        const glm::vec3 a = ssdo.px(ssdo.lit, x, y), e = none.px(none.lit, x, y);
        const float scale = std::max({e.r, e.g, e.b});
        for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(a[c] - e[c]) / scale));
      }
    std::printf("plane rotation %s: worst relative difference %.4f\n", rotation, worst);
    EXPECT_GT(checked, int(kW * kH) / 4) << rotation;
    EXPECT_LT(worst, 0.025) << rotation;  // measured 0.013 (floor), 0.001 (wall)
  }
}

// A box on a floor under a sky whose zenith is red and whose horizon and ground are blue. Next
// to the box the blocked directions are mostly low (toward the box's wall at small elevation
// more of the step reaches it), i.e. bluish: SSDO's shadow there turns redder than the open
// floor; SSAO scales the whole environment term, so its shadow keeps the open floor's hue.
TEST_F(SsdoTest, ShadowNextToABoxTakesTheColourOfTheUnblockedSky) {
  const Scene s = jsonScene("box", R"({
      "models": [
        { "primitive": "plane", "size": 40, "material": { "base_color": [0.8, 0.8, 0.8] } },
        { "primitive": "box", "size": 2, "translation": [0, 1, 0],
          "material": { "base_color": [0.8, 0.8, 0.8] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 3, 5], "target": [0, 0, 1] },
      "environment": { "type": "sky", "intensity": 1, "zenith_color": [1, 0, 0],
                       "horizon_color": [0, 0, 1], "ground_color": [0, 0, 1] } })");
  auto floor = [](glm::vec3 p) { return std::abs(p.y) < 1e-3f && std::abs(p.x) < 0.6f; };
  auto near = [&](glm::vec3 p) { return floor(p) && p.z > 1.02f && p.z < 1.15f; };
  auto far = [&](glm::vec3 p) { return floor(p) && p.z > 2.5f && p.z < 3.5f; };
  auto redness = [](glm::dvec3 c) { return c.r / (c.r + c.b); };
  const Result ssdo = render(s, {"ssdo.bounce=false", "ssdo.radius=0.5"});
  const Result ssao = render(s, {"ssao.radius=0.5"}, "ssao");
  int nNear = 0, nFar = 0;
  const glm::dvec3 dNear = mean(ssdo, ssdo.lit, near, &nNear),
                   dFar = mean(ssdo, ssdo.lit, far, &nFar);
  const glm::dvec3 aNear = mean(ssao, ssao.lit, near), aFar = mean(ssao, ssao.lit, far);
  ASSERT_GT(nNear, 20);
  ASSERT_GT(nFar, 20);
  std::printf("redness r/(r+b): ssdo near %.4f far %.4f; ssao near %.4f far %.4f\n", redness(dNear),
              redness(dFar), redness(aNear), redness(aFar));
  std::printf("luminance near/far: ssdo %.3f ssao %.3f\n", (dNear.r + dNear.b) / (dFar.r + dFar.b),
              (aNear.r + aNear.b) / (aFar.r + aFar.b));
  // Both darken next to the box.
  EXPECT_LT(dNear.r + dNear.b, 0.9 * (dFar.r + dFar.b));
  EXPECT_LT(aNear.r + aNear.b, 0.9 * (aFar.r + aFar.b));
  // SSAO: grey shadow (same hue within rounding); SSDO: coloured, toward the open sky (red).
  EXPECT_NEAR(redness(aNear), redness(aFar), 0.003);  // measured 1e-4
  EXPECT_GT(redness(dNear), redness(dFar) + 0.02);    // measured +0.039
  // Without the blur's normal test (blur_normals=false) the box's wall, whose own term is blue
  // (it sees the horizon and the ground), blends into the floor's first pixels across the
  // crease: the band next to the box keeps little of its hue (measured 0.7946, as the open
  // floor). What the normal test buys, which the NRMSE against the reference hardly sees.
  const Result plain =
      render(s, {"ssdo.bounce=false", "ssdo.radius=0.5", "ssdo.blur_normals=false"});
  const glm::dvec3 pNear = mean(plain, plain.lit, near);
  std::printf("redness next to the box without the normal test %.4f\n", redness(pNear));
  EXPECT_LT(redness(pNear), redness(dNear) - 0.02);  // measured -0.041
}

// The issue's two-colour case, the colours split left / right: an equirect map red toward -x,
// blue toward +x, over a floor with a box. Beside the box's -x face the box hides the blue
// half: SSDO's shadow there is red; beside its +x face it hides the red half: the shadow is
// blue; SSAO darkens both sides with the open floor's hue (r / (r + b) 0.5000 everywhere).
// Read through the map's SH9 (its first-order band keeps the split: 0.573 left, 0.427 right,
// 0.500 open) and through multiple importance sampling (0.603, 0.347, 0.496: the sharp split),
// with the default two layers (steps beyond the box's back faces count as open); with one
// layer 0.599 / 0.407 / 0.500 and 0.692 / 0.325 / 0.496.
TEST_F(SsdoTest, ShadowsOnEachSideOfABoxTakeTheColourOfTheOtherSide) {
  const std::string dir = ::testing::TempDir();
  // Column x: u = (x + 0.5) / 32 = atan(z, x) / 2 pi: x < 0 (red) for u in (0.25, 0.75).
  writeRgbeMap(dir + "/ssdo_red_blue.hdr", 32, 16, [](int x, int) {
    return x >= 8 && x < 24 ? Rgbe{128, 0, 0, 129} : Rgbe{0, 0, 128, 129};
  });
  const Scene s = jsonScene("red_blue", R"({
      "models": [
        { "primitive": "plane", "size": 40, "material": { "base_color": [0.8, 0.8, 0.8] } },
        { "primitive": "box", "size": 1, "translation": [0, 0.5, 0],
          "material": { "base_color": [0.8, 0.8, 0.8] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 4, 2.5], "target": [0, 0, 0] },
      "environment": { "type": "map", "file": ")" +
                                            dir + R"(/ssdo_red_blue.hdr" } })");
  auto floor = [](glm::vec3 p) { return std::abs(p.y) < 1e-3f && std::abs(p.z) < 0.45f; };
  auto left = [&](glm::vec3 p) { return floor(p) && p.x > -0.65f && p.x < -0.51f; };
  auto right = [&](glm::vec3 p) { return floor(p) && p.x > 0.51f && p.x < 0.65f; };
  auto open = [](glm::vec3 p) {
    return std::abs(p.y) < 1e-3f && std::abs(p.x) < 0.3f && p.z > 1.6f && p.z < 2.0f;
  };
  auto redness = [](glm::dvec3 c) { return c.r / (c.r + c.b); };
  // Both effects must darken the floor beside the box (a shadow at all), or "grey" and
  // "coloured" would say nothing: below 0.9 of the open floor's red + blue.
  auto shade = [](glm::dvec3 c) { return c.r + c.b; };
  const Result ssao = render(s, {"ssao.radius=1"}, "ssao");
  const double aOpen = redness(mean(ssao, ssao.lit, open));
  std::printf("ssao redness: left %.4f, right %.4f, open %.4f; shade left / open %.3f\n",
              redness(mean(ssao, ssao.lit, left)), redness(mean(ssao, ssao.lit, right)), aOpen,
              shade(mean(ssao, ssao.lit, left)) / shade(mean(ssao, ssao.lit, open)));
  EXPECT_NEAR(redness(mean(ssao, ssao.lit, left)), aOpen, 0.005);
  EXPECT_NEAR(redness(mean(ssao, ssao.lit, right)), aOpen, 0.005);
  EXPECT_LT(shade(mean(ssao, ssao.lit, left)), 0.9 * shade(mean(ssao, ssao.lit, open)));
  EXPECT_LT(shade(mean(ssao, ssao.lit, right)), 0.9 * shade(mean(ssao, ssao.lit, open)));
  for (const char* mode : {"sh9", "mis"}) {
    const Result r = render(s, {"ssdo.bounce=false", "ssdo.radius=1",
                                std::string("ssdo.environment_sampling=") + mode});
    int nLeft = 0, nRight = 0, nOpen = 0;
    const double l = redness(mean(r, r.lit, left, &nLeft)),
                 rr = redness(mean(r, r.lit, right, &nRight)),
                 o = redness(mean(r, r.lit, open, &nOpen));
    std::printf("ssdo %s redness: left %.4f, right %.4f, open %.4f; shade left / open %.3f\n", mode,
                l, rr, o, shade(mean(r, r.lit, left)) / shade(mean(r, r.lit, open)));
    ASSERT_GT(std::min({nLeft, nRight, nOpen}), 20) << mode;
    EXPECT_LT(shade(mean(r, r.lit, left)), 0.9 * shade(mean(r, r.lit, open))) << mode;
    EXPECT_LT(shade(mean(r, r.lit, right)), 0.9 * shade(mean(r, r.lit, open))) << mode;
    EXPECT_NEAR(o, 0.5, 0.05) << mode << ": the open floor sees both halves alike";
    EXPECT_GT(l, o + 0.05) << mode << ": the shadow left of the box is red";
    EXPECT_LT(rr, o - 0.05) << mode << ": the shadow right of the box is blue";
  }
}

// A white floor and a yellow emissive wall (x = 0) under a black environment: the floor's
// indirect light is yellow, strongest next to the wall, fading with distance and 0 beyond the
// radius. Back-facing senders are rejected: the G-buffer turns every normal toward the camera,
// so the case is a surface facing away from the receiver, not from the camera.
TEST_F(SsdoTest, BounceFromAYellowWallFadesAndBackFacingSendersGiveNothing) {
  auto scene = [&](const char* name, int rotationZ) {
    return jsonScene(name, std::string(R"({
      "models": [
        { "primitive": "plane", "size": 40, "material": { "base_color": [1, 1, 1] } },
        { "primitive": "plane", "size": 2, "translation": [0, 1, 0], "rotation": [0, 0, )") +
                               std::to_string(rotationZ) + R"(],
          "material": { "base_color": [1, 1, 0], "emission": [1, 1, 0] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [3, 2.5, 0], "target": [0.5, 0, 0] },
      "environment": { "type": "constant", "color": [0, 0, 0] } })");
  };
  auto band = [](float lo, float hi) {
    return [lo, hi](glm::vec3 p) {
      return std::abs(p.y) < 1e-3f && std::abs(p.z) < 0.5f && p.x > lo && p.x < hi;
    };
  };
  const Result front = render(scene("front", -90), {"ssdo.radius=0.5"});
  const glm::dvec3 near = mean(front, front.indirect, band(0.02f, 0.12f));
  const glm::dvec3 mid = mean(front, front.indirect, band(0.25f, 0.35f));
  const glm::dvec3 far = mean(front, front.indirect, band(0.8f, 2.0f));
  std::printf("floor indirect near %.4f %.4f %.4f mid %.4f far %.4f\n", near.r, near.g, near.b,
              mid.r, far.r);
  EXPECT_GT(near.r, 0.02);
  EXPECT_NEAR(near.g, near.r, 0.01 * near.r);  // yellow: r = g (white floor, yellow sender)
  EXPECT_LT(near.b, 1e-6);
  EXPECT_GT(near.r, 1.5 * mid.r);
  EXPECT_GT(mid.r, 0.0);
  EXPECT_EQ(far.r, 0.0) << "no sample reaches the wall from beyond the radius";
  // The floor's lit image carries the tint: red and green above blue near the wall.
  const glm::dvec3 lit = mean(front, front.lit, band(0.02f, 0.12f));
  EXPECT_GT(lit.r, lit.b + 0.02);

  // A yellow emissive platform (y = 0.2, x < 0) facing up: the floor's samples under its edge
  // are blocked by its top, whose normal (+y) faces away from the floor below (cos_s = 0).
  const Scene platform = jsonScene("back", R"({
      "models": [
        { "primitive": "plane", "size": 40, "material": { "base_color": [1, 1, 1] } },
        { "primitive": "plane", "size": 4, "translation": [-2, 0.2, 0],
          "material": { "base_color": [1, 1, 0], "emission": [1, 1, 0] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [3, 2.5, 0], "target": [0.5, 0, 0] },
      "environment": { "type": "constant", "color": [1, 1, 1] } })");
  const Result back = render(platform, {"ssdo.radius=0.5"});
  int n = 0;
  const glm::dvec3 backNear = mean(back, back.indirect, band(0.02f, 0.12f), &n);
  ASSERT_GT(n, 20);
  EXPECT_EQ(backNear, glm::dvec3(0.0)) << "a back-facing sender must give no energy";
  // ... although samples there are blocked: the directional term is below the open floor's.
  const glm::dvec3 openAmbient = mean(back, back.ambient, band(1.0f, 2.0f));
  const glm::dvec3 nearAmbient = mean(back, back.ambient, band(0.02f, 0.12f));
  EXPECT_LT(nearAmbient.r, 0.97 * openAmbient.r);
}

// SSDO's bounce energy on the yellow wall (emission 1, x = 0, y in [0, 2], z in [-1, 1], facing
// +x) lighting the white floor at distance h, against numbers computed here:
//  - the truth within the radius: (1/pi) int over the wall points within R of the receiver of
//    L cos_s cos_r / d^2 dA (the light a bounce limited to senders within R should give);
//  - the method's expectation: R^2 E[L cos_s cos_r / max(d^2, d_min^2)] over its continuous
//    sample distribution (cosine directions, steps uniform in (0, 1]), a sample counting when
//    the camera's ray through it meets the wall in front of it by more than the bias and less
//    than R (the sender is that wall point), as ssdo.glsl does, with A_s / pi = R^2 / N;
//  - the same estimator with each pixel's own 32 samples (the shader's table and frame).
// Measured (160x120, 32 samples, unblurred, four pixel rows = all 16 sample sets), R = 0.5 at
// h = 0.09, 0.17, 0.32, 0.47: GPU / its samples on the CPU 1.05, 1.00, 1.15, - (both 0);
// expectation / truth 0.55, 0.33, 0.10, 0.02. R = 2 at h = 0.09, 0.32, 0.60: GPU / samples
// 0.93, 0.92, 0.81; expectation / truth 1.29, 0.71, 0.42. So the shortfall is not a scaling
// error (the GPU computes the estimator it claims, within texel snapping) but the method: every
// blocked sample stands for the same area pi R^2 / N whatever share of the ball the sender
// covers, so the light falls off with the receiver's distance faster than the form factor
// (the blocked share of the ball shrinks), and a large R overshoots next to the wall
// (effects/ssdo/README.md).
TEST_F(SsdoTest, BounceEnergyIsTheMethodsExpectationAndDepartsFromTheFormFactorWithDistance) {
  const Scene scene = yellowWall("energy");
  const glm::dvec3 eye(3.0, 2.5, 0.0);
  const glm::dvec3 viewDir = glm::normalize(glm::dvec3(0.5, 0.0, 0.0) - eye);
  auto onWall = [](const glm::dvec3& p) {
    return p.y >= 0.0 && p.y <= 2.0 && std::abs(p.z) <= 1.0;
  };
  // The truth within R at the floor point (h, 0, z0): midpoint rule on the wall.
  auto truth = [&](double h, double z0, double R) {
    const int n = 200;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const glm::dvec3 S(0.0, (i + 0.5) * 2.0 / n, -1.0 + (j + 0.5) * 2.0 / n);
        const glm::dvec3 d = S - glm::dvec3(h, 0.0, z0);
        const double d2 = glm::dot(d, d);
        if (d2 >= R * R) continue;
        sum += (h * S.y) / (d2 * d2);  // cos_s cos_r / d^2 = (h / d)(y / d) / d^2
      }
    return sum * (2.0 / n) * (2.0 / n) / M_PI;
  };
  // The method's expectation at (h, 0, z0), Monte Carlo over its continuous distribution.
  // One sample's bounce term at receiver P (floor, normal +y): the sample Q counts when the
  // camera's ray through it meets the wall in front of it by more than the bias and less than
  // R; the sender S is that wall point.
  auto sendOf = [&](const glm::dvec3& P, const glm::dvec3& Q, double R, double dMin) {
    if (Q.x >= 0.0) return 0.0;  // in front of the wall's plane: open
    const glm::dvec3 S = eye + (Q - eye) * (eye.x / (eye.x - Q.x));
    if (!onWall(S)) return 0.0;
    const double behind = glm::dot(Q - S, viewDir);  // view-depth difference
    if (!(behind > ssdo::kBias * R && behind < R)) return 0.0;
    const glm::dvec3 d = S - P;
    const double d2 = glm::dot(d, d), len = std::sqrt(d2);
    return (P.x / len) * (S.y / len) / std::max(d2, dMin * dMin);
  };
  // The same with pixel (x, y)'s own 32 samples (the shader's table, its tangent frame).
  auto pixelSamples = [&](const Result& r, int x, int y, const glm::dvec3& P, double R,
                          double dMin) {
    const glm::dvec3 N = glm::dmat3(r.camera.view) * glm::dvec3(0.0, 1.0, 0.0);
    const double sg = N.z >= 0.0 ? 1.0 : -1.0, a = -1.0 / (sg + N.z), b = N.x * N.y * a;
    const glm::dvec3 T(1.0 + sg * N.x * N.x * a, sg * b, -sg * N.x);
    const glm::dvec3 B(b, sg + N.y * N.y * a, -N.y);
    const glm::dmat3 toWorld = glm::inverse(glm::dmat3(r.camera.view));
    double sum = 0.0;
    for (int i = 0; i < 32; ++i) {
      const ssdo::Sample k = ssdo::sampleAt(x, y, i, 32, ssdo::kPhases);
      const glm::dvec3 w = toWorld * (T * double(k.x) + B * double(k.y) + N * double(k.z));
      sum += sendOf(P, P + R * double(k.s) * w, R, dMin);
    }
    return R * R * sum / 32.0;
  };
  // The method's expectation at P: R^2 E[send] over its continuous distribution.
  auto method = [&](const glm::dvec3& P, double R, double dMin) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int n = 50000;
    double sum = 0.0;
    for (int k = 0; k < n; ++k) {
      const double u1 = u(rng), u2 = u(rng), step = 1.0 - u(rng);
      const double r = std::sqrt(u1), phi = 2.0 * M_PI * u2;
      const glm::dvec3 w(r * std::cos(phi), std::sqrt(1.0 - u1), r * std::sin(phi));
      sum += sendOf(P, P + R * step * w, R, dMin);
    }
    return R * R * sum / n;
  };
  // Per case: the GPU's bounce (unblurred: each pixel its own receiver), the same estimator
  // with each pixel's own 32 samples on the CPU, the method's expectation and the truth, each
  // averaged over the floor's pixels (|z| < 0.3, where the 2-wide wall is nearly infinite) of
  // the four pixel rows nearest distance h: all 16 interleaved sample sets.
  struct Means {
    double gpu = 0.0, samples = 0.0, method = 0.0, truth = 0.0, h = 0.0;
  };
  auto measure = [&](double R, double h) {
    const Result r = render(
        scene, {"ssdo.radius=" + std::to_string(R), "ssdo.samples=32", "ssdo.blur_radius=0"});
    std::map<int, std::vector<glm::ivec2>> rows;  // floor pixels per image row
    std::map<int, double> rowX;
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x) {
        const glm::vec3 p = r.worldAt(x, y);
        if (r.sky(x, y) || std::abs(p.y) > 1e-3f || std::abs(p.z) > 0.3f || p.x <= 0.0f) continue;
        rows[y].push_back({x, y});
        rowX[y] += p.x;
      }
    int nearest = -1;
    for (auto& [y, sum] : rowX) {
      sum /= double(rows[y].size());
      if (nearest < 0 || std::abs(sum - h) < std::abs(rowX[nearest] - h)) nearest = y;
    }
    Means m;
    std::set<int> phases;
    int n = 0;
    for (int y = nearest - 1; y <= nearest + 2; ++y)
      for (const glm::ivec2 px : rows[y]) {
        const glm::vec3 p = r.worldAt(px.x, px.y);
        const glm::dvec3 P(p.x, 0.0, p.z);
        phases.insert((px.y & 3) * 4 + (px.x & 3));
        m.gpu += r.px(r.indirect, px.x, px.y).r;
        m.samples += pixelSamples(r, px.x, px.y, P, R, 0.1);
        m.method += method(P, R, 0.1);
        m.truth += truth(p.x, p.z, R);
        m.h += p.x;
        ++n;
      }
    EXPECT_EQ(phases.size(), 16u);
    for (double* v : {&m.gpu, &m.samples, &m.method, &m.truth, &m.h}) *v /= std::max(n, 1);
    std::printf(
        "R %.1f h %.3f (%d px): GPU %.4f, its samples on the CPU %.4f, method's "
        "expectation %.4f, truth within R %.4f; GPU / samples %.2f, GPU / truth %.2f, "
        "expectation / truth %.2f\n",
        R, m.h, n, m.gpu, m.samples, m.method, m.truth, m.gpu / m.samples, m.gpu / m.truth,
        m.method / m.truth);
    return m;
  };
  std::vector<Means> small, large;
  for (double h : {0.08, 0.15, 0.3, 0.45}) small.push_back(measure(0.5, h));
  for (double h : {0.08, 0.3, 0.6}) large.push_back(measure(2.0, h));
  for (const Means& m : small) {
    // The scaling: the GPU is the estimator it claims to be, sample for sample.
    if (m.samples > 0.005) {
      EXPECT_NEAR(m.gpu / m.samples, 1.0, 0.25) << "h " << m.h;
    } else {
      EXPECT_LT(m.gpu, 0.005) << "h " << m.h;
    }
  }
  for (const Means& m : large) EXPECT_NEAR(m.gpu / m.samples, 1.0, 0.25) << "h " << m.h;
  // The method, R = 0.5: its expectation falls short of the truth with distance (the blocked
  // samples' share of the ball shrinks, each keeps the area pi R^2 / N) and reaches nothing
  // near R; with 32 samples per pixel it delivers less still (the horizon directions, where a
  // near wall's light comes from, are the cosine distribution's rarest).
  EXPECT_LT(small[2].method / small[2].truth, 0.5 * small[0].method / small[0].truth);
  EXPECT_LT(small[3].method / small[3].truth, 0.1);
  EXPECT_LT(small[0].gpu, small[0].method);
  // R = 2: near the wall the expectation overshoots the truth, farther out it falls short.
  EXPECT_GT(large[0].method / large[0].truth, 1.15);
  EXPECT_LT(large[2].method / large[2].truth, 0.6);
}

// The bounce's distance clamp: an occluder touching the receiver (the wall-floor corner,
// d -> 0) stays finite even at the smallest clamp, and each sender's term is bounded by
// L_s x bounce scale / d_min^2 (so the pixel by N times that, times the albedo).
TEST_F(SsdoTest, TouchingOccludersStayFiniteAndBoundedByTheDistanceClamp) {
  const Scene s = yellowWall("touch");
  for (double clamp : {1e-6, 0.02, 0.1}) {
    const std::string c = "ssdo.distance_clamp=" + std::to_string(clamp);
    const Result r = render(s, {"ssdo.radius=0.5", "ssdo.samples=12", "ssdo.bounce_strength=1", c,
                                "ssdo.blur_radius=0"});
    ASSERT_TRUE(finite(r.indirect)) << c;
    ASSERT_TRUE(finite(r.lit)) << c;
    // Sender radiance 1 (the wall's emission), A_s / pi = R^2 / N; at most N senders.
    const double bound = 12.0 * (0.25 / 12.0) / (clamp * clamp);
    float maxFloor = 0.0f;
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x)
        if (!r.sky(x, y) && std::abs(r.worldAt(x, y).y) < 1e-3f)
          maxFloor = std::max(maxFloor, r.px(r.indirect, x, y).r);
    std::printf("%s: max floor indirect %.4f (bound %.4g)\n", c.c_str(), maxFloor, bound);
    EXPECT_LE(maxFloor, std::min(bound * 1.01, 65000.0)) << c;
  }
}

TEST_F(SsdoTest, NoNaNAtGrazingAnglesExtremeClipPlanesAndSky) {
  // Grazing: the eye 1e-3 above the floor; extreme planes; looking up into the sky.
  for (const test::HardCornerView& k : test::hardCornerViews()) {
    const Scene s = k.scene();
    // The last: depth peeling and additional cameras on the same hard cases.
    for (const char* bounce : {"ssdo.bounce=true", "ssdo.bounce=false", "ssdo.layers=2"}) {
      std::vector<std::string> sets = {bounce, "ssdo.distance_clamp=1e-6"};
      if (std::string(bounce) == "ssdo.layers=2") sets.push_back("ssdo.cameras=2");
      const Result r = render(s, sets);
      EXPECT_TRUE(finite(r.ambient)) << bounce << " near " << k.znear;
      EXPECT_TRUE(finite(r.indirect)) << bounce << " near " << k.znear;
      EXPECT_TRUE(finite(r.lit)) << bounce << " near " << k.znear;
      for (size_t i = 0; i < r.ambient.pixels.size(); ++i) ASSERT_GE(r.ambient.pixels[i], 0.0f);
    }
  }
}

TEST_F(SsdoTest, PassListFollowsBounceAndBlurAndBounceOffKeepsTheDirectionalTerm) {
  const Scene scene = test::cornerScene();  // no lights: no shadow pass
  struct Frame {
    std::vector<std::string> passes;
    ImageRGBA32F ambient, indirect;
    bool indirectPublished = true;
  };
  auto passes = [&](const std::vector<std::string>& sets) {
    Renderer r(ctx(), scene, settingsFor(scene, "ssdo", sets), &registry);
    r.renderFrame();
    Frame f{r.passNames(), r.readTarget("ambient"), {}};
    try {
      f.indirect = r.readTarget("indirect");
    } catch (const Error&) {
      f.indirectPublished = false;
    }
    return f;
  };
  // One layer: the second layer's pass is PeelingAndCameraPassesOnlyWhenAsked's subject.
  const auto on = passes({"ssdo.bounce=true", "ssdo.layers=1"});
  const auto off = passes({"ssdo.bounce=false", "ssdo.layers=1"});
  const auto resolveOnly = passes({"ssdo.blur_radius=0", "ssdo.layers=1"});
  const std::vector<std::string> blurred = {"gbuffer",   "ssdo_surface", "ssdo",
                                            "ssdo_blur", "lighting",     "tonemap"};
  EXPECT_EQ(on.passes, blurred);
  // Without the bounce (one layer, no cameras) the taps read the G-buffer depth
  // (ssdo_depth.comp): no surface texels.
  EXPECT_EQ(off.passes,
            (std::vector<std::string>{"gbuffer", "ssdo", "ssdo_blur", "lighting", "tonemap"}));
  EXPECT_EQ(resolveOnly.passes, (std::vector<std::string>{"gbuffer", "ssdo_surface", "ssdo",
                                                          "ssdo_resolve", "lighting", "tonemap"}));
  // The bounce changes nothing in the directional term, bit for bit, though off it is computed
  // from the depth and on from the surface texels; off, "indirect" is not published (the
  // lighting pass's neutral 0 stands in).
  EXPECT_EQ(on.ambient.pixels, off.ambient.pixels);
  EXPECT_TRUE(on.indirectPublished);
  EXPECT_FALSE(off.indirectPublished);
  float maxOn = 0.0f;
  for (float v : on.indirect.pixels) maxOn = std::max(maxOn, v);
  EXPECT_GT(maxOn, 0.0f);
}

// With the bounce, ssdo_surface sums the lights for its senders exactly as the lighting pass
// would (sumLights: PCF, specular, contact shadows) and publishes the sum as "direct_light",
// which the lighting pass then adds instead of summing the lights itself. With the bounce's
// strength at 0 (indirect = 0) the lit image must be the one of the bounce turned off (the
// lighting pass's own sum): the default room (a shadowed point light, PCF 1) and a shadowed
// directional light with contact shadows (applied by ssdo_surface here, by the lighting pass
// there). Tolerance: the half-float direct_light (2^-11 relative) and the lit image's own half
// float. The published image is finite, 0 on sky pixels, and lights the room.
TEST_F(SsdoTest, TheBouncesPublishedDirectLightIsTheLightingPassesOwn) {
  const Scene room = makeDefaultScene();
  const Scene contact = jsonScene("direct_contact", R"({
      "models": [
        { "primitive": "plane", "size": 16, "material": { "base_color": [0.8, 0.8, 0.8], "roughness": 0.4 } },
        { "primitive": "box", "size": [0.1, 0.1, 0.1], "translation": [0, 0.05, 0],
          "material": { "base_color": [0.8, 0.6, 0.3], "roughness": 0.3 } } ],
      "lights": [ { "type": "directional", "direction": [1, -1, 0.3], "intensity": 3,
                    "casts_shadows": true } ],
      "camera": { "position": [0.4, 0.25, 0.15], "target": [0.05, 0.0, 0.02] } })");
  struct Case {
    const Scene* scene;
    std::vector<std::string> sets;
    uint32_t shadowMapSize;  // 256 in the contact scene: a bias the contact shadows correct
  };
  for (const Case& c :
       {Case{&room, {}, 1024}, Case{&contact, {"ssdo.contact_shadows=true"}, 256}}) {
    auto renderWith = [&](const std::vector<std::string>& sets) {
      RenderSettings rs = settingsFor(*c.scene, "ssdo", sets);
      rs.shadowMapSize = c.shadowMapSize;
      Renderer r(ctx(), *c.scene, rs, &registry);
      r.renderFrame();
      return std::array<ImageRGBA32F, 3>{
          r.readTarget("lit"), r.readTarget("depth"),
          sets.back() == "ssdo.bounce=false" ? ImageRGBA32F{} : r.readTarget("direct_light")};
    };
    std::vector<std::string> published = c.sets, own = c.sets;
    published.insert(published.end(), {"ssdo.bounce_strength=0", "ssdo.bounce=true"});
    own.push_back("ssdo.bounce=false");
    const auto [lit, depth, direct] = renderWith(published);
    const ImageRGBA32F referenceLit = renderWith(own)[0];
    ASSERT_TRUE(finite(direct));
    ASSERT_TRUE(finite(lit));
    ASSERT_EQ(direct.pixels.size(), lit.pixels.size());
    double directSum = 0.0;
    for (size_t i = 0; i < lit.pixels.size(); i += 4) {
      if (depth.pixels[i] <= 0.0f) {  // sky: lighting draws the sky itself
        ASSERT_EQ(direct.pixels[i] + direct.pixels[i + 1] + direct.pixels[i + 2], 0.0f);
        continue;
      }
      for (size_t k = 0; k < 3; ++k) {
        const float a = lit.pixels[i + k], b = referenceLit.pixels[i + k];
        ASSERT_NEAR(a, b, 2e-3f * std::max(a, b) + 1e-5f) << "pixel " << i / 4 << " channel " << k;
      }
      directSum += direct.pixels[i + 1];
    }
    EXPECT_GT(directSum, 1.0) << "the lights must light the view";
  }
}

// Seed 000 Fig. 5: a thin wall floating in front of the floor (seen from the camera). Floor
// points behind it, more than R from the wall, are truly open (nothing within R but the floor),
// but with one depth layer the samples above them that project onto the wall are behind it and
// within R: wrongly blocked. With two layers (the wall's back face peeled) they lie behind the
// solid interval and are open: ambient = albedo x L as on an open plane (1%, as above).
TEST_F(SsdoTest, DepthPeelingLightsTheFloorBehindAThinWall) {
  const Scene s = jsonScene("slab", R"({
      "models": [
        { "primitive": "plane", "size": 40, "material": { "base_color": [0.5, 0.5, 0.5] } },
        { "primitive": "box", "size": [3, 2, 0.04], "translation": [0, 1.3, 0.5],
          "material": { "base_color": [0.5, 0.5, 0.5] } } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 0.6, 4], "target": [0, 0.2, 0] },
      "environment": { "type": "constant", "color": [1, 1, 1] } })");
  const Result one = render(s, {"ssdo.radius=1", "ssdo.bounce=false", "ssdo.layers=1"});
  const Result two = render(s, {"ssdo.radius=1", "ssdo.bounce=false", "ssdo.layers=2"});
  // Floor seen under the wall, 1.2 .. 1.4 behind it: its nearest point is > 1.22 = R away.
  auto behind = [](glm::vec3 p) {
    return std::abs(p.y) < 1e-3f && std::abs(p.x) < 0.5f && p.z > -0.9f && p.z < -0.7f;
  };
  int n1 = 0, n2 = 0;
  const glm::dvec3 a1 = mean(one, one.ambient, behind, &n1),
                   a2 = mean(two, two.ambient, behind, &n2);
  ASSERT_GT(n1, 20);
  ASSERT_EQ(n1, n2);
  std::printf("floor behind the wall: one layer %.4f, two layers %.4f (open 0.5)\n", a1.r, a2.r);
  EXPECT_LT(a1.r, 0.44) << "one layer: samples behind the wall count as blocked";
  // The pixel that one layer shadows most is open with two.
  float worst = 1.0f;
  int wx = -1, wy = -1;
  for (int y = 0; y < one.h; ++y)
    for (int x = 0; x < one.w; ++x)
      if (!one.sky(x, y) && behind(one.worldAt(x, y)) && one.px(one.ambient, x, y).r < worst) {
        worst = one.px(one.ambient, x, y).r;
        wx = x;
        wy = y;
      }
  ASSERT_GE(wx, 0);
  std::printf("pixel %d,%d: one layer %.4f, two layers %.4f\n", wx, wy, worst,
              two.px(two.ambient, wx, wy).r);
  EXPECT_LT(worst, 0.44f);  // measured 0.426
  EXPECT_NEAR(two.px(two.ambient, wx, wy).r, 0.5f, 0.005f);
  for (int y = 0; y < two.h; ++y)
    for (int x = 0; x < two.w; ++x) {
      if (two.sky(x, y) || !behind(two.worldAt(x, y))) continue;
      ASSERT_NEAR(two.px(two.ambient, x, y).r, 0.5f, 0.005f) << x << "," << y;
    }
  EXPECT_TRUE(finite(two.ambient));
  EXPECT_TRUE(finite(two.lit));
}

// The scene of the additional-camera tests (JSON): a floor and a 1 x 3 x 1 box just left of the
// main view (off-screen), the box's and the floor's materials and the environment given; and
// the floor regions next to the box (the image's left edge) and far from it.
std::string offscreenBoxScene(const std::string& floorMaterial, const std::string& boxMaterial,
                              const std::string& environment) {
  return std::string(R"({ "models": [
        { "primitive": "plane", "size": 8, "material": )") +
         floorMaterial + R"( },
        { "primitive": "box", "size": [1, 3, 1], "translation": [-3.2, 1.5, 0], "material": )" +
         boxMaterial + R"( } ],
      "lights": [ { "type": "directional", "intensity": 0, "casts_shadows": false } ],
      "camera": { "position": [0, 3, 3], "target": [0, 0, 0] },
      "environment": )" +
         environment + " }";
}
bool nextToTheOffscreenBox(glm::vec3 p) {
  return std::abs(p.y) < 1e-3f && p.x < -1.9f && std::abs(p.z) < 0.4f;
}
bool farFromTheOffscreenBox(glm::vec3 p) {
  return std::abs(p.y) < 1e-3f && p.x > -0.5f && p.x < 1.0f && std::abs(p.z) < 1.0f;
}

// Seed 000 §4, additional cameras: a box just left of the main view shadows the floor at the
// image's left edge only when the first additional camera (displaced to the right, aimed at the
// centre of interest: it sees past the left edge) sees it; the main view's samples there leave
// the image: open. The floor far from it keeps its value (the extra view
// adds no self-occlusion), and the bounce stays finite.
TEST_F(SsdoTest, AdditionalCameraSeesAnOccluderOutsideTheView) {
  const std::string grey = R"({ "base_color": [0.5, 0.5, 0.5] })";
  const Scene s = jsonScene(
      "offscreen", offscreenBoxScene(grey, grey, R"({ "type": "constant", "color": [1, 1, 1] })"));
  const Result main = render(s, {"ssdo.radius=1", "ssdo.cameras=0"});
  const Result extra = render(s, {"ssdo.radius=1", "ssdo.cameras=1"});
  for (int y = 0; y < main.h; ++y)
    for (int x = 0; x < main.w; ++x) {
      ASSERT_TRUE(main.sky(x, y) || std::abs(main.worldAt(x, y).y) < 1e-3f)
          << "the box must be off-screen: " << x << "," << y << " " << main.worldAt(x, y).x << " "
          << main.worldAt(x, y).y << " " << main.worldAt(x, y).z;
    }
  const auto nearBox = nextToTheOffscreenBox;
  const auto far = farFromTheOffscreenBox;
  int n = 0;
  const glm::dvec3 m = mean(main, main.ambient, nearBox, &n),
                   e = mean(extra, extra.ambient, nearBox);
  const glm::dvec3 mFar = mean(main, main.ambient, far), eFar = mean(extra, extra.ambient, far);
  std::printf(
      "floor next to the off-screen box: main view %.4f, with a camera %.4f; far %.4f %.4f\n", m.r,
      e.r, mFar.r, eFar.r);
  ASSERT_GT(n, 20);
  EXPECT_NEAR(m.r, 0.5, 0.005) << "the main view alone cannot see the box";
  // Relative to the main view's own value: the fixed sample set's estimate of the open floor
  // moves by ~1% with the normal's last bits (0.4969 with half-float normals, 0.5029 packed),
  // the camera's shadow does not (0.0164 and 0.0166 below it).
  EXPECT_LT(e.r, m.r - 0.012) << "the additional camera's box must shadow the floor";
  // The floor pixel nearest the box (the image's left edge, 0.4 from it): darkest.
  float darkest = 1.0f, mainThere = 0.0f;
  for (int y = 0; y < extra.h; ++y)
    for (int x = 0; x < extra.w; ++x)
      if (!extra.sky(x, y) && nearBox(extra.worldAt(x, y)) &&
          extra.px(extra.ambient, x, y).r < darkest) {
        darkest = extra.px(extra.ambient, x, y).r;
        mainThere = main.px(main.ambient, x, y).r;
      }
  std::printf("darkest floor pixel: %.4f with the camera, %.4f without\n", darkest, mainThere);
  EXPECT_LT(darkest, 0.45f);  // measured 0.433
  EXPECT_NEAR(mainThere, 0.5f, 0.005f);
  EXPECT_NEAR(eFar.r, mFar.r, 0.01 * mFar.r);
  EXPECT_TRUE(finite(extra.ambient));
  EXPECT_TRUE(finite(extra.indirect));
  EXPECT_TRUE(finite(extra.lit));
}

// The same off-screen box as an emissive yellow sender under a black environment: only the
// additional camera's G-buffer holds it, so only with the camera does the floor beside it
// receive a bounce, yellow (r = g, b = 0); far from it, none either way.
TEST_F(SsdoTest, AdditionalCameraAddsTheBounceOfASenderOutsideTheView) {
  const Scene s = jsonScene(
      "offscreen_sender", offscreenBoxScene(R"({ "base_color": [1, 1, 1] })",
                                            R"({ "base_color": [1, 1, 0], "emission": [1, 1, 0] })",
                                            R"({ "type": "constant", "color": [0, 0, 0] })"));
  const Result main = render(s, {"ssdo.radius=1", "ssdo.cameras=0"});
  const Result extra = render(s, {"ssdo.radius=1", "ssdo.cameras=1"});
  int n = 0;
  const glm::dvec3 m = mean(main, main.indirect, nextToTheOffscreenBox, &n),
                   e = mean(extra, extra.indirect, nextToTheOffscreenBox);
  const glm::dvec3 eFar = mean(extra, extra.indirect, farFromTheOffscreenBox);
  std::printf(
      "floor next to the off-screen sender: indirect %.5f without the camera, %.5f %.5f "
      "%.5f with it; far %.5f\n",
      m.r, e.r, e.g, e.b, eFar.r);
  ASSERT_GT(n, 20);
  EXPECT_EQ(m.r, 0.0) << "the main view alone holds no sender";
  EXPECT_GT(e.r, 1e-3) << "the additional camera's sender must light the floor";
  EXPECT_NEAR(e.g, e.r, 0.01 * e.r);
  EXPECT_LT(e.b, 1e-6);
  EXPECT_EQ(eFar.r, 0.0) << "beyond the radius of every sender";
  EXPECT_TRUE(finite(extra.indirect));
}

// Seed 000 §5, contact shadows: a 0.1 box on a 16 m plane under a directional light (no
// environment, so lit = the direct term), 256^2 shadow map (texel ~0.07 m), default bias
// (b ~ 3 texels at 45 degrees: more than the box's thickness along the light). The engine's
// visibility of the light at a pixel is lit / lit without shadows. Floor pixels in the box's
// geometric shadow within 1 cm of its base: the bias lifts the receiver past the box, the
// engine lights them; with contact_shadows the samples toward the light enter the box: darker.
// Open floor further than 0.15 from the box keeps its value.
TEST_F(SsdoTest, ContactShadowsRestoreTheShadowTheBiasRemoves) {
  auto scene = [&](bool shadows) {
    return jsonScene(shadows ? "contact" : "contact_unshadowed", std::string(R"({
      "models": [
        { "primitive": "plane", "size": 16, "material": { "base_color": [0.8, 0.8, 0.8], "roughness": 1 } },
        { "primitive": "box", "size": [0.1, 0.1, 0.1], "translation": [0, 0.05, 0],
          "material": { "base_color": [0.8, 0.8, 0.8], "roughness": 1 } } ],
      "lights": [ { "type": "directional", "direction": [1, -1, 0.3], "intensity": 3,
                    "casts_shadows": )") + (shadows ? "true" : "false") +
                                                                     R"( } ],
      "camera": { "position": [0.4, 0.25, 0.15], "target": [0.05, 0.0, 0.02] },
      "environment": { "type": "constant", "color": [0, 0, 0] } })");
  };
  auto renderAt256 = [&](const Scene& sc, const std::vector<std::string>& sets,
                         const std::string& effect) {
    RenderSettings rs = settingsFor(sc, effect, sets);
    rs.shadowMapSize = 256;
    Renderer r(ctx(), sc, rs, &registry);
    r.renderFrame();
    Result res;
    res.lit = r.readTarget("lit");
    res.depth = r.readTarget("depth");
    res.camera = r.camera();
    res.w = int(kW);
    res.h = int(kH);
    return res;
  };
  const Scene s = scene(true), open = scene(false);
  const std::vector<std::string> base = {"ssdo.bounce=false"};
  std::vector<std::string> on = base;
  on.push_back("ssdo.contact_shadows=true");
  const Result engine = renderAt256(s, {}, "");
  const Result unshadowed = renderAt256(open, {}, "");
  const Result off = renderAt256(s, base, "ssdo");
  const Result contact = renderAt256(s, on, "ssdo");
  ASSERT_TRUE(finite(contact.lit));
  // The light travels toward +x (and a little +z): the shadow falls on the box's +x side.
  const glm::vec3 l = glm::normalize(glm::vec3(-1, 1, -0.3f));  // toward the light
  auto inBoxShadow = [&](glm::vec3 p) {  // the ray toward the light hits the box
    const glm::vec3 lo(-0.05f, 0.0f, -0.05f), hi(0.05f, 0.1f, 0.05f);
    float t0 = 0.0f, t1 = 1e9f;
    for (int a = 0; a < 3; ++a) {
      const float ta = (lo[a] - p[a]) / l[a], tb = (hi[a] - p[a]) / l[a];
      t0 = std::max(t0, std::min(ta, tb));
      t1 = std::min(t1, std::max(ta, tb));
    }
    return t0 < t1;
  };
  auto boxDistance = [](glm::vec3 p) {  // horizontal distance to the box's base
    const float dx = std::max(std::abs(p.x) - 0.05f, 0.0f),
                dz = std::max(std::abs(p.z) - 0.05f, 0.0f);
    return std::sqrt(dx * dx + dz * dz);
  };
  double engineSum = 0.0, contactSum = 0.0;
  int touching = 0, far = 0;
  for (int y = 0; y < engine.h; ++y)
    for (int x = 0; x < engine.w; ++x) {
      if (engine.sky(x, y)) continue;
      const glm::vec3 p = engine.worldAt(x, y);
      if (std::abs(p.y) > 1e-3f) continue;  // floor only
      const float d = boxDistance(p);
      if (d < 2e-3f) continue;  // the box's faces at its base (depth reconstruction error)
      const float full = unshadowed.px(unshadowed.lit, x, y).g;
      ASSERT_GT(full, 0.0f) << x << "," << y;
      const float vEngine = engine.px(engine.lit, x, y).g / full,
                  vOff = off.px(off.lit, x, y).g / full,
                  vContact = contact.px(contact.lit, x, y).g / full;
      ASSERT_NEAR(vOff, vEngine, 1e-3f) << "contact_shadows off changes nothing: " << x << "," << y;
      if (inBoxShadow(p) && d < 0.01f) {
        ++touching;
        engineSum += vEngine;
        contactSum += vContact;
        EXPECT_GT(vEngine, 0.9f) << "the bias must lift the contact shadow: " << x << "," << y;
      } else if (d > 0.15f) {
        ++far;
        ASSERT_NEAR(vContact, vEngine, 1e-3f) << "open floor: " << x << "," << y;
      }
    }
  ASSERT_GT(touching, 10);
  ASSERT_GT(far, 100);
  std::printf("floor touching the box (%d px): engine visibility %.3f, with contact shadows %.3f\n",
              touching, engineSum / touching, contactSum / touching);
  // Measured 1.000 -> 0.522: the segment (b ~ 0.2 here) leaves the 0.1 box through its top, so
  // about half the samples are blocked.
  EXPECT_LT(contactSum / touching, engineSum / touching - 0.4);
}

TEST_F(SsdoTest, PeelingAndCameraPassesOnlyWhenAsked) {
  const Scene scene = test::cornerScene();  // no lights: no shadow pass
  auto passes = [&](std::vector<std::string> sets) {
    Renderer r(ctx(), scene, settingsFor(scene, "ssdo", sets), &registry);
    r.renderFrame();
    EXPECT_TRUE(finite(r.readTarget("ambient")));
    EXPECT_TRUE(finite(r.readTarget("indirect")));
    return r.passNames();
  };
  using V = std::vector<std::string>;
  // Two layers by default (one peel pass); `layers` 1 turns peeling off.
  EXPECT_EQ(passes({}), (V{"gbuffer", "ssdo_peel", "ssdo_surface", "ssdo", "ssdo_blur", "lighting",
                           "tonemap"}));
  EXPECT_EQ(passes({"ssdo.layers=1"}),
            (V{"gbuffer", "ssdo_surface", "ssdo", "ssdo_blur", "lighting", "tonemap"}));
  EXPECT_EQ(passes({"ssdo.layers=1", "ssdo.cameras=2"}),
            (V{"gbuffer", "ssdo_cameras", "ssdo_camera_surface", "ssdo_surface", "ssdo",
               "ssdo_blur", "lighting", "tonemap"}));
  EXPECT_EQ(
      passes({"ssdo.layers=1", "ssdo.contact_shadows=true"}),
      (V{"gbuffer", "ssdo_contact", "ssdo_surface", "ssdo", "ssdo_blur", "lighting", "tonemap"}));
  EXPECT_EQ(passes({"ssdo.cameras=4"}),
            (V{"gbuffer", "ssdo_peel", "ssdo_cameras", "ssdo_camera_surface", "ssdo_surface",
               "ssdo", "ssdo_blur", "lighting", "tonemap"}));
  // The environment's importance samples only for environment_sampling=mis.
  EXPECT_EQ(passes({"ssdo.layers=1", "ssdo.environment_sampling=map"}),
            (V{"gbuffer", "ssdo_surface", "ssdo", "ssdo_blur", "lighting", "tonemap"}));
  EXPECT_EQ(passes({"ssdo.layers=1", "ssdo.environment_sampling=mis"}),
            (V{"gbuffer", "ssdo_surface", "ssdo_env_samples", "ssdo", "ssdo_blur", "lighting",
               "tonemap"}));
}

// The sample table: every pixel phase has its set, the 16 sets together are one stratified
// set (each of the 16 N azimuth strata holds one sample), and the packing round-trips.
TEST(SsdoSamples, SetsPartitionOneStratifiedSet) {
  const int n = 8, m = 16;
  std::vector<int> strata(size_t(n * m), 0);
  for (int phase = 0; phase < 16; ++phase)
    for (int i = 0; i < n; ++i) {
      const ssdo::Sample s = ssdo::sampleAt(phase & 3, phase >> 2, i, n, m);
      EXPECT_NEAR(s.x * s.x + s.y * s.y + s.z * s.z, 1.0f, 2e-3f);
      EXPECT_GT(s.s, 0.0f);
      EXPECT_LE(s.s, 1.0f);
      double phi = std::atan2(double(s.y), double(s.x));
      if (phi < 0) phi += 2 * M_PI;
      ++strata[size_t(std::min(int(phi / (2 * M_PI) * n * m), n * m - 1))];
    }
  for (int k = 0; k < n * m; ++k) EXPECT_EQ(strata[size_t(k)], 1) << "stratum " << k;
  const ssdo::Uniforms u = ssdo::makeUniforms(0.5, n, m, 1.0, 0.1);
  EXPECT_FLOAT_EQ(u.bounceScale, 0.25f / n);
  EXPECT_FLOAT_EQ(u.distanceClamp2, 0.01f);
}

}  // namespace
}  // namespace gi
