// The obscurance plugin (seed 001) against analytic cases: a lone plane is open; the step
// membership is ambient occlusion and the sqrt membership obscurance in a 90-degree corner
// (closed forms); the ambient transfer W is 1 in a closed white box, equals O for black
// occluders, stays finite and in [0, 1] for every albedo (the guard); far foreground objects
// cast no silhouette shadow; the 4x4 filter removes the interleave pattern without crossing
// depth edges; no NaN at grazing angles, extreme clip planes or on the sky; the radiance
// transfer is the albedo transfer times the environment without lights and takes the colour of
// a lit wall with them. The sample set and the SPIR-V specialization are checked on the CPU.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "../effects/obscurance/obscurance_kernel.h"
#include "effect_fixture.h"
#include "gi/renderer.h"
#include "process.h"
#include "quad_scene.h"

namespace gi {
namespace {

namespace obs = obscurance;
constexpr uint32_t kW = 160, kH = 120;

using test::cornerQuads;
using test::finite;
using test::patternEnergy;
using test::Quads;

// Quads of one material with linear albedo `albedo`, seen from `eye` towards `target`.
Scene quadScene(const Quads& quads, glm::vec3 eye, glm::vec3 target, float albedo = 0.8f,
                float znear = 0.05f, float zfar = 100.0f) {
  Scene s = test::quadScene(quads, eye, target, 1.0f, znear, zfar);
  s.materials[0].baseColor = glm::vec4(glm::vec3(albedo), 1.0f);
  return s;
}

glm::mat4 rotation(float degrees, glm::vec3 axis) {
  return glm::rotate(glm::mat4(1.0f), glm::radians(degrees), axis);
}
glm::mat4 translation(glm::vec3 t) {
  return glm::translate(glm::mat4(1.0f), t);
}

// The 90-degree concave corner (floor y = 0, wall x = 0) of albedo `albedo`.
Scene cornerScene(float albedo = 0.8f) {
  return quadScene(cornerQuads(), glm::vec3(2.5f, 1.6f, 0.0f), glm::vec3(0.0f), albedo);
}

// A closed box [-1, 1]^3 seen from inside.
Scene boxScene(float albedo) {
  Quads q;
  for (float s : {-1.0f, 1.0f}) {
    q.push_back({translation({0, 0, s}), 1.0f});
    q.push_back({translation({s, 0, 0}) * rotation(90, {0, 1, 0}), 1.0f});
    q.push_back({translation({0, s, 0}) * rotation(90, {1, 0, 0}), 1.0f});
  }
  return quadScene(q, glm::vec3(0.3f, 0.2f, 0.9f), glm::vec3(-0.2f, -0.3f, -1.0f), albedo);
}

// A crevice: three quads meeting in a cube corner, looked into.
Scene creviceScene(float albedo) {
  Quads q = cornerQuads();
  q.push_back({glm::mat4(1.0f), 20.0f});  // z = 0
  return quadScene(q, glm::vec3(1.2f, 1.0f, 1.4f), glm::vec3(0.0f), albedo);
}

class ObscuranceTest : public test::EffectTest {
 protected:
  std::string effectName() const override { return "obscurance"; }
  struct Result : test::AoFrame {
    double mean() const {
      double s = 0.0;
      for (size_t i = 0; i < ao.pixels.size(); i += 4) s += ao.pixels[i];
      return s / double(ao.pixels.size() / 4);
    }
  };
  Result render(const Scene& scene, const std::vector<std::string>& sets, uint32_t w = kW,
                uint32_t h = kH) {
    Renderer r(ctx(), scene, settingsFor(scene, sets, w, h), &registry);
    r.renderFrame();
    return {{r.readTarget("ao"), r.readTarget("depth"), r.camera(), int(w), int(h)}};
  }
};

// ---- closed forms ---------------------------------------------------------------------------

// Obscurance of a floor point at distance a R from an infinite wall: for cosine-distributed w,
// the component t towards the wall has density (2/pi) sqrt(1 - t^2) and the wall is hit at
// distance a R / t, so O = 1 - Int_a^1 (2/pi) sqrt(1 - t^2) (1 - mu(a / t)) dt.
double cornerObscurance(obs::Membership m, double a) {
  if (a >= 1.0) return 1.0;
  const int n = 20000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = a + (1.0 - a) * (i + 0.5) / n;
    sum += (2.0 / obs::kPi) * std::sqrt(1.0 - t * t) * (1.0 - obs::membership(m, a / t));
  }
  return 1.0 - sum * (1.0 - a) / n;
}
// Step membership = ambient occlusion: the same integral in closed form.
double cornerAO(double a) {
  return 1.0 - (obs::kPi / 2 - a * std::sqrt(1.0 - a * a) - std::asin(a)) / obs::kPi;
}

// ---- CPU: sample set, guard, specialization -------------------------------------------------

TEST(ObscuranceKernel, LloydSamplesAreDeterministicSpreadAndImportanceSampled) {
  const auto a = obs::lloydPoints(32, 3), b = obs::lloydPoints(32, 3);
  ASSERT_EQ(a, b) << "fixed seed";
  auto minDistance = [](const std::vector<std::array<double, 3>>& p) {
    double best = 1e9;
    for (size_t i = 0; i < p.size(); ++i)
      for (size_t j = i + 1; j < p.size(); ++j) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) d2 += (p[i][k] - p[j][k]) * (p[i][k] - p[j][k]);
        best = std::min(best, std::sqrt(d2));
      }
    return best;
  };
  // Uniform random points of the same count for comparison (what Lloyd starts from).
  std::mt19937 rng(1);
  std::vector<std::array<double, 3>> random(32);
  for (auto& p : random)
    for (auto& c : p) c = double(rng() >> 8) / 16777216.0;
  const double dLloyd = minDistance(a), dRandom = minDistance(random);
  std::printf("min distance: Lloyd %.3f, random %.3f\n", dLloyd, dRandom);
  EXPECT_GT(dLloyd, 2.0 * dRandom) << "relaxation spreads the points (Poisson-disc-like)";
  for (const auto& p : a)
    for (double c : p) ASSERT_TRUE(c >= 0.0 && c <= 1.0);

  // Importance sampling: 64 sqrt-membership taps. E[cos theta] = 2/3 (cosine lobe) and
  // E[r / R] = E[xi^2] = 1/3 (density mu'); a well-spread set gets both within 0.03.
  const auto taps = obs::sampleSet(obs::Membership::Sqrt, 64);
  double cosSum = 0.0, rSum = 0.0;
  for (const obs::Tap& t : taps) {
    const double r = std::sqrt(t.x * t.x + t.y * t.y + t.z * t.z);
    rSum += r;
    cosSum += r > 0 ? t.z / r : 1.0;
  }
  EXPECT_NEAR(cosSum / 64, 2.0 / 3.0, 0.03);
  EXPECT_NEAR(rSum / 64, 1.0 / 3.0, 0.03);
  for (const obs::Tap& t : obs::sampleSet(obs::Membership::Step, 16))  // every tap at R
    EXPECT_NEAR(std::sqrt(t.x * t.x + t.y * t.y + t.z * t.z), 1.0, 1e-5);
  for (auto m : {obs::Membership::Sqrt, obs::Membership::Linear, obs::Membership::Smoothstep})
    for (double u : {0.1, 0.5, 0.9})  // mu(mu^-1(u)) = u
      EXPECT_NEAR(obs::membership(m, obs::membershipInverse(m, u)), u, 1e-12);
}

TEST(ObscuranceKernel, TransferGuardKeepsWFiniteAndInUnitRange) {
  // The phantom open sample: W = (N + eta) / (D + eta) with 0 <= N <= D.
  EXPECT_EQ(obs::transferRatio(0.0f, 0.0f), 1.0f) << "fully occluded by white: W = 1";
  for (float n : {0.0f, 0.01f, 0.3f, 1.0f}) EXPECT_EQ(obs::transferRatio(n, n), 1.0f);
  // Full occlusion (N = 0) with albedo a: D = 1 - a. Finite, in [0, 1], monotone in a, -> 1.
  float previous = -1.0f;
  for (int i = 0; i <= 1000; ++i) {
    const float a = float(i) / 1000.0f, w = obs::transferRatio(0.0f, 1.0f - a);
    ASSERT_TRUE(std::isfinite(w)) << a;
    ASSERT_GE(w, 0.0f);
    ASSERT_LE(w, 1.0f);
    ASSERT_GE(w, previous) << "W grows with the albedo";
    previous = w;
  }
  EXPECT_LT(obs::transferRatio(0.0f, 1.0f), 1.01f * obs::kTransferGuard) << "black: W = O = 0";
  // Against the exact ratio O / (1 - a (1 - O)) away from the singular corner: the bias is
  // eta (1 - W) / (D + eta), at most eta for black occluders (D = 1).
  for (float o : {0.1f, 0.5f, 0.9f})
    for (float a : {0.0f, 0.5f, 0.99f}) {
      const float d = o + (1.0f - o) * (1.0f - a), exact = o / d;
      const float bias = obs::kTransferGuard * (1.0f - exact) / (d + obs::kTransferGuard);
      EXPECT_NEAR(obs::transferRatio(o, d), exact + bias, 1e-6f) << o << " " << a;
      if (a == 0.0f) {
        EXPECT_LE(bias, obs::kTransferGuard);
      }
    }
}

// ---- GPU ------------------------------------------------------------------------------------

TEST_F(ObscuranceTest, LonePlaneIsOpen) {
  Scene s = quadScene({{glm::mat4(1.0f), 1.0f}}, glm::vec3(0, 0, 5), glm::vec3(0));
  for (const char* m : {"sqrt", "step", "linear", "smoothstep"})
    for (const char* t : {"off", "albedo"}) {
      Result r =
          render(s, {std::string("obscurance.membership=") + m,
                     std::string("obscurance.transfer=") + t, "obscurance.points_per_ray=2"});
      ASSERT_TRUE(finite(r.ao));
      int sky = 0;
      for (int y = 0; y < r.h; ++y)
        for (int x = 0; x < r.w; ++x) {
          ASSERT_NEAR(r.at(x, y), 1.0f, 0.01f) << m << " " << t << " pixel " << x << "," << y;
          if (r.sky(x, y)) {
            ++sky;
            ASSERT_EQ(r.at(x, y), 1.0f) << "sky pixel " << x << "," << y;
          }
        }
      EXPECT_GT(sky, 1000);
    }
}

// Floor pixels of the corner scene at distances (minX, maxX) from the wall, centre columns.
std::vector<glm::ivec2> floorPixels(const auto& r, float minX, float maxX) {
  std::vector<glm::ivec2> out;
  for (int y = 4; y < r.h - 4; ++y)
    for (int x = r.w / 2 - 24; x < r.w / 2 + 24; ++x) {
      const glm::vec3 p = r.worldAt(x, y);
      if (!r.sky(x, y) && std::abs(p.y) < 1e-3f && p.x > minX && p.x < maxX) out.push_back({x, y});
    }
  return out;
}

// Mean rendered value against the mean closed form over floor pixels in bands of x / R.
void expectCornerMatches(const auto& r, obs::Membership m, double tolerance,
                         const std::string& what) {
  const float R = 0.5f;
  for (auto [lo, hi] : {std::pair{0.1f, 0.3f}, {0.3f, 0.5f}, {0.5f, 0.7f}, {0.7f, 0.9f}}) {
    const auto pixels = floorPixels(r, lo * R, hi * R);
    ASSERT_GE(pixels.size(), 100u) << what << " band " << lo;
    double rendered = 0.0, expected = 0.0;
    for (glm::ivec2 p : pixels) {
      rendered += r.at(p.x, p.y);
      expected += cornerObscurance(m, r.worldAt(p.x, p.y).x / R);
    }
    rendered /= double(pixels.size());
    expected /= double(pixels.size());
    std::printf("%s, x/R in [%.1f, %.1f]: rendered %.4f, closed form %.4f (%zu pixels)\n",
                what.c_str(), lo, hi, rendered, expected, pixels.size());
    EXPECT_NEAR(rendered, expected, tolerance) << what << " band " << lo;
  }
}

TEST_F(ObscuranceTest, StepMembershipIsAmbientOcclusionInACorner) {
  for (double a : {0.0, 0.3, 0.7, 0.99})  // the integrator against the AO closed form
    EXPECT_NEAR(cornerObscurance(obs::Membership::Step, a), cornerAO(a), 1e-4);
  for (const char* points : {"obscurance.points_per_ray=1", "obscurance.points_per_ray=2"}) {
    Result r = render(cornerScene(),
                      {"obscurance.radius=0.5", "obscurance.membership=step", "obscurance.bias=0",
                       "obscurance.samples=16", points},
                      320, 240);
    ASSERT_TRUE(finite(r.ao));
    expectCornerMatches(r, obs::Membership::Step, 0.02, points);  // measured worst 0.015
  }
}

TEST_F(ObscuranceTest, SqrtMembershipMatchesTheObscuranceClosedForm) {
  // Measured worst band: 0.029 with 16 samples (the sample set's own quadrature error is up to
  // 0.012 per band, the rest is the depth buffer's texel grid near the wall), 0.012 with 64.
  for (auto [n, tolerance] :
       {std::pair{"obscurance.samples=16", 0.035}, {"obscurance.samples=64", 0.015}}) {
    Result r = render(
        cornerScene(),
        {"obscurance.radius=0.5", "obscurance.membership=sqrt", "obscurance.bias=0", n}, 320, 240);
    expectCornerMatches(r, obs::Membership::Sqrt, tolerance, n);
  }
}

TEST_F(ObscuranceTest, ClosedWhiteBoxHasNoDarkCorners) {
  const Scene white = boxScene(1.0f);
  Result o = render(white, {"obscurance.transfer=off"});
  float darkest = 1.0f;
  for (int y = 0; y < o.h; ++y)
    for (int x = 0; x < o.w; ++x) darkest = std::min(darkest, o.at(x, y));
  std::printf("white box: darkest obscurance %.3f\n", darkest);
  ASSERT_LT(darkest, 0.8f) << "the box's corners must be occluded for the test to bite";
  for (const char* points : {"obscurance.points_per_ray=1", "obscurance.points_per_ray=2"}) {
    Result w = render(white, {"obscurance.transfer=albedo", points});
    for (int y = 0; y < w.h; ++y)
      for (int x = 0; x < w.w; ++x) {
        ASSERT_FALSE(w.sky(x, y)) << "the box is closed";
        ASSERT_NEAR(w.at(x, y), 1.0f, 1e-3f) << points << " pixel " << x << "," << y;
      }
  }
}

TEST_F(ObscuranceTest, BlackOccludersGiveTheObscurance) {
  const Scene black = cornerScene(0.0f);
  Result o = render(black, {"obscurance.transfer=off", "obscurance.membership=step"});
  Result w = render(black, {"obscurance.transfer=albedo", "obscurance.membership=step"});
  double worst = 0.0;
  float darkest = 1.0f;
  for (size_t i = 0; i < o.ao.pixels.size(); i += 4) {
    worst = std::max(worst, double(std::abs(o.ao.pixels[i] - w.ao.pixels[i])));
    darkest = std::min(darkest, o.ao.pixels[i]);
  }
  std::printf("albedo 0: max |W - O| %.5f, darkest O %.4f\n", worst, darkest);
  EXPECT_LT(darkest, 0.7f) << "the corner must be occluded for the test to bite";
  // The guard's bias (<= eta = 1e-3) plus 16-bit rounding of the sums (< 1e-3).
  EXPECT_LT(worst, 2e-3);
}

TEST_F(ObscuranceTest, TransferIsFiniteAndOrderedForEveryAlbedo) {
  Result o = render(creviceScene(0.5f), {"obscurance.transfer=off", "obscurance.radius=1"});
  std::vector<Result> sweep;
  const std::vector<float> albedos = {0.0f, 0.25f, 0.5f, 0.9f, 0.99f, 0.999f, 1.0f};
  for (float a : albedos)
    sweep.push_back(render(creviceScene(a), {"obscurance.transfer=albedo", "obscurance.radius=1"}));
  for (size_t k = 0; k < sweep.size(); ++k) {
    const Result& w = sweep[k];
    ASSERT_TRUE(finite(w.ao)) << albedos[k];
    for (size_t i = 0; i < w.ao.pixels.size(); i += 4) {
      const float v = w.ao.pixels[i];
      ASSERT_GE(v, 0.0f) << albedos[k];
      ASSERT_LE(v, 1.0f) << albedos[k];
      ASSERT_GE(v, o.ao.pixels[i] - 2e-3f) << "W >= O, albedo " << albedos[k];
      if (k > 0) {
        ASSERT_GE(v, sweep[k - 1].ao.pixels[i] - 2e-3f) << "W grows with the albedo";
      }
    }
    std::printf("crevice, albedo %.3f: mean W %.4f (mean O %.4f)\n", albedos[k], w.mean(),
                o.mean());
  }
  EXPECT_GT(sweep.back().mean(), 0.999);
  float darkest = 1.0f;
  for (size_t i = 0; i < o.ao.pixels.size(); i += 4) darkest = std::min(darkest, o.ao.pixels[i]);
  std::printf("crevice: darkest O %.4f\n", darkest);
  EXPECT_LT(darkest, 0.6f) << "the crevice must be occluded for the test to bite";
  EXPECT_GT(sweep[2].mean(), o.mean() + 0.01) << "albedo 0.5 must brighten the crevice";
  // The emission variant without emitters equals the albedo variant; with two points per ray.
  for (const char* t : {"obscurance.transfer=emission", "obscurance.transfer=albedo"}) {
    Result e = render(creviceScene(1.0f), {t, "obscurance.points_per_ray=2"});
    ASSERT_TRUE(finite(e.ao)) << t;
    EXPECT_GT(e.mean(), 0.999) << t;
  }
  // Emissive occluders add their radiance: W above the albedo variant's.
  Scene glowing = creviceScene(0.5f);
  glowing.materials[0].emission = glm::vec3(0.5f);
  Result e = render(glowing, {"obscurance.transfer=emission", "obscurance.radius=1"});
  ASSERT_TRUE(finite(e.ao));
  std::printf("crevice, albedo 0.5, emission 0.5: mean W %.4f (albedo variant %.4f)\n", e.mean(),
              sweep[2].mean());
  EXPECT_GT(e.mean(), sweep[2].mean() + 0.01);
}

// transfer = radiance without lights or emission: the occluders send only their share of the
// ambient light, so the published ambient is L^a x the albedo transfer W (the same sums; the
// guard's phantom sample sees L^a in both) and the lit images agree. Tolerance: the sums'
// half floats and the filter averaging L^a over its window (constant on each face here).
TEST_F(ObscuranceTest, RadianceTransferWithoutLightsIsTheAlbedoTransferTimesTheAmbient) {
  const Scene crevice = creviceScene(0.7f);  // no lights: the environment alone
  auto lit = [&](const char* transfer, ImageRGBA32F* ambient) {
    Renderer r(
        ctx(), crevice,
        settingsFor(crevice, {transfer, "obscurance.radius=1", "obscurance.samples=16"}, kW, kH),
        &registry);
    r.renderFrame();
    if (ambient) *ambient = r.readTarget("ambient");
    return r.readTarget("lit");
  };
  ImageRGBA32F ambient;
  const ImageRGBA32F a = lit("obscurance.transfer=albedo", nullptr);
  const ImageRGBA32F b = lit("obscurance.transfer=radiance", &ambient);
  const Result o = render(crevice, {"obscurance.transfer=off", "obscurance.radius=1"});
  ASSERT_TRUE(finite(b));
  ASSERT_TRUE(finite(ambient));
  // Within 2 pixels of a crease the filter's window holds two faces and their different L^a:
  // the worst there is measured, not bounded; elsewhere (0.1 from the creases) it is.
  double worst = 0.0, worstAway = 0.0, sum = 0.0;
  int n = 0;
  for (int y = 0; y < o.h; ++y)
    for (int x = 0; x < o.w; ++x) {
      const size_t i = (size_t(y) * o.w + x) * 4;
      if (o.sky(x, y)) {
        EXPECT_EQ(ambient.pixels[i + 3], 0.0f) << "sky: the lighting pass's own term";
        continue;
      }
      ASSERT_EQ(ambient.pixels[i + 3], 2.0f) << "per unit albedo, at " << x << "," << y;
      // On a face one coordinate is 0; away from its creases both others exceed 0.1.
      const glm::vec3 w = glm::abs(o.worldAt(x, y));
      const bool away =
          w.x + w.y + w.z - std::min({w.x, w.y, w.z}) - std::max({w.x, w.y, w.z}) > 0.1f;
      for (int c = 0; c < 3; ++c) {
        const double rel = std::abs(double(b.pixels[i + c]) - a.pixels[i + c]) /
                           std::max(double(a.pixels[i + c]), 1e-3);
        worst = std::max(worst, rel), sum += rel, ++n;
        if (away) worstAway = std::max(worstAway, rel);
      }
    }
  std::printf(
      "no lights: lit radiance vs albedo transfer: mean relative difference %.5f, worst "
      "%.5f away from the creases, %.5f next to them, over %d channels\n",
      sum / n, worstAway, worst, n);
  ASSERT_GT(n, 10000);
  EXPECT_LT(sum / n, 2e-3);
  EXPECT_LT(worstAway, 5e-3);  // measured 0.0013
}

// A white floor next to a red wall lit by a sun that grazes the floor: with transfer = radiance
// the floor's ambient light near the wall turns red and rises above the open sky's (the wall
// sends its direct light: W above 1), fading with the distance; the albedo transfer's stays
// grey and below the open floor's.
TEST_F(ObscuranceTest, RadianceTransferBleedsTheColourOfALitWall) {
  const std::string path = test::makeTempDir("scenes") + "/obscurance_red_wall.json";
  {
    std::ofstream f(path);
    f << R"({
      "models": [
        { "primitive": "plane", "size": 20, "material": { "base_color": [0.8, 0.8, 0.8] } },
        { "primitive": "plane", "size": 20, "rotation": [0, 0, -90],
          "material": { "base_color": [0.9, 0.05, 0.05] } } ],
      "lights": [ { "type": "directional", "direction": [-1, -0.02, 0], "intensity": 4 } ],
      "camera": { "position": [2.5, 1.6, 0], "target": [0, 0, 0] } })";
  }
  const Scene scene = loadSceneJson(path);
  struct Out {
    ImageRGBA32F ambient, lit;
  };
  auto run = [&](const char* transfer) {
    Renderer r(ctx(), scene, settingsFor(scene, {transfer, "obscurance.radius=0.5"}, kW, kH),
               &registry);
    r.renderFrame();
    Out out{{}, r.readTarget("lit")};
    if (std::string(transfer).find("radiance") != std::string::npos) {
      out.ambient = r.readTarget("ambient");
      // The occluders' direct radiance first, after the shadow map it reads.
      EXPECT_EQ(r.passNames(), (std::vector<std::string>{
                                   "gbuffer", "shadow_0", "obscurance_radiance", "obscurance",
                                   "obscurance_filter", "lighting", "tonemap"}));
    }
    return out;
  };
  const Out radiance = run("obscurance.transfer=radiance");
  const Out albedo = run("obscurance.transfer=albedo");
  {
    // Having summed the lights, the radiance pass publishes them as "direct_light", as SSDO's
    // bounce does (whose direct_light is tested to be the lighting pass's own sum): the same
    // values, within half-float rounding.
    Renderer r(
        ctx(), scene,
        settingsFor(scene, {"obscurance.transfer=radiance", "obscurance.radius=0.5"}, kW, kH),
        &registry);
    r.renderFrame();
    const ImageRGBA32F mine = r.readTarget("direct_light");
    ASSERT_TRUE(registry.has("ssdo"));
    const RenderSettings rs = settingsFor({"ssdo"}, scene, {}, kW, kH);
    Renderer s(ctx(), scene, rs, &registry);
    s.renderFrame();
    const ImageRGBA32F theirs = s.readTarget("direct_light");
    double worst = 0.0, maxValue = 0.0;
    for (size_t i = 0; i < mine.pixels.size(); ++i) {
      if (i % 4 == 3) continue;
      worst = std::max(worst, double(std::abs(mine.pixels[i] - theirs.pixels[i])) /
                                  std::max(1.0, double(theirs.pixels[i])));
      maxValue = std::max(maxValue, double(theirs.pixels[i]));
    }
    std::printf("direct_light against SSDO's: worst relative difference %.5f (max value %.3f)\n",
                worst, maxValue);
    EXPECT_GT(maxValue, 0.1) << "the wall must be lit for the test to bite";
    EXPECT_LT(worst, 2e-3);
  }
  const Result o = render(scene, {"obscurance.transfer=off", "obscurance.radius=0.5"});
  ASSERT_TRUE(finite(radiance.ambient));
  ASSERT_TRUE(finite(radiance.lit));
  // Mean ambient (radiance) and lit colour (both) over floor pixels in a band of x.
  auto band = [&](const ImageRGBA32F& img, float x0, float x1, int* count) {
    glm::dvec3 sum(0.0);
    *count = 0;
    for (int y = 0; y < o.h; ++y)
      for (int x = 0; x < o.w; ++x) {
        if (o.sky(x, y)) continue;
        const glm::vec3 w = o.worldAt(x, y);
        if (std::abs(w.y) > 1e-3f || w.x < x0 || w.x >= x1 || std::abs(w.z) > 1.0f) continue;
        const float* p = &img.pixels[(size_t(y) * o.w + x) * 4];
        sum += glm::dvec3(p[0], p[1], p[2]), ++*count;
      }
    return *count > 0 ? sum / double(*count) : sum;
  };
  int nNear = 0, nMid = 0, nFar = 0;
  const glm::dvec3 near = band(radiance.ambient, 0.02f, 0.1f, &nNear);
  const glm::dvec3 mid = band(radiance.ambient, 0.25f, 0.4f, &nMid);
  const glm::dvec3 far = band(radiance.ambient, 0.8f, 1.5f, &nFar);  // beyond R: open
  ASSERT_GT(nNear, 20);
  ASSERT_GT(nMid, 20);
  ASSERT_GT(nFar, 20);
  auto redness = [](glm::dvec3 c) { return c.r / std::max(c.g, 1e-9); };
  std::printf(
      "floor ambient (per unit albedo) near / mid / far from the red wall: "
      "(%.3f %.3f %.3f) / (%.3f %.3f %.3f) / (%.3f %.3f %.3f); r/g %.2f / %.2f / %.2f\n",
      near.r, near.g, near.b, mid.r, mid.g, mid.b, far.r, far.g, far.b, redness(near), redness(mid),
      redness(far));
  EXPECT_GT(redness(near), 1.5 * redness(far)) << "the lit red wall tints the floor near it";
  EXPECT_GT(redness(near), redness(mid)) << "the tint fades with the distance";
  EXPECT_GT(redness(mid), redness(far));
  EXPECT_GT(near.r, far.r) << "the lit wall sends more red than the open sky: W above 1";
  // The albedo transfer's lit floor: grey (the floor's own colour), darker near the wall.
  int a0 = 0, a1 = 0;
  const glm::dvec3 litNear = band(albedo.lit, 0.02f, 0.1f, &a0);
  const glm::dvec3 litFar = band(albedo.lit, 0.8f, 1.5f, &a1);
  std::printf("albedo transfer, lit floor near / far: r/g %.3f / %.3f\n", redness(litNear),
              redness(litFar));
  EXPECT_NEAR(redness(litNear), redness(litFar), 0.05 * redness(litFar));
}

TEST_F(ObscuranceTest, NoFalseSilhouetteShadowAndNoFilterAcrossDepthEdges) {
  // A wall at z = 0 and, 3 units (6 R) in front of it, an open book of two small quads at 90
  // degrees opening towards the camera: dark inside, up to its silhouettes. Wall pixels around
  // the silhouettes must not darken: not by the book as an occluder (0 < z - z* < R) and not
  // by filtering the book's values into them (depth-aware filter).
  Scene s = quadScene(test::openBookQuads(), test::kOpenBookEye, glm::vec3(0));
  for (const char* filter : {"obscurance.filter=false", "obscurance.filter=true"}) {
    Result r = render(s, {"obscurance.radius=0.5", "obscurance.membership=step", filter});
    const test::BookOutline o = test::bookOutline(r);
    for (const auto& [px, v] : o.wall)
      ASSERT_GT(v, 0.99f) << filter << " wall pixel " << px.x << "," << px.y << " darkened";
    std::printf("%s: darkest book pixel next to the wall %.3f\n", filter, o.darkestPage);
    EXPECT_GT(o.wall.size(), 50u) << filter;
    ASSERT_GT(o.pages, 50) << filter;
    EXPECT_LT(o.darkestPage, 0.95f) << filter << ": the book must be dark for the test to bite";
  }
}

TEST_F(ObscuranceTest, FilterRemovesTheInterleavePattern) {
  for (const char* t : {"obscurance.transfer=off", "obscurance.transfer=albedo"}) {
    auto with = [&](const char* filter) {
      return render(cornerScene(0.5f),
                    {"obscurance.samples=8", "obscurance.membership=step", t, filter}, 320, 240);
    };
    Result raw = with("obscurance.filter=false"), filtered = with("obscurance.filter=true");
    const double eRaw = patternEnergy(raw, 0.05f, 0.4f), eF = patternEnergy(filtered, 0.05f, 0.4f);
    std::printf("%s: pattern energy raw %.3g, filtered %.3g (%.0fx less)\n", t, eRaw, eF,
                eRaw / eF);
    EXPECT_GT(eRaw, 1e-4) << t << ": the raw interleaved estimate should show its pattern";
    EXPECT_LT(eF, eRaw / 50.0) << t;
  }
}

TEST_F(ObscuranceTest, NoNaNAtGrazingAnglesExtremeClipPlanesOrSky) {
  const glm::mat4 floor = rotation(-90, {1, 0, 0});
  Scene grazing = quadScene({{floor, 1000.0f}}, glm::vec3(0, 0.01f, 0), glm::vec3(0, 0.01f, -10),
                            0.8f, 1e-4f, 1e5f);
  for (const char* radius :
       {"obscurance.radius=0.5", "obscurance.radius=1e-4", "obscurance.radius=1e4"}) {
    for (const char* t : {"obscurance.transfer=off", "obscurance.transfer=albedo",
                          "obscurance.transfer=emission"}) {
      Result r = render(grazing, {radius, t, "obscurance.points_per_ray=2"});
      ASSERT_TRUE(finite(r.ao)) << radius << " " << t;
      double sum = 0.0;
      int floorPixels = 0, sky = 0;
      for (int y = 0; y < r.h; ++y)
        for (int x = 0; x < r.w; ++x) {
          ASSERT_GE(r.at(x, y), 0.0f);
          ASSERT_LE(r.at(x, y), 1.0f);
          if (r.sky(x, y)) {
            ++sky;
            ASSERT_EQ(r.at(x, y), 1.0f) << "sky";
          } else {
            sum += r.at(x, y), ++floorPixels;
          }
        }
      ASSERT_GT(floorPixels, 1000);
      ASSERT_GT(sky, 1000);
      std::printf("grazing floor, %s, %s: mean %.4f\n", radius, t, sum / floorPixels);
      EXPECT_GT(sum / floorPixels, 0.98)
          << radius << " " << t << ": a plane does not occlude itself";
    }
  }  // transfer = radiance publishes "ambient": finite and non-negative there too, sky untouched.
  for (const char* radius : {"obscurance.radius=1e-4", "obscurance.radius=1e4"}) {
    Renderer r(ctx(), grazing,
               settingsFor(grazing, {radius, "obscurance.transfer=radiance"}, kW, kH), &registry);
    r.renderFrame();
    const ImageRGBA32F ambient = r.readTarget("ambient"), depth = r.readTarget("depth");
    ASSERT_TRUE(finite(ambient)) << radius;
    ASSERT_TRUE(finite(r.readTarget("lit"))) << radius;
    for (size_t i = 0; i < ambient.pixels.size(); i += 4) {
      ASSERT_GE(std::min({ambient.pixels[i], ambient.pixels[i + 1], ambient.pixels[i + 2]}), 0.0f)
          << radius;
      if (depth.pixels[i] <= 0.0f) {
        ASSERT_EQ(ambient.pixels[i + 3], 0.0f) << radius << " sky";
      }
    }
  }
}

TEST_F(ObscuranceTest, PassListAndLiveSettings) {
  Scene scene = cornerScene();
  RenderSettings rs = settingsFor(scene, {}, kW, kH);
  Renderer r(ctx(), scene, rs, &registry);
  r.renderFrame();
  EXPECT_EQ(r.passNames(), (std::vector<std::string>{"gbuffer", "obscurance", "obscurance_filter",
                                                     "lighting", "tonemap"}));
  auto meanAO = [&] {
    const ImageRGBA32F ao = r.readTarget("ao");
    double sum = 0.0;
    for (size_t i = 0; i < ao.pixels.size(); i += 4) sum += ao.pixels[i];
    return sum / double(ao.pixels.size() / 4);
  };
  const double sqrtMean = meanAO();
  // Membership and radius are uniform-only: applied next frame without a recompile.
  SettingValues values = rs.effects[0].settings;
  values.set("membership", "step", "test");
  r.setEffectSettings("obscurance", values);
  EXPECT_FALSE(r.graphRecompiledByLastChange());
  r.renderFrame();
  const double stepMean = meanAO();
  std::printf("mean: sqrt %.4f, step %.4f\n", sqrtMean, stepMean);
  EXPECT_LT(stepMean, sqrtMean - 0.005) << "AO darkens more than sqrt obscurance";
  // Specialization constants change the graph.
  values.set("samples", 8, "test");
  r.setEffectSettings("obscurance", values);
  EXPECT_TRUE(r.graphRecompiledByLastChange());
  r.renderFrame();
  EXPECT_NEAR(meanAO(), stepMean, 0.02);
}

}  // namespace
}  // namespace gi
