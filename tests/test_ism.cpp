// The ISM plugin (effects/ism): the VPL singularity guard and the pull-push rules on the CPU;
// on the GPU: one VPL above a floor with a box casts an ISM shadow that overlaps the classic
// (triangle) shadow map's, pull-push closes light leaks, an all-black RSM gives zero indirect
// light without NaN, a receiver behind every VPL's hemisphere gets 0, moving the light moves
// the VPLs (and their light), the ISM shadow follows an animated mesh, 1, 2, 3 bounces add up
// monotonically, and a scene without the effect runs no ISM pass. Glossy receivers: the Phong
// lobe's normalisation and bounds (CPU), a highlight at the VPL's mirror direction (GPU).
// Classic mode's maps are this frame's (its first frame already has the shadow). Environment
// VPLs: an open floor gets the environment's light through them alone (the engine's term is
// replaced, not doubled), a box shadows the floor beside it and the shadow follows the box when
// it moves, a black environment adds nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "../effects/ism/ism_params.h"
#include "effect_fixture.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

constexpr uint32_t kW = 160, kH = 120;

// ---- CPU: the formulas the shaders implement ----------------------------------------------

// d = 0 has no direction: 0, not NaN; below d_min the irradiance is that of d_min (bounded);
// beyond it the plain 1 / d^2 law.
TEST(IsmFormulas, SingularityGuardKeepsTheVplFinite) {
  const glm::vec3 n(0, 1, 0), nv(0, -1, 0), phi(3.0f);
  const float dMin = 0.1f;
  EXPECT_EQ(ism::vplIrradiance(glm::vec3(0), n, glm::vec3(0), nv, phi, dMin), glm::vec3(0.0f));
  // Facing each other at distance d: cos = 1 both, E = phi / (pi max(d^2, dMin^2)).
  for (float d : {1e-6f, 0.01f, 0.05f, 0.1f, 0.5f, 2.0f}) {
    const glm::vec3 e = ism::vplIrradiance(glm::vec3(0), n, glm::vec3(0, d, 0), nv, phi, dMin);
    const float expected = 3.0f / (3.14159265f * std::max(d * d, dMin * dMin));
    EXPECT_TRUE(std::isfinite(e.x)) << d;
    EXPECT_NEAR(e.x, expected, 1e-4f * expected) << d;
  }
  EXPECT_LE(ism::vplIrradiance(glm::vec3(0), n, glm::vec3(0, 1e-30f, 0), nv, phi, dMin).x,
            3.0f / (3.14159265f * dMin * dMin) * 1.0001f);
}

// A receiver behind the VPL's hemisphere (or facing away) gets nothing.
TEST(IsmFormulas, ReceiverBehindTheVplHemisphereGetsZero) {
  const glm::vec3 nv(0, 1, 0), phi(1.0f);
  // Below the VPL (which faces up), receiver facing up toward it: cos at the VPL < 0.
  EXPECT_EQ(
      ism::vplIrradiance(glm::vec3(0.3f, -1, 0), glm::vec3(0, 1, 0), glm::vec3(0), nv, phi, 0.01f),
      glm::vec3(0.0f));
  // Above it but facing away.
  EXPECT_EQ(
      ism::vplIrradiance(glm::vec3(0, 1, 0), glm::vec3(0, 1, 0), glm::vec3(0), nv, phi, 0.01f),
      glm::vec3(0.0f));
  glm::vec2 p;
  EXPECT_FALSE(ism::paraboloid(ism::basis(nv), glm::vec3(0, -1, 0), p));
  ASSERT_TRUE(ism::paraboloid(ism::basis(nv), glm::vec3(0, 1, 0), p));
  EXPECT_EQ(p, glm::vec2(0.0f));  // the axis maps to the disk's centre
}

// Pull averages only depths close to the nearest child (a far point shining through is not
// mixed in); push fills holes and replaces outliers far behind the coarse value, and keeps
// valid texels near it or in front of it.
// The Phong lobe (n + 2) / (2 pi) cos^n(alpha): exactly its maximum at the mirror direction,
// reflecting at most all the light (the directional albedo, integrated over incoming directions
// with the receiver's cosine, is 1 within 1% for a view along the normal and below 1 at grazing
// views), finite and 0 for w = 0 and at grazing incidence.
TEST(IsmFormulas, PhongLobeIsNormalisedAndPeaksAtTheMirrorDirection) {
  const glm::vec3 n(0, 0, 1);
  const float pi = 3.14159265f;
  for (float e : {1.0f, 8.0f, 32.0f, gi::ism::kMaxPhongExponent}) {
    const glm::vec3 v = glm::normalize(glm::vec3(0.6f, 0, 0.8f));
    const glm::vec3 w = glm::reflect(v, n);  // light whose mirror direction is v
    EXPECT_NEAR(gi::ism::phongLobe(w, n, v, e), (e + 2) / (2 * pi), 1e-4f * (e + 2));
    EXPECT_LT(gi::ism::phongLobe(glm::normalize(w + glm::vec3(0.3f, 0.2f, 0)), n, v, e),
              (e + 2) / (2 * pi));
    EXPECT_EQ(gi::ism::phongLobe(glm::vec3(0.0f), n, v, e), 0.0f);
    const float grazing = gi::ism::phongLobe(glm::vec3(1, 0, 0), n, glm::vec3(1, 0, 0), e);
    EXPECT_TRUE(std::isfinite(grazing) && grazing >= 0.0f) << grazing;
    // Directional albedo: sum over a theta x phi grid of lobe x cos(theta) x sin(theta).
    for (float viewAngle : {0.0f, 1.3f}) {
      const glm::vec3 view(std::sin(viewAngle), 0, std::cos(viewAngle));
      const int nt = 400, np = 400;
      double albedo = 0;
      for (int i = 0; i < nt; ++i)
        for (int j = 0; j < np; ++j) {
          const float t = (i + 0.5f) * 0.5f * pi / nt, ph = (j + 0.5f) * 2 * pi / np;
          const glm::vec3 in(std::sin(t) * std::cos(ph), std::sin(t) * std::sin(ph), std::cos(t));
          albedo += gi::ism::phongLobe(-in, n, view, e) * std::cos(t) * std::sin(t) *
                    (0.5 * pi / nt) * (2 * pi / np);
        }
      if (viewAngle == 0.0f)
        EXPECT_NEAR(albedo, 1.0, 0.01) << e;
      else
        EXPECT_LT(albedo, 1.0) << e;
    }
  }
}

// Glossy radiance f0 x lobe x E stays bounded by the singularity guard: at most
// f0 (n + 2) / (2 pi) phi / (pi d_min^2) for receivers from d = 0 out, finite everywhere.
TEST(IsmFormulas, GlossyVplLightIsBoundedByTheSingularityGuard) {
  const glm::vec3 nv(0, -1, 0), phi(3.0f), n(0, 1, 0);
  const float dMin = 0.05f, e = gi::ism::kMaxPhongExponent, f0 = 1.0f;
  const float bound = f0 * (e + 2) / (2 * 3.14159265f) * 3.0f / (3.14159265f * dMin * dMin);
  float largest = 0.0f;
  for (float d : {0.0f, 1e-12f, 1e-6f, 1e-3f, 0.01f, 0.05f, 0.2f, 1.0f})
    for (float x : {0.0f, 1e-6f, 1e-3f, 0.01f}) {
      const glm::vec3 xv(0, 1, 0), p = xv + glm::vec3(x, -d, 0);
      const glm::vec3 v = glm::normalize(glm::reflect(p - xv, n) + glm::vec3(0, 1e-7f, 0));
      const glm::vec3 l = f0 * gi::ism::phongLobe(p - xv, n, v, e) *
                          gi::ism::vplIrradiance(p, n, xv, nv, phi, dMin);
      ASSERT_TRUE(std::isfinite(l.x)) << d << " " << x;
      EXPECT_LE(l.x, bound * 1.0001f) << d << " " << x;
      largest = std::max(largest, l.x);
    }
  EXPECT_GT(largest, 0.5f * bound);  // the bound is reached (at d <= d_min, mirror direction)
}

TEST(IsmFormulas, PullPushFillsHolesWithoutDepthOutliers) {
  const float inf = std::numeric_limits<float>::infinity();
  const float children[4] = {2.0f, 2.1f, inf, 9.0f};
  const ism::PullPushTexel pulled = ism::pullDepth(children, 0.5f);
  EXPECT_FLOAT_EQ(pulled.depth, 2.05f);  // 9 rejected, hole ignored
  EXPECT_TRUE(pulled.majority);          // 2 of the 3 valid children
  const float holes[4] = {inf, inf, inf, inf};
  EXPECT_FALSE(std::isfinite(ism::pullDepth(holes, 0.5f).depth));
  auto push = [](float fine, ism::PullPushTexel coarse) {
    return ism::pushDepth({fine, false}, coarse, 0.5f).depth;
  };
  EXPECT_FLOAT_EQ(push(inf, pulled), 2.05f);   // hole filled
  EXPECT_FLOAT_EQ(push(9.0f, pulled), 2.05f);  // outlier behind replaced
  EXPECT_FLOAT_EQ(push(2.3f, pulled), 2.3f);   // close: kept
  EXPECT_FLOAT_EQ(push(1.0f, pulled), 1.0f);   // in front: kept
  EXPECT_FLOAT_EQ(push(3.0f, {}), 3.0f);       // nothing coarse to push
  // A silhouette: one near child among three far ones. The coarse value is the near surface's
  // (holes next to it are filled with it) but it is a minority: the far texels stay.
  const float edge[4] = {2.0f, 9.0f, 9.1f, 9.0f};
  const ism::PullPushTexel silhouette = ism::pullDepth(edge, 0.5f);
  EXPECT_FLOAT_EQ(silhouette.depth, 2.0f);
  EXPECT_FALSE(silhouette.majority);
  EXPECT_FLOAT_EQ(push(9.0f, silhouette), 9.0f);
  EXPECT_FLOAT_EQ(push(inf, silhouette), 2.0f);
}

// The environment VPLs' orthographic maps fitted to the view: a camera that sees part of a
// large scene gets a smaller map (a smaller texel) that still holds every point it sees, with a
// depth origin past the scene's far side; a camera looking away from the scene, or a broken
// matrix, gets the whole scene.
TEST(IsmFormulas, EnvironmentMapsFitWhatTheCameraSees) {
  const glm::vec3 lo(-10, 0, -10), hi(10, 5, 10);
  const float sceneRadius = 0.5f * glm::length(hi - lo);
  const glm::vec3 eye(0, 2, 8);
  const glm::mat4 proj = perspectiveReverseZ(glm::radians(30.0f), 1.0f, 0.1f, 100.0f);
  const glm::mat4 view = glm::lookAt(eye, glm::vec3(0, 2, -10), glm::vec3(0, 1, 0));
  const ism::OrthoFit fit = ism::fitEnvironmentMaps(lo, hi, glm::inverse(proj * view), eye);
  EXPECT_LT(fit.radius, 0.8f * sceneRadius);
  for (const glm::vec3 seen : {glm::vec3(0, 0, 0), glm::vec3(0, 0, -10), glm::vec3(2, 2, 6)})
    EXPECT_LE(glm::length(seen - fit.centre), fit.radius) << seen.x << "," << seen.z;
  for (int i = 0; i < 8; ++i) {  // every occluder of the scene lies in front of the depth origin
    const glm::vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
    EXPECT_GE(fit.depth, glm::length(corner - fit.centre));
  }
  const glm::vec3 away(0, 2, 20);
  const glm::mat4 awayView = glm::lookAt(away, glm::vec3(0, 2, 40), glm::vec3(0, 1, 0));
  const ism::OrthoFit whole = ism::fitEnvironmentMaps(lo, hi, glm::inverse(proj * awayView), away);
  EXPECT_FLOAT_EQ(whole.radius, sceneRadius);
  EXPECT_FLOAT_EQ(whole.depth, sceneRadius);
  const glm::mat4 broken(std::numeric_limits<float>::quiet_NaN());
  const ism::OrthoFit guarded = ism::fitEnvironmentMaps(lo, hi, broken, eye);
  EXPECT_FLOAT_EQ(guarded.radius, sceneRadius);
  EXPECT_TRUE(std::isfinite(guarded.centre.x));
}

// Environment VPLs: the k^2 interleaving phases each gather every k^2-th VPL, so each phase's
// sample points must cover both coordinates of the sampler's unit square, not just all of them
// together: 256 points, 16 phases, each phase's 16 points one in every 1/16 slab of either
// coordinate. (Plain Hammersley points put a phase's 16 second coordinates in one slab: a
// sixteenth of the sky's azimuths per phase, which the blur left as stripes on a bumpy model.)
TEST(IsmFormulas, EnvironmentSamplePointsStratifyEachInterleavingPhase) {
  const uint32_t n = 256, phases = 16;
  for (uint32_t phase = 0; phase < phases; ++phase) {
    std::vector<int> first(phases, 0), second(phases, 0);
    for (uint32_t i = phase; i < n; i += phases) {
      const glm::vec2 u = ism::envSamplePoint(i, n, phases);
      ASSERT_TRUE(u.x >= 0.0f && u.x < 1.0f && u.y >= 0.0f && u.y < 1.0f) << i;
      ++first[size_t(u.x * phases)];
      ++second[size_t(u.y * phases)];
    }
    for (uint32_t b = 0; b < phases; ++b) {
      EXPECT_EQ(first[b], 1) << "phase " << phase << " slab " << b;
      EXPECT_EQ(second[b], 1) << "phase " << phase << " slab " << b;
    }
  }
}

// ---- GPU ------------------------------------------------------------------------------------

class IsmTest : public test::EffectTest {
 protected:
  std::string effectName() const override { return "ism"; }
  struct Result {
    ImageRGBA32F indirect, depth, lit;
    CameraView camera;
    std::vector<std::string> passes, warnings;
    glm::vec3 px(const ImageRGBA32F& img, int x, int y) const {
      const float* p = &img.pixels[(size_t(y) * kW + x) * 4];
      return {p[0], p[1], p[2]};
    }
    bool sky(int x, int y) const { return depth.pixels[(size_t(y) * kW + x) * 4] <= 0.0f; }
    // The pixel that shows world point p (the camera's projection; Vulkan's y points down).
    glm::ivec2 pixelOf(const glm::vec3& p) const {
      const glm::vec4 c = camera.proj * camera.view * glm::vec4(p, 1.0f);
      const glm::vec2 ndc = glm::vec2(c) / c.w;
      return glm::ivec2((ndc * 0.5f + 0.5f) * glm::vec2(kW, kH));
    }
    glm::vec3 worldAt(int x, int y) const {
      const float d = depth.pixels[(size_t(y) * kW + x) * 4];
      glm::vec4 v = glm::inverse(camera.proj) *
                    glm::vec4((x + 0.5f) / kW * 2 - 1, (y + 0.5f) / kH * 2 - 1, d, 1.0f);
      return glm::vec3(glm::inverse(camera.view) * glm::vec4(glm::vec3(v) / v.w, 1.0f));
    }
  };
  Result render(const Scene& scene, const std::vector<std::string>& sets, int frames = 1,
                bool withIsm = true, double time = 0.0) {
    return renderEffects(scene,
                         withIsm ? std::vector<std::string>{"ism"} : std::vector<std::string>{},
                         sets, frames, time);
  }
  // `effects` together; "indirect" is read when an effect published it.
  Result renderEffects(const Scene& scene, const std::vector<std::string>& effects,
                       const std::vector<std::string>& sets, int frames = 1, double time = 0.0) {
    Renderer r(ctx(), scene, settingsFor(effects, scene, sets, kW, kH), &registry);
    r.setTime(time);
    for (int i = 0; i < frames; ++i) r.renderFrame();
    Result res;
    res.passes = r.passNames();
    res.warnings = r.warnings();
    // Without a light to bounce or environment VPLs ISM adds no pass (and no "indirect").
    for (const auto& e : r.effectPasses())
      if (e.run > 0 && (e.effect == "ism" || e.effect == "ssdo"))
        res.indirect = r.readTarget("indirect");
    res.depth = r.readTarget("depth");
    res.lit = r.readTarget("lit");
    res.camera = r.camera();
    return res;
  }
  Scene jsonScene(const std::string& name, const std::string& json) {
    const std::string path = test::makeTempDir("scenes") + "/ism_" + name + ".json";
    {
      std::ofstream f(path);
      f << json;
    }
    return loadSceneJson(path);
  }
  // One VPL: a spot light below a small down-facing panel lights only the panel, whose one VPL
  // lights a floor with a box on it (`boxAnimation`: an "animation" entry for the box).
  Scene panelScene(const std::string& boxAnimation = "") {
    return panelLitScene("panel" + std::to_string(boxAnimation.size()),
                         R"(
        { "primitive": "plane", "size": 12, "material": { "base_color": [0.8, 0.8, 0.8] } },
        { "primitive": "box", "size": [1, 1.5, 1], "translation": [0, 0.75, 0], )" +
                             boxAnimation + R"(
          "material": { "base_color": [0.8, 0.8, 0.8] } },)",
                         R"({ "position": [0, 6, 6], "target": [1, 0, 0] })");
  }
  // The only light is a spot below a small down-facing white panel at (-2, 2, 0): it lights
  // just the panel, so every first-bounce VPL sits on it. `models`: the other models' entries,
  // each followed by a comma; `camera`: the camera object.
  Scene panelLitScene(const std::string& name, const std::string& models,
                      const std::string& camera) {
    return jsonScene(name, R"({ "models": [ )" + models + R"(
        { "primitive": "plane", "size": 0.5, "translation": [-2, 2, 0], "rotation": [180, 0, 0],
          "material": { "base_color": [1, 1, 1] } } ],
      "lights": [ { "type": "spot", "position": [-2, 1.5, 0], "direction": [0, 1, 0],
                    "intensity": 50, "inner_cone_deg": 5, "outer_cone_deg": 10,
                    "casts_shadows": false } ],
      "camera": )" + camera + R"(,
      "environment": { "type": "constant", "intensity": 0 } })");
  }
  // Geometry pixels with exactly zero indirect light (one VPL, no interleaving, no blur: a
  // pixel in its shadow or facing away from it gets exactly 0).
  static std::vector<bool> shadowMask(const Result& r, int* lit = nullptr) {
    std::vector<bool> m(kW * kH, false);
    int n = 0;
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(kW); ++x) {
        if (r.sky(x, y)) continue;
        const glm::vec3 e = r.px(r.indirect, x, y);
        m[size_t(y) * kW + x] = e.x == 0.0f && e.y == 0.0f && e.z == 0.0f;
        if (!m[size_t(y) * kW + x]) ++n;
      }
    if (lit) *lit = n;
    return m;
  }
  static double iou(const std::vector<bool>& a, const std::vector<bool>& b) {
    int both = 0, either = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      both += a[i] && b[i];
      either += a[i] || b[i];
    }
    return either > 0 ? double(both) / either : 1.0;
  }
  // A floor (albedo 0.8) under a white constant environment, its only light (the light is
  // off: a scene without one gets a default sun); `box`: a unit box on it at the origin
  // (`boxAnimation`: an "animation" entry for it).
  Scene environmentScene(const std::string& name, bool box, float intensity = 1.0f,
                         const std::string& boxAnimation = "") {
    return jsonScene(name, R"({ "models": [
        { "primitive": "plane", "size": 10, "material": { "base_color": [0.8, 0.8, 0.8] } })" +
                               std::string(box ? R"(,
        { "primitive": "box", "size": [1, 1, 1], "translation": [0, 0.5, 0], )" +
                                                     boxAnimation + R"(
          "material": { "base_color": [0.8, 0.8, 0.8] } })"
                                               : "") +
                               R"( ],
      "lights": [ { "type": "directional", "direction": [0, -1, 0], "intensity": 0 } ],
      "camera": { "position": [0, 4, 5], "target": [0, 0, 0] },
      "environment": { "type": "constant", "color": [1, 1, 1], "intensity": )" +
                               std::to_string(intensity) + " } }");
  }
  static void expectFinite(const ImageRGBA32F& img) {
    for (float v : img.pixels) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;
  }
};

float luminance(const glm::vec3& c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

const std::vector<std::string> kOneVpl = {"ism.vpls=1",
                                          "ism.block_size=1",
                                          "ism.pull_push_levels=1",
                                          "ism.ism_resolution=128",
                                          "ism.points_per_ism=32768",
                                          "ism.rsm_resolution=32"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// One VPL: the shadow the box casts in the ISM agrees with the classic map's. IoU of the
// zero-indirect masks (shadow + surfaces facing away, the latter identical in both), on the
// floor alone: measured 0.837 with the default push (holes only), 0.900 with the outlier rule
// at push_threshold 0.05 (0.94 with the earlier rule that replaced any texel behind the coarse
// value: it dilated silhouettes by up to 2^levels - 1 texels and darkened every benchmark
// scene against classic maps, see the push_threshold setting).
TEST_F(IsmTest, OneVplIsmShadowOverlapsTheClassicShadow) {
  const Scene s = panelScene();
  const Result classic = render(s, with(kOneVpl, {"ism.mode=classic"}), 2);
  const Result imperfect = render(s, kOneVpl, 2);
  // The push's outlier rule (a texel behind a coarse value that holds most of its block takes
  // it): off by default (holes only), it tightens this one-VPL shadow.
  const Result outliers = render(s, with(kOneVpl, {"ism.push_threshold=0.05"}), 2);
  expectFinite(classic.indirect);
  expectFinite(imperfect.indirect);
  int litClassic = 0, litIsm = 0;
  const auto a = shadowMask(classic, &litClassic), b = shadowMask(imperfect, &litIsm);
  int shadow = 0;
  for (bool v : a) shadow += v;
  const double overlap = iou(a, b);
  // The floor alone (y = 0): surfaces facing away from the VPL are dark in both modes alike and
  // would lift the IoU; on the floor only the box's shadow is dark.
  std::vector<bool> floorA(a.size(), false), floorB(b.size(), false);
  int floorShadow = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      const size_t i = size_t(y) * kW + x;
      if (classic.sky(x, y) || std::abs(classic.worldAt(x, y).y) > 1e-3f) continue;
      floorA[i] = a[i];
      floorB[i] = b[i];
      floorShadow += a[i];
    }
  const double floorOverlap = iou(floorA, floorB);
  std::printf("classic: %d dark, %d lit; ism lit %d; IoU %.3f; floor only: %d dark, IoU %.3f\n",
              shadow, litClassic, litIsm, overlap, floorShadow, floorOverlap);
  EXPECT_GT(litClassic, int(kW * kH) / 4);  // the VPL lights most of the floor
  EXPECT_GT(shadow, 200);                   // and the box shadows a visible region
  EXPECT_GT(overlap, 0.85);
  EXPECT_GT(floorShadow, 100);
  EXPECT_GT(floorOverlap, 0.8);  // measured 0.837
  const auto c = shadowMask(outliers);
  std::vector<bool> floorC(c.size(), false);
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      const size_t i = size_t(y) * kW + x;
      floorC[i] = !classic.sky(x, y) && std::abs(classic.worldAt(x, y).y) <= 1e-3f && c[i];
    }
  const double outlierOverlap = iou(floorA, floorC);
  std::printf("floor IoU with the outlier rule: %.3f\n", outlierOverlap);
  EXPECT_GT(outlierOverlap, floorOverlap + 0.03);  // measured 0.900
}

// Dynamic: the box slides +1 in x (a looping translation clip, t = 0 -> 1). The surface points
// follow the moved mesh, so the ISM shadow moves with it and still matches the classic shadow
// of the moved box (IoU > 0.85, measured 0.92) much better than it matches its own shadow
// before the move; the shadow's centroid on the floor moves by more than 0.3 (measured 0.48:
// the shadow runs off the image's edge, so its centroid moves less than the box).
TEST_F(IsmTest, IsmShadowFollowsAnAnimatedMesh) {
  const Scene s = panelScene(R"("animation": { "translation": { "times": [0, 2],
      "values": [[0, 0.75, 0], [2, 0.75, 0]] } },)");
  auto centroidX = [&](const Result& r) {
    double sx = 0;
    int n = 0;
    const auto m = shadowMask(r);
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(kW); ++x) {
        const glm::vec3 p = r.worldAt(x, y);
        if (!m[size_t(y) * kW + x] || r.sky(x, y) || p.y > 0.01f) continue;  // floor only
        sx += p.x;
        ++n;
      }
    EXPECT_GT(n, 100);
    return n > 0 ? sx / n : 0.0;
  };
  const Result before = render(s, kOneVpl, 1, true, 0.0);
  const Result after = render(s, kOneVpl, 2, true, 1.0);
  const Result classic = render(s, with(kOneVpl, {"ism.mode=classic"}), 2, true, 1.0);
  const double moved = centroidX(after) - centroidX(before);
  const double overlap = iou(shadowMask(classic), shadowMask(after));
  const double unchanged = iou(shadowMask(before), shadowMask(after));
  std::printf(
      "floor shadow centroid moved %.3f; IoU with the moved classic shadow %.3f, with "
      "the shadow before %.3f\n",
      moved, overlap, unchanged);
  EXPECT_GT(moved, 0.3);
  EXPECT_GT(overlap, 0.85);
  EXPECT_LT(unchanged, overlap - 0.2);
}

// With few points (2048 for a 128^2 map) the ISM has holes through which light leaks. Two
// remedies, measured as IoU against the classic shadow: pull-push with the push's outlier rule
// (no splat enlargement: 0.25 without, 0.62 with two levels at push_threshold 0.05: a texel
// behind a coarse value is replaced only where the near surface holds most of the block, so
// silhouettes do not grow), and splats sized by the area each point stands for in its map's
// subset (radius up to 2 texels, no pull-push: 0.86), the default remedy.
TEST_F(IsmTest, PullPushAndAreaSplatsCloseLightLeaks) {
  const Scene s = panelScene();
  const std::vector<std::string> sparse = {"ism.vpls=1", "ism.block_size=1",
                                           "ism.ism_resolution=128", "ism.points_per_ism=2048",
                                           "ism.rsm_resolution=32"};
  const auto classic = shadowMask(render(s, with(sparse, {"ism.mode=classic"}), 2));
  auto ismIou = [&](const char* splat, const char* levels) {
    return iou(classic, shadowMask(render(s, with(sparse, {splat, levels}))));
  };
  const double without = ismIou("ism.splat_radius=0", "ism.pull_push_levels=0");
  const double pullPush = iou(
      classic, shadowMask(render(s, with(sparse, {"ism.splat_radius=0", "ism.pull_push_levels=2",
                                                  "ism.push_threshold=0.05"}))));
  const double splats = ismIou("ism.splat_radius=2", "ism.pull_push_levels=0");
  std::printf("IoU without either %.3f, pull-push (2 levels) %.3f, area splats %.3f\n", without,
              pullPush, splats);
  EXPECT_GT(pullPush, without + 0.3);
  EXPECT_GT(splats, 0.8);
}

// A spot light pointing into the empty sky: the RSM is black, the CDF empty: zero VPLs, exactly
// zero indirect light, no NaN.
TEST_F(IsmTest, LightFacingAwayGivesZeroIndirectAndNoNaN) {
  const Scene s = jsonScene("away", R"({
      "models": [ { "primitive": "plane", "size": 10, "material": { "base_color": [0.8, 0.8, 0.8] } },
                  { "primitive": "box", "size": [1, 1, 1], "translation": [0, 0.5, 0] } ],
      "lights": [ { "type": "spot", "position": [0, 3, 0], "direction": [0, 1, 0],
                    "intensity": 50, "outer_cone_deg": 20, "casts_shadows": false } ],
      "camera": { "position": [0, 4, 6], "target": [0, 0, 0] } })");
  // With 3 bounces the later bounces' IRSMs are empty too (their CDF's sum is 0: no VPL).
  for (const char* bounces : {"ism.bounces=1", "ism.bounces=3"}) {
    const Result r = render(s, {bounces});
    int geometry = 0;
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(kW); ++x) {
        if (r.sky(x, y)) continue;
        ++geometry;
        ASSERT_EQ(r.px(r.indirect, x, y), glm::vec3(0.0f)) << bounces << " " << x << "," << y;
      }
    expectFinite(r.indirect);
    EXPECT_GT(geometry, int(kW * kH) / 4);
  }
}

// A spot light lights only the top of a raised platform: every VPL faces up, so a floor below
// the platform lies behind all their hemispheres and gets exactly 0; the platform's top (the
// VPLs sit on it: distance ~0 to receivers there) stays finite.
TEST_F(IsmTest, ReceiverBehindTheVplHemispheresGetsZero) {
  const Scene s = jsonScene("behind", R"({
      "models": [ { "primitive": "plane", "size": 40, "material": { "base_color": [0.8, 0.8, 0.8] } },
                  { "primitive": "box", "size": [3, 0.1, 3], "translation": [0, 2, 0],
                    "material": { "base_color": [0.8, 0.8, 0.8] } } ],
      "lights": [ { "type": "spot", "position": [0, 4, 0], "direction": [0, -1, 0],
                    "intensity": 50, "inner_cone_deg": 10, "outer_cone_deg": 15,
                    "casts_shadows": true } ],
      "camera": { "position": [0, 3.5, 7], "target": [0, 0.5, 0] },
      "environment": { "type": "constant", "intensity": 0 } })");
  const Result r = render(s, {"ism.vpls=64"});
  expectFinite(r.indirect);
  int floor = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      if (r.sky(x, y)) continue;
      const glm::vec3 p = r.worldAt(x, y);
      if (p.y > 0.05f) continue;
      ++floor;
      ASSERT_EQ(r.px(r.indirect, x, y), glm::vec3(0.0f)) << x << "," << y;
    }
  EXPECT_GT(floor, int(kW * kH) / 4);
}

// A spot light moved from x = -1.5 to x = +1.5 moves its VPLs on the floor, and with them the
// indirect light on the back wall: its luminance-weighted centroid follows in x.
TEST_F(IsmTest, MovingTheLightMovesTheVpls) {
  auto scene = [&](float x) {
    return jsonScene("move" + std::to_string(int(x * 10)), R"({
      "models": [ { "primitive": "plane", "size": 10, "material": { "base_color": [0.8, 0.8, 0.8] } },
                  { "primitive": "plane", "size": 10, "translation": [0, 5, -2], "rotation": [90, 0, 0],
                    "material": { "base_color": [0.8, 0.8, 0.8] } } ],
      "lights": [ { "type": "spot", "position": [)" + std::to_string(x) +
                                                               R"(, 2, 0], "direction": [0, -1, 0],
                    "intensity": 50, "outer_cone_deg": 25, "casts_shadows": false } ],
      "camera": { "position": [0, 2, 6], "target": [0, 1.5, -2] },
      "environment": { "type": "constant", "intensity": 0 } })");
  };
  auto centroid = [&](const Result& r) {
    double sum = 0, wx = 0;
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(kW); ++x) {
        if (r.sky(x, y)) continue;
        const glm::vec3 p = r.worldAt(x, y);
        if (p.z > -1.95f) continue;  // the wall only
        const glm::vec3 e = r.px(r.indirect, x, y);
        sum += e.x + e.y + e.z;
        wx += (e.x + e.y + e.z) * p.x;
      }
    EXPECT_GT(sum, 0.0);
    return sum > 0 ? wx / sum : 0.0;
  };
  const Scene left = scene(-1.5f), right = scene(1.5f);
  const double a = centroid(render(left, {"ism.vpls=64"})),
               b = centroid(render(right, {"ism.vpls=64"}));
  std::printf("wall centroid x: %.3f -> %.3f\n", a, b);
  EXPECT_LT(a, -0.5);
  EXPECT_GT(b, 0.5);
}

// Multi-bounce: in the (closed) Cornell box each further bounce adds light (VPLs sampled from
// the previous bounce's imperfect reflective shadow maps), less each time: the mean indirect
// radiance increases monotonically with 1, 2, 3 bounces and the increments shrink (measured rgb
// sums 0.463, 0.769, 0.975 at 128 VPLs per bounce: increments 0.306, 0.206; 0.789 and 0.993
// when the candidates were 2048 points shaded with every VPL of the previous bounce).
TEST_F(IsmTest, CornellBoxBouncesIncreaseMonotonicallyAndConverge) {
  const Scene s = loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/cornell_box.json");
  double mean[4] = {0, 0, 0, 0};
  for (int b = 1; b <= 3; ++b) {
    const Result r = render(s, {"ism.vpls=128", "ism.bounces=" + std::to_string(b)});
    expectFinite(r.indirect);
    for (size_t i = 0; i < r.indirect.pixels.size(); i += 4)
      mean[b] += r.indirect.pixels[i] + r.indirect.pixels[i + 1] + r.indirect.pixels[i + 2];
    mean[b] /= double(r.indirect.pixels.size() / 4);
  }
  std::printf("mean indirect (rgb sum): 1 bounce %.4f, 2: %.4f, 3: %.4f\n", mean[1], mean[2],
              mean[3]);
  EXPECT_GT(mean[1], 0.0);
  EXPECT_GT(mean[2], mean[1] * 1.2);
  EXPECT_GT(mean[3], mean[2] * 1.05);
  EXPECT_LT(mean[3] - mean[2], mean[2] - mean[1]);
}

// VPL sampling is unbiased: N VPLs each carry flux / (N p) of the RSM texel they were drawn
// from (ism_vpl.comp), so the Cornell box's mean indirect light does not depend on N: 16, 64,
// 256 VPLs within 8% of 1024's (measured 0.2539, 0.2613, 0.2535 vs 0.2476: +2.6, +5.5, +2.4%;
// block size 1, no blur). A missing 1 / N or 1 / p would be off by factors.
TEST_F(IsmTest, MeanIndirectLightDoesNotDependOnTheVplCount) {
  const Scene s = loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/cornell_box.json");
  std::vector<double> means;
  for (int n : {16, 64, 256, 1024}) {
    const Result r = render(s, {"ism.vpls=" + std::to_string(n), "ism.block_size=1"});
    expectFinite(r.indirect);
    double sum = 0.0;
    int count = 0;
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(kW); ++x)
        if (!r.sky(x, y)) {
          sum += luminance(r.px(r.indirect, x, y));
          ++count;
        }
    means.push_back(sum / std::max(count, 1));
    std::printf("%4d VPLs: mean indirect %.5f\n", n, means.back());
  }
  ASSERT_GT(means.back(), 0.0);
  for (double m : means) EXPECT_NEAR(m, means.back(), 0.08 * means.back());
}

// The RSMs of the other light kinds (a point light's cube is the Cornell box's): a directional
// light (one orthographic map) and a wide spot (outer cone 75 degrees: a paraboloid map) on a
// white floor beside a red wall. The floor's indirect light is finite, present, and red next
// to the wall (its light comes from the wall's VPLs), grey-to-red fading away from it.
TEST_F(IsmTest, DirectionalAndWideSpotLightsProduceVpls) {
  const std::string models = R"(
        { "primitive": "plane", "size": 8, "material": { "base_color": [0.8, 0.8, 0.8] } },
        { "primitive": "box", "size": [0.2, 3, 6], "translation": [-1.1, 1.5, 0],
          "material": { "base_color": [0.9, 0.1, 0.1] } } ],)";
  const std::string camera = R"("camera": { "position": [2.5, 3, 4], "target": [0, 0.5, 0] },
      "environment": { "type": "constant", "intensity": 0 } })";
  for (const std::string& light :
       {std::string(R"({ "type": "directional", "direction": [-1, -1, 0.2], "intensity": 3 })"),
        std::string(R"({ "type": "spot", "position": [1.5, 2.5, 0], "direction": [-1, -0.6, 0],
                        "intensity": 40, "inner_cone_deg": 60, "outer_cone_deg": 75 })")}) {
    const Scene s =
        jsonScene("kinds" + std::to_string(light.size()),
                  R"({ "models": [ )" + models + R"( "lights": [ )" + light + " ], " + camera);
    const Result r = render(s, {"ism.vpls=256", "ism.block_size=1"});
    expectFinite(r.indirect);
    glm::dvec3 nearWall(0.0), far(0.0);
    int nNear = 0, nFar = 0;
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(kW); ++x) {
        if (r.sky(x, y)) continue;
        const glm::vec3 p = r.worldAt(x, y);
        if (std::abs(p.y) > 1e-3f || std::abs(p.z) > 1.5f) continue;  // the floor, mid-wall
        const glm::vec3 e = r.px(r.indirect, x, y);
        if (p.x > -1.0f && p.x < -0.6f) {
          nearWall += glm::dvec3(e);
          ++nNear;
        } else if (p.x > 1.5f && p.x < 2.5f) {
          far += glm::dvec3(e);
          ++nFar;
        }
      }
    ASSERT_GT(nNear, 20) << light;
    ASSERT_GT(nFar, 20) << light;
    nearWall /= nNear;
    far /= nFar;
    std::printf("floor next to the red wall (%.4f %.4f %.4f), far from it (%.4f %.4f %.4f)\n",
                nearWall.r, nearWall.g, nearWall.b, far.r, far.g, far.b);
    EXPECT_GT(nearWall.r, 0.0) << light;
    EXPECT_GT(nearWall.r, 2.0 * nearWall.g) << light << ": red from the wall's VPLs";
    EXPECT_GT(nearWall.r, far.r) << light << ": fading away from the wall";
  }
}

// The VPL singularity guard on the GPU: 1 / max(d^2, d_min^2) with d_min = distance_clamp x
// the scene's diagonal (17.09 here). With d_min = 3.42 (clamp 0.2) the floor under the panel's
// VPL (d ~ 2) gets (d / d_min)^2 of its unclamped light; pixels farther than d_min keep theirs
// exactly; no pixel gets brighter. (The CPU mirror: IsmFormulas.SingularityGuardKeepsTheVplFinite.)
TEST_F(IsmTest, SingularityClampCapsTheLightNearTheVpl) {
  const Scene s = panelScene();
  const Result base = render(s, kOneVpl);
  const Result clamped = render(s, with(kOneVpl, {"ism.distance_clamp=0.2"}));
  const glm::vec3 vpl(-2, 2, 0);  // the panel's centre: the VPL lies on it, within 0.25
  const float dMin = 0.2f * std::sqrt(12.0f * 12.0f * 2.0f + 2.0f * 2.0f);
  int nearPixels = 0, farPixels = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      if (base.sky(x, y)) continue;
      const float e0 = luminance(base.px(base.indirect, x, y)),
                  e1 = luminance(clamped.px(clamped.indirect, x, y));
      ASSERT_TRUE(std::isfinite(e1));
      ASSERT_LE(e1, e0 * 1.001f + 1e-6f) << x << "," << y;
      const float d = glm::length(base.worldAt(x, y) - vpl);
      if (d > dMin + 0.4f) {
        ++farPixels;
        ASSERT_NEAR(e1, e0, 1e-3f * e0 + 1e-6f) << "beyond d_min, pixel " << x << "," << y;
      } else if (d < dMin - 0.4f && e0 > 1e-4f) {
        ++nearPixels;
        const float lo = (d - 0.3f) / dMin, hi = (d + 0.3f) / dMin;
        ASSERT_GE(e1 / e0, lo * lo) << "pixel " << x << "," << y << " at " << d;
        ASSERT_LE(e1 / e0, hi * hi) << "pixel " << x << "," << y << " at " << d;
      }
    }
  std::printf("%d lit pixels within d_min, %d beyond\n", nearPixels, farPixels);
  EXPECT_GT(nearPixels, 50);
  EXPECT_GT(farPixels, 50);
}

// The geometry-aware blur removes the k x k interleaving pattern: with 4 x 4 blocks (each pixel
// gathers 16 of the 256 VPLs) the blurred indirect light of the Cornell box matches the image
// whose every pixel gathers all 256 (block 1) within 10% on average (measured 7.7%: the residue
// where the blur rejects neighbours, near corners), and its pixel-to-pixel
// steps are no larger than that image's beyond 1.5x. With blur_tolerance 0 (the blur rejects
// every neighbour) the pattern stays: the steps must then exceed 3x, or the metric would not
// see it.
TEST_F(IsmTest, BlurRemovesTheInterleavingPattern) {
  const Scene s = loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/cornell_box.json");
  auto lum = [](const Result& r, int x, int y) { return luminance(r.px(r.indirect, x, y)); };
  // Mean |I(p) - I(right neighbour)| over pairs of geometry pixels away from the border, and
  // the mean of I.
  auto steps = [&](const Result& r, double* mean) {
    double sum = 0.0, total = 0.0;
    int n = 0;
    for (int y = 4; y < int(kH) - 4; ++y)
      for (int x = 4; x < int(kW) - 5; ++x) {
        if (r.sky(x, y) || r.sky(x + 1, y)) continue;
        sum += std::abs(lum(r, x, y) - lum(r, x + 1, y));
        total += lum(r, x, y);
        ++n;
      }
    *mean = total / std::max(n, 1);
    return sum / std::max(n, 1);
  };
  const Result all = render(s, {"ism.vpls=256", "ism.block_size=1"});
  const Result blurred = render(s, {"ism.vpls=256", "ism.block_size=4"});
  const Result raw = render(s, {"ism.vpls=256", "ism.block_size=4", "ism.blur_tolerance=0"});
  expectFinite(blurred.indirect);
  double meanAll = 0.0, meanBlurred = 0.0, meanRaw = 0.0;
  const double stepAll = steps(all, &meanAll), stepBlurred = steps(blurred, &meanBlurred),
               stepRaw = steps(raw, &meanRaw);
  double diff = 0.0;
  int n = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x)
      if (!all.sky(x, y)) {
        diff += std::abs(lum(blurred, x, y) - lum(all, x, y));
        ++n;
      }
  diff /= std::max(n, 1) * meanAll;
  std::printf(
      "mean indirect: block 1 %.4f, block 4 blurred %.4f, unblurred %.4f; mean |blurred - "
      "block 1| / mean %.4f; steps: block 1 %.5f, blurred %.5f, unblurred %.5f\n",
      meanAll, meanBlurred, meanRaw, diff, stepAll, stepBlurred, stepRaw);
  ASSERT_GT(meanAll, 0.0);
  EXPECT_LT(diff, 0.10);
  EXPECT_LT(stepBlurred, 1.5 * stepAll);
  EXPECT_GT(stepRaw, 3.0 * stepAll) << "without the blur the pattern must show in the metric";
}

// Imperfect reflective shadow maps (ism_irsm.glsl): the second bounce starts only at points
// the first bounce's VPLs see. The spot light lights only a down-facing panel at x = -2 (every
// first-bounce VPL sits on it) above a grey floor that ends at a wall (x = -1.1..-0.9, 6
// high); a red floor beyond it (x = 1..7) and a white wall at its far end (x = 7, facing it)
// are hidden from the panel. Second-bounce VPLs on the red floor would light the far wall red
// (red / green 8 for light from the red floor alone); with VPLs only where the panel sees, the
// far wall's little bounce-2 light (ISM leaks over the grey side's wall, seen edge-on by the
// floor's VPLs) is grey. Measured red / green 1.000 on the far wall; 1.37 with the IRSMs'
// depth test removed (every point of a VPL's subset shaded).
TEST_F(IsmTest, SecondBounceStartsOnlyWhereTheFirstBouncesVplsSee) {
  const Scene s = panelLitScene("irsm_wall", R"(
        { "primitive": "plane", "size": 8, "translation": [-5, 0, 0],
          "material": { "base_color": [0.8, 0.8, 0.8] } },
        { "primitive": "box", "size": [0.2, 6, 8], "translation": [-1, 3, 0],
          "material": { "base_color": [0.8, 0.8, 0.8] } },
        { "primitive": "plane", "size": 6, "translation": [4, 0, 0],
          "material": { "base_color": [0.8, 0.1, 0.1] } },
        { "primitive": "plane", "size": 6, "translation": [7, 3, 0], "rotation": [0, 0, 90],
          "material": { "base_color": [0.8, 0.8, 0.8] } },)",
                                R"({ "position": [0, 16, 12], "target": [-1, 0, 0] })");
  const std::vector<std::string> sets = {"ism.vpls=32", "ism.points_per_ism=32768",
                                         "ism.ism_resolution=128", "ism.pull_push_levels=2"};
  const Result one = render(s, with(sets, {"ism.bounces=1"}));
  const Result two = render(s, with(sets, {"ism.bounces=2"}));
  expectFinite(two.indirect);
  glm::dvec3 nearAdded(0.0), farAdded(0.0);
  int nearCount = 0, farCount = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      if (one.sky(x, y)) continue;
      const float wx = one.worldAt(x, y).x;
      const glm::dvec3 added = glm::dvec3(two.px(two.indirect, x, y) - one.px(one.indirect, x, y));
      if (wx < -1.2f) {
        nearAdded += added;
        ++nearCount;
      } else if (wx > 6.9f) {
        farAdded += added;
        ++farCount;
      }
    }
  ASSERT_GT(nearCount, 1000);
  ASSERT_GT(farCount, 200);
  const double nearGain = (nearAdded.x + nearAdded.y + nearAdded.z) / nearCount;
  const double farGain = (farAdded.x + farAdded.y + farAdded.z) / farCount;
  const double farRedOverGreen = farAdded.y > 0.0 ? farAdded.x / farAdded.y : 0.0;
  std::printf("bounce 2 adds %.4g on the near side, %.4g on the far wall (red / green %.3f)\n",
              nearGain, farGain, farRedOverGreen);
  EXPECT_GT(nearGain, 0.0);
  EXPECT_GT(farAdded.y, 0.0);  // some leak light to compare hues with
  EXPECT_LT(farRedOverGreen, 1.1);
}

// Classic mode draws its maps from this frame's VPLs (their views written on the GPU, not read
// back on the host): its first frame already has the box's shadow, the same as its second
// frame's and as the ISM's (IoU > 0.85). Before, the first frame had no maps (no shadow) and a
// moving light's maps lagged one frame.
TEST_F(IsmTest, ClassicMapsUseThisFramesVpls) {
  const Scene s = panelScene();
  const Result first = render(s, with(kOneVpl, {"ism.mode=classic"}), 1);
  const Result second = render(s, with(kOneVpl, {"ism.mode=classic"}), 2);
  const Result imperfect = render(s, kOneVpl, 1);
  expectFinite(first.indirect);
  const auto a = shadowMask(first), b = shadowMask(second), c = shadowMask(imperfect);
  int dark = 0;
  for (bool v : a) dark += v;
  std::printf("classic frame 1: %d dark; IoU with frame 2 %.4f, with the ISM %.3f\n", dark,
              iou(a, b), iou(a, c));
  EXPECT_GT(dark, 200);
  EXPECT_EQ(iou(a, b), 1.0);
  EXPECT_GT(iou(a, c), 0.85);
}

// A moving light in classic mode: the frame at t = 1 after one at t = 0 equals a first frame
// at t = 1 (the maps follow this frame's VPLs; with last frame's they were placed at t = 0's
// VPLs, 1.5 away from this frame's, whose distances the maps' then no longer describe), and
// differs from the frame at t = 0 (the light moves 1.5 in x).
TEST_F(IsmTest, ClassicMapsFollowAMovingLightInTheSameFrame) {
  const Scene s = jsonScene("moving_light", R"({
      "models": [ { "primitive": "plane", "size": 10, "material": { "base_color": [0.8, 0.8, 0.8] } },
                  { "primitive": "box", "size": [0.6, 1.2, 0.6], "translation": [0, 0.6, -1] },
                  { "primitive": "plane", "size": 10, "translation": [0, 5, -2], "rotation": [90, 0, 0],
                    "material": { "base_color": [0.8, 0.8, 0.8] } } ],
      "lights": [ { "type": "spot", "position": [-1.5, 2, 0], "direction": [0, -1, 0],
                    "intensity": 50, "outer_cone_deg": 25, "casts_shadows": false,
                    "animation": { "translation": { "times": [0, 2],
                        "values": [[-1.5, 2, 0], [1.5, 2, 0]] } } } ],
      "camera": { "position": [0, 2, 6], "target": [0, 1.5, -2] },
      "environment": { "type": "constant", "intensity": 0 } })");
  auto frames = [&](const std::vector<double>& times) {
    RenderSettings rs = settingsFor(s, {"ism.vpls=64", "ism.mode=classic"}, kW, kH);
    Renderer r(ctx(), s, rs, &registry);
    for (double t : times) {
      r.setTime(t);
      r.renderFrame();
    }
    return r.readTarget("indirect");
  };
  const ImageRGBA32F moved = frames({0.0, 1.0}), fresh = frames({1.0}), before = frames({0.0});
  expectFinite(moved);
  double diff = 0, change = 0, sum = 0;
  for (size_t i = 0; i < moved.pixels.size(); ++i) {
    diff += std::abs(moved.pixels[i] - fresh.pixels[i]);
    change += std::abs(fresh.pixels[i] - before.pixels[i]);
    sum += fresh.pixels[i];
  }
  std::printf("moved vs fresh: %.3g, fresh vs t = 0: %.3g (of %.3g)\n", diff, change, sum);
  EXPECT_GT(sum, 0.0);
  EXPECT_GT(change, 0.02 * sum);  // measured 0.041 x sum
  EXPECT_LE(diff, 1e-6 * sum);    // measured 0: the same VPLs, the same maps
}

// Classic mode with 2 bounces draws maps for the second bounce's VPLs too (their tiles,
// 16..31 of the atlas, hold distances in over a quarter of their texels: before, only the first
// bounce's VPLs got maps and the second bounce's light was unshadowed).
TEST_F(IsmTest, ClassicModeDrawsEveryBouncesMaps) {
  const Scene s = loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/cornell_box.json");
  RenderSettings rs = settingsFor(
      s, {"ism.vpls=16", "ism.bounces=2", "ism.mode=classic", "ism.ism_resolution=32"}, kW, kH);
  rs.view = "ism_atlas";
  Renderer r(ctx(), s, rs, &registry);
  r.renderFrame();
  const ImageRGBA32F atlas = r.readTarget("ism_atlas");
  const int res = 32, perRow = 6;  // ceil(sqrt(32)) tiles per row
  ASSERT_EQ(atlas.width, perRow * res);
  size_t filled[2] = {0, 0};
  for (int i = 0; i < 32; ++i)
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x) {
        const size_t t = size_t((i / perRow) * res + y) * atlas.width + (i % perRow) * res + x;
        filled[i / 16] += atlas.pixels[t * 4] > 0.0f;
      }
  std::printf("filled texels: bounce 1 %zu, bounce 2 %zu of %d each\n", filled[0], filled[1],
              16 * res * res);
  // The disk is pi / 4 of a tile and the box is open to the camera: measured 6475 and 7606.
  EXPECT_GT(filled[0], size_t(16 * res * res / 4));
  EXPECT_GT(filled[1], size_t(16 * res * res / 4));
}

// Glossy receivers: one VPL (a down-facing panel) over a floor, Phong exponent 32. alpha: the
// angle between the VPL light's mirror direction at a floor point and the direction to the
// camera (VPL taken at the panel's centre, within 0.25 of the sampled one). A dielectric floor
// (f0 0.04 over an unchanged diffuse part) is never darker than the diffuse-only image (up to
// the RGB9E5 rounding of the glossy path); its
// largest gain (predicted 1 + 0.04 x 34 / (2 pi) / (0.8 / pi) = 1.85, measured 1.850) lies where
// alpha < 12 degrees and there is none (< 2%) beyond 45 degrees. A metal floor (all glossy, f0 =
// albedo) is brighter than the diffuse floor near the mirror direction and darker (< 0.2x) away
// from it.
TEST_F(IsmTest, GlossyReceiverShowsTheVplHighlightAtTheMirrorDirection) {
  auto scene = [&](const std::string& name, const std::string& floor) {
    return panelLitScene("glossy_" + name,
                         R"({ "primitive": "plane", "size": 12, "material": )" + floor + "},",
                         R"({ "position": [0, 6, 6], "target": [-1, 0, 1] })");
  };
  const Scene dielectric = scene("dielectric", R"({ "base_color": [0.8, 0.8, 0.8] })");
  const Scene metal = scene("metal", R"({ "base_color": [0.8, 0.8, 0.8], "metallic": 1 })");
  const std::vector<std::string> glossy =
      with(kOneVpl, {"ism.glossy=true", "ism.phong_exponent=32"});
  const Result diffuse = render(dielectric, kOneVpl);
  const Result shiny = render(dielectric, glossy);
  const Result metallic = render(metal, glossy);
  expectFinite(shiny.indirect);
  expectFinite(metallic.indirect);
  const glm::vec3 vpl(-2, 2, 0), eye(glm::inverse(diffuse.camera.view)[3]);
  float bestGain = 0, bestAlpha = 180, farGain = 0, metalNear = 0, metalFar = 0;
  int near = 0, far = 0;
  for (int y = 0; y < int(kH); ++y)
    for (int x = 0; x < int(kW); ++x) {
      const float d = luminance(diffuse.px(diffuse.indirect, x, y));
      const glm::vec3 p = diffuse.worldAt(x, y);
      if (diffuse.sky(x, y) || p.y > 0.01f || d < 1e-4f) continue;
      const glm::vec3 r = glm::reflect(glm::normalize(p - vpl), glm::vec3(0, 1, 0));
      const float alpha =
          glm::degrees(std::acos(std::clamp(glm::dot(r, glm::normalize(eye - p)), -1.0f, 1.0f)));
      const float gain = luminance(shiny.px(shiny.indirect, x, y)) / d;
      const float metalGain = luminance(metallic.px(metallic.indirect, x, y)) / d;
      ASSERT_GE(gain, 0.995f) << x << "," << y;  // RGB9E5 rounds twice: 2 x 2^-9 relative
      if (gain > bestGain) {
        bestGain = gain;
        bestAlpha = alpha;
      }
      if (alpha < 8) {
        ++near;
        metalNear = std::max(metalNear, metalGain);
      }
      if (alpha > 45) {
        ++far;
        farGain = std::max(farGain, gain);
        metalFar = std::max(metalFar, metalGain);
      }
    }
  std::printf(
      "dielectric: largest gain %.3f at alpha %.1f deg, largest beyond 45 deg %.4f; metal vs "
      "diffuse: %.3f near (%d px), %.4f far (%d px)\n",
      bestGain, bestAlpha, farGain, metalNear, near, metalFar, far);
  ASSERT_GT(near, 10);
  ASSERT_GT(far, 100);
  EXPECT_NEAR(bestGain, 1.85f, 0.05f);  // measured 1.850 at alpha 0.6 degrees
  EXPECT_LT(bestAlpha, 12.0f);
  EXPECT_LT(farGain, 1.02f);
  EXPECT_GT(metalNear, 1.0f);
  EXPECT_LT(metalFar, 0.2f);
}

// The frame graph runs ISM passes only when the scene asks for the effect.
// The atlas debug view (distances, 0 = hole) is built only when it is the view, in both modes.
TEST_F(IsmTest, AtlasViewRunsOnlyWhenViewed) {
  const Scene s = panelScene();
  auto has = [](const std::vector<std::string>& v, const char* p) {
    return std::find(v.begin(), v.end(), p) != v.end();
  };
  EXPECT_FALSE(has(render(s, {"ism.vpls=16"}).passes, "ism_atlas_view"));
  for (const char* mode : {"ism", "classic"}) {
    RenderSettings rs = settingsFor(s, {"ism.vpls=16", std::string("ism.mode=") + mode}, kW, kH);
    rs.view = "ism_atlas";
    Renderer r(ctx(), s, rs, &registry);
    r.renderFrame();  // one frame: classic mode places its maps from this frame's VPLs
    EXPECT_TRUE(has(r.passNames(), "ism_atlas_view")) << mode;
    const ImageRGBA32F atlas = r.readTarget("ism_atlas");
    size_t filled = 0;
    for (size_t i = 0; i < atlas.pixels.size(); i += 4) {
      ASSERT_TRUE(std::isfinite(atlas.pixels[i]) && atlas.pixels[i] >= 0.0f) << mode;
      filled += atlas.pixels[i] > 0.0f;
    }
    EXPECT_GT(filled, atlas.pixels.size() / 4 / 20) << mode << ": the 16 maps hold distances";
  }
}

// The single-pass, tile-local pull-push (ism_pull_push.comp) against the CPU rules
// (ism::pullDepth / pushDepth) applied level by level to the splatted atlas it starts from:
// sparse maps (256 points in 64^2 texels), 1, 3 and 6 levels, thresholds 0 (only the nearest
// child is pulled, any texel behind the coarse value is replaced) and 1 (every distance lies
// within the scene's extent: all valid children are averaged, only holes are filled). Equal
// within 1e-5 relative on at least 99.9% of the texels (a float rounding difference in a mean
// can flip a threshold-0 comparison).
TEST_F(IsmTest, PullPushMatchesTheCpuRules) {
  const Scene s = panelScene();
  auto atlas = [&](int levels, const char* threshold) {
    RenderSettings rs =
        settingsFor(s,
                    {"ism.vpls=16", "ism.ism_resolution=64", "ism.points_per_ism=256",
                     "ism.pull_push_levels=" + std::to_string(levels),
                     std::string("ism.pull_threshold=") + threshold,
                     std::string("ism.push_threshold=") + threshold},
                    kW, kH);
    rs.view = "ism_atlas";
    Renderer r(ctx(), s, rs, &registry);
    r.renderFrame();
    return r.readTarget("ism_atlas");
  };
  constexpr int kRes = 64;
  const float inf = std::numeric_limits<float>::infinity();
  for (const char* threshold : {"0", "1"}) {
    const float t = std::string(threshold) == "0" ? 0.0f : 1e30f;
    const ImageRGBA32F splatted = atlas(0, threshold);
    ASSERT_EQ(splatted.width, 4u * kRes);
    size_t holes = 0;
    for (size_t i = 0; i < splatted.pixels.size(); i += 4) holes += splatted.pixels[i] == 0.0f;
    ASSERT_GT(holes, splatted.pixels.size() / 4 / 4) << "sparse maps have holes to fill";
    for (int levels : {1, 3, 6}) {
      const ImageRGBA32F gpu = atlas(levels, threshold);
      ASSERT_EQ(gpu.width, splatted.width);
      size_t bad = 0, total = 0;
      for (int tile = 0; tile < 16; ++tile) {
        const int ox = (tile % 4) * kRes, oy = (tile / 4) * kRes;
        std::vector<std::vector<ism::PullPushTexel>> lv(size_t(levels) + 1);
        lv[0].resize(kRes * kRes);
        for (int y = 0; y < kRes; ++y)
          for (int x = 0; x < kRes; ++x) {
            const float d = splatted.pixels[(size_t(oy + y) * splatted.width + ox + x) * 4];
            lv[0][size_t(y) * kRes + x].depth = d > 0.0f ? d : inf;
          }
        for (int l = 0; l < levels; ++l) {
          const int n = kRes >> (l + 1);
          lv[l + 1].resize(size_t(n) * n);
          for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
              const auto& f = lv[l];
              const size_t a = size_t(2 * y) * 2 * n + 2 * x, b = a + 2 * size_t(n);
              const float c[4] = {f[a].depth, f[a + 1].depth, f[b].depth, f[b + 1].depth};
              lv[l + 1][size_t(y) * n + x] = ism::pullDepth(c, t * float(1 << l));
            }
        }
        for (int l = levels - 1; l >= 0; --l) {
          const int n = kRes >> l;
          for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
              ism::PullPushTexel& f = lv[l][size_t(y) * n + x];
              f = ism::pushDepth(f, lv[l + 1][size_t(y / 2) * (n / 2) + x / 2], t * float(1 << l));
            }
        }
        for (int y = 0; y < kRes; ++y)
          for (int x = 0; x < kRes; ++x) {
            const float want = lv[0][size_t(y) * kRes + x].depth;
            const float got = gpu.pixels[(size_t(oy + y) * gpu.width + ox + x) * 4];
            const bool same =
                std::isfinite(want) ? std::abs(got - want) <= 1e-5f * want : got == 0.0f;
            bad += !same;
            ++total;
          }
      }
      EXPECT_LE(bad, total / 1000) << levels << " levels, threshold " << threshold;
      if (std::string(threshold) == "1") {
        EXPECT_EQ(bad, 0u) << levels << " levels";
      }
    }
  }
}

TEST_F(IsmTest, NoIsmPassWithoutTheEffect) {
  const Scene s = panelScene();
  for (const std::string& p : render(s, {}, 1, false).passes)
    EXPECT_EQ(p.rfind("ism_", 0), std::string::npos) << p;
  const auto passes = render(s, {"ism.vpls=16"}).passes;
  for (const char* p :
       {"ism_rsm", "ism_vpl", "ism_clear", "ism_splat", "ism_pull_push", "ism_gather", "ism_blur"})
    EXPECT_NE(std::find(passes.begin(), passes.end(), p), passes.end()) << p;
  const auto three = render(s, {"ism.vpls=16", "ism.bounces=3"}).passes;
  for (const char* p :
       {"ism_irsm2", "ism_bounce2", "ism_splat2", "ism_irsm3", "ism_bounce3", "ism_splat3"})
    EXPECT_NE(std::find(three.begin(), three.end(), p), three.end()) << p;
  EXPECT_EQ(std::find(passes.begin(), passes.end(), "ism_irsm2"), passes.end());
  const auto classic = render(s, {"ism.vpls=16", "ism.mode=classic"}).passes;
  EXPECT_NE(std::find(classic.begin(), classic.end(), "ism_classic_sm"), classic.end());
  EXPECT_EQ(std::find(classic.begin(), classic.end(), "ism_splat"), classic.end());
}

// An open floor under a constant environment: with environment VPLs its light comes through
// "indirect" alone (the lit image equals it: the engine's unshadowed term was replaced, not
// added to) and matches the engine's term, which is exact here (nothing occludes the sky),
// within 3%. Measured: equal to half-float precision -- the Hammersley points' first
// coordinate stratifies cos(theta) evenly over a constant map, and the midpoint rule
// integrates the cosine exactly; a self-shadowing floor (normal offset 0.5 texel) is 6% darker.
TEST_F(IsmTest, EnvironmentVplsLightAnOpenFloorLikeTheEnvironment) {
  const Scene s = environmentScene("env_open", false);
  const Result engine = render(s, {});
  const Result env = render(s, {"ism.environment_vpls=256"});
  int checked = 0;
  float worst = 0.0f;
  for (int y = kH / 2; y < int(kH) - 10; y += 5)
    for (int x = 30; x < int(kW) - 30; x += 5) {
      ASSERT_FALSE(env.sky(x, y));
      const float e = luminance(engine.px(engine.lit, x, y));
      const float l = luminance(env.px(env.lit, x, y));
      EXPECT_NEAR(l, e, 0.03f * e) << x << "," << y;
      worst = std::max(worst, std::abs(l - e) / e);
      EXPECT_NEAR(luminance(env.px(env.indirect, x, y)), l, 0.01f * l) << x << "," << y;
      ++checked;
    }
  std::printf("open floor: environment VPLs within %.2f%% of the engine's term\n", 100 * worst);
  EXPECT_GT(checked, 50);
  expectFinite(env.indirect);
  expectFinite(env.lit);
}

// A unit box on the floor shadows the sky from the floor beside it: 0.1 from its face the
// floor gets at least 10% less light than 2.5 away, where the engine's unshadowed term gives
// both the same within 2%. Measured (64^2 maps): 0.46 and 0.41 of the open floor's light on
// the two sides, the ray-traced reference 0.59 and 0.57 (darker: pull-push dilates the box by
// a texel, 0.22 m here).
TEST_F(IsmTest, EnvironmentVplsShadowTheFloorBesideABox) {
  const Scene s = environmentScene("env_box", true);
  for (const char* glossy : {"ism.glossy=false", "ism.glossy=true"}) {
    const Result engine = render(s, {glossy});
    const Result env = render(s, {"ism.environment_vpls=256", glossy});
    for (float side : {-1.0f, 1.0f}) {
      const glm::ivec2 near = env.pixelOf({side * 0.6f, 0.0f, 0.2f});
      const glm::ivec2 far = env.pixelOf({side * 3.0f, 0.0f, 0.2f});
      ASSERT_FALSE(env.sky(near.x, near.y));
      ASSERT_FALSE(env.sky(far.x, far.y));
      const float envNear = luminance(env.px(env.lit, near.x, near.y));
      const float envFar = luminance(env.px(env.lit, far.x, far.y));
      const float engNear = luminance(engine.px(engine.lit, near.x, near.y));
      const float engFar = luminance(engine.px(engine.lit, far.x, far.y));
      std::printf(
          "%s side %+.0f (px %d,%d / %d,%d): beside / open floor %.3f (engine's term %.3f)\n",
          glossy, side, near.x, near.y, far.x, far.y, envNear / envFar, engNear / engFar);
      EXPECT_LT(envNear, 0.9f * envFar) << glossy << " side " << side;
      EXPECT_NEAR(engNear, engFar, 0.02f * engFar) << glossy << " side " << side;
    }
    expectFinite(env.indirect);
  }
}

// The environment's shadow follows an animated box (the orthographic ISMs are splatted from
// the surface points, which follow the deformed geometry): a looping clip slides it from
// x = -2 (t = 0) to x = 1 (t = 1.5); the floor beside its start is darker at t = 0 than at
// t = 1.5, and the floor beside its end the other way round (measured 0.42 vs 0.80, 0.40 vs
// 0.79).
TEST_F(IsmTest, EnvironmentVplShadowFollowsAnAnimatedBox) {
  const Scene s = environmentScene("env_moving", true, 1.0f,
                                   R"("animation": { "translation": { "times": [0, 2],
                                        "values": [[-2, 0.5, 0], [2, 0.5, 0]] } },)");
  const Result start = render(s, {"ism.environment_vpls=256"}, 2, true, 0.0);
  const Result end = render(s, {"ism.environment_vpls=256"}, 2, true, 1.5);
  const glm::ivec2 left = start.pixelOf({-2.6f, 0.0f, 0.2f});
  const glm::ivec2 right = start.pixelOf({1.6f, 0.0f, 0.2f});
  const auto at = [](const Result& r, glm::ivec2 p) { return luminance(r.px(r.lit, p.x, p.y)); };
  std::printf("beside the start: %.3f (t 0) vs %.3f (t 1.5); beside the end: %.3f vs %.3f\n",
              at(start, left), at(end, left), at(start, right), at(end, right));
  EXPECT_LT(at(start, left), 0.9f * at(end, left));
  EXPECT_LT(at(end, right), 0.9f * at(start, right));
  expectFinite(start.indirect);
  expectFinite(end.indirect);
}

// Environment VPLs composed with an AO effect split visibility by distance: occluders within
// the AO's radius R (EffectContext::publishedRange) are the AO's, the orthographic maps count
// only those beyond R, and the VPLs' light is multiplied by the AO, so nothing is counted
// twice. The two limits are closed-form. R beyond every occluder (20, the box is within 1.8 of
// the floor beside it for elevations above 3 degrees): the maps see nothing, so the light is
// the unshadowed environment's (the engine's term, within 3%: the open-floor test above) x the
// same AO as the AO effect alone. R below every occluder (0.01): the AO is 1 and the maps'
// shadow is ISM's alone.
TEST_F(IsmTest, EnvironmentVplsLeaveTheNearFieldToAnAOEffect) {
  const Scene s = environmentScene("env_box_ao", true);
  auto render = [&](const std::vector<std::string>& effects, const std::vector<std::string>& sets) {
    return renderEffects(s, effects, sets);
  };
  const std::string env = "ism.environment_vpls=256";
  const Result aoWide = render({"gtao"}, {"gtao.radius=20"});
  const Result bothWide = render({"gtao", "ism"}, {"gtao.radius=20", env});
  const Result ismAlone = render({"ism"}, {env});
  const Result bothNarrow = render({"gtao", "ism"}, {"gtao.radius=0.01", env});
  // Both effects ran, the AO first (ISM reads it).
  const auto at = [&](const std::string& pass) {
    return std::find(bothWide.passes.begin(), bothWide.passes.end(), pass) -
           bothWide.passes.begin();
  };
  ASSERT_LT(at("gtao"), at("ism_gather"));
  ASSERT_LT(at("ism_gather"), std::ptrdiff_t(bothWide.passes.size()));
  for (float side : {-1.0f, 1.0f})
    for (float x : {0.6f, 1.0f, 3.0f}) {  // beside the box to the open floor
      const glm::ivec2 p = aoWide.pixelOf({side * x, 0.0f, 0.2f});
      ASSERT_FALSE(aoWide.sky(p.x, p.y));
      const float wideAo = luminance(aoWide.px(aoWide.lit, p.x, p.y));
      const float wideBoth = luminance(bothWide.px(bothWide.lit, p.x, p.y));
      const float ism = luminance(ismAlone.px(ismAlone.lit, p.x, p.y));
      const float narrowBoth = luminance(bothNarrow.px(bothNarrow.lit, p.x, p.y));
      std::printf(
          "x %+.1f: R 20: AO alone %.4f, with ISM %.4f; R 0.01: ISM alone %.4f, with AO %.4f\n",
          side * x, wideAo, wideBoth, ism, narrowBoth);
      EXPECT_NEAR(wideBoth, wideAo, 0.04f * wideAo) << side * x;
      EXPECT_NEAR(narrowBoth, ism, 0.04f * ism) << side * x;
      // Beside the box the maps' shadow is deep (measured 0.46 of the open floor), so counting
      // the box in both the maps and the AO would fail the first check by far.
      if (x < 1.0f) {
        EXPECT_LT(ism, 0.7f * wideAo) << side * x;
      }
    }
}

// SSDO's near-field bounce with ISM's far field, split by distance: the gathering skips the
// first bounce's VPLs within SSDO's radius R of the receiver (EffectContext::publishedRange)
// and adds the rest to SSDO's "indirect". One VPL on the panel at (-2, 2, 0), no interleaving,
// no blur, so per pixel: indirect(both) = indirect(SSDO) + indirect(ISM) where the VPL is
// farther than R, = indirect(SSDO) where it is nearer (the panel is 0.5 wide: pixels within
// 0.4 of R either way are not judged).
TEST_F(IsmTest, SsdoNearFieldAndIsmFarFieldSplitTheBounceByDistance) {
  const Scene s = panelScene();
  auto render = [&](const std::vector<std::string>& effects, std::vector<std::string> sets) {
    const auto on = [&](const char* e) {
      return std::find(effects.begin(), effects.end(), e) != effects.end();
    };
    if (on("ism")) sets.insert(sets.end(), kOneVpl.begin(), kOneVpl.end());
    if (on("ssdo")) sets.push_back("ssdo.bounce=true");
    return renderEffects(s, effects, sets);
  };
  const float radius = 2.5f;
  const std::string r = "ssdo.radius=" + std::to_string(radius);
  const Result ssdo = render({"ssdo"}, {r});
  const Result ism = render({"ism"}, {});
  const Result both = render({"ssdo", "ism"}, {r});
  ASSERT_NE(std::find(both.passes.begin(), both.passes.end(), "ism_gather"), both.passes.end());
  const glm::vec3 panel(-2.0f, 2.0f, 0.0f);
  int nearChecked = 0, farChecked = 0;
  double farIsm = 0.0, nearIsm = 0.0;
  for (int y = 0; y < int(kH); y += 2)
    for (int x = 0; x < int(kW); x += 2) {
      if (ssdo.sky(x, y)) continue;
      const float d = glm::length(ssdo.worldAt(x, y) - panel);
      const float a = luminance(ssdo.px(ssdo.indirect, x, y));
      const float i = luminance(ism.px(ism.indirect, x, y));
      const float sum = luminance(both.px(both.indirect, x, y));
      if (d < radius - 0.4f) {
        EXPECT_NEAR(sum, a, 1e-3f + 0.01f * a) << x << "," << y << " d " << d;
        nearIsm += i;
        ++nearChecked;
      } else if (d > radius + 0.4f) {
        EXPECT_NEAR(sum, a + i, 1e-3f + 0.01f * (a + i)) << x << "," << y << " d " << d;
        farIsm += i;
        ++farChecked;
      }
    }
  std::printf(
      "near pixels %d (SSDO's alone; ISM's there %.3f), far pixels %d (SSDO's + ISM's, "
      "ISM's %.3f)\n",
      nearChecked, nearIsm, farChecked, farIsm);
  EXPECT_GT(nearChecked, 100);
  EXPECT_GT(farChecked, 100);
  // ISM alone lights both sides: both checks above can fail.
  EXPECT_GT(farIsm, 1.0);
  EXPECT_GT(nearIsm, 1.0);
  expectFinite(both.indirect);
}

// A black environment gives environment VPLs nothing to carry (the sampler's black-map tables:
// radiance 0): indirect light exactly 0 everywhere, no NaN, also with glossy receivers.
TEST_F(IsmTest, EnvironmentVplsUnderABlackEnvironmentAddNothing) {
  const Scene s = environmentScene("env_black", true, 0.0f);
  for (const char* glossy : {"ism.glossy=false", "ism.glossy=true"}) {
    const Result r = render(s, {"ism.environment_vpls=64", glossy});
    for (size_t i = 0; i < r.indirect.pixels.size(); i += 4)
      ASSERT_EQ(glm::vec3(r.indirect.pixels[i], r.indirect.pixels[i + 1], r.indirect.pixels[i + 2]),
                glm::vec3(0.0f))
          << glossy;
    expectFinite(r.lit);
  }
}

// The environment VPLs' passes run only when asked for; classic mode draws their orthographic
// maps from the triangles instead of splatting points (after two bounces' paraboloid maps).
TEST_F(IsmTest, EnvironmentVplPassesOnlyWhenAskedFor) {
  const Scene s = environmentScene("env_passes", true);
  const auto has = [](const std::vector<std::string>& passes, const char* p) {
    return std::find(passes.begin(), passes.end(), p) != passes.end();
  };
  // The scene's only light is off: without environment VPLs there is nothing to do, no ISM
  // pass runs and the renderer says so, naming the effect.
  const Result nothing = render(s, {"ism.vpls=16"});
  const auto off = nothing.passes;
  for (const std::string& p : off) EXPECT_NE(p.rfind("ism", 0), 0u) << p;
  ASSERT_EQ(nothing.warnings.size(), 1u);
  EXPECT_NE(nothing.warnings[0].find("effect 'ism' adds no pass"), std::string::npos)
      << nothing.warnings[0];
  const auto on = render(s, {"ism.vpls=16", "ism.environment_vpls=16"}).passes;
  // Different counts (each classic pass pair draws from its own views buffer; validation
  // caught the point VPLs' draw reading the environment VPLs' smaller one).
  const auto classic =
      render(s, {"ism.vpls=32", "ism.environment_vpls=16", "ism.bounces=2", "ism.mode=classic"});
  for (const char* p : {"ism_env_vpl", "ism_env_splat", "ism_env_pull_push", "ism_env_ambient",
                        "ism_env_classic_views", "ism_env_classic_sm"}) {
    EXPECT_FALSE(has(off, p)) << p;
    EXPECT_FALSE(has(render(s, {"ism.vpls=16", "ism.mode=classic"}).passes, p)) << p;
  }
  for (const char* p : {"ism_env_vpl", "ism_env_splat", "ism_env_pull_push", "ism_env_ambient"})
    EXPECT_TRUE(has(on, p)) << p;
  for (const char* p :
       {"ism_env_vpl", "ism_env_classic_views", "ism_env_classic_sm", "ism_env_ambient"})
    EXPECT_TRUE(has(classic.passes, p)) << p;
  EXPECT_FALSE(has(classic.passes, "ism_env_splat"));
  expectFinite(classic.indirect);
}

}  // namespace
}  // namespace gi
