// The SSAO plugin against analytic cases: a lone plane is unoccluded, a 90-degree corner
// matches the same estimator evaluated on the CPU (its discrete kernel, and its continuous form
// integrated numerically), the result is scale invariant and never NaN, and the blur removes
// the 4x4 interleave pattern without bleeding across depth edges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "../effects/ssao/ssao_kernel.h"
#include "effect_fixture.h"
#include "gi/renderer.h"
#include "process.h"
#include "quad_scene.h"

namespace gi {
namespace {

constexpr uint32_t kW = 160, kH = 120;

using test::cornerLinePixels;
using test::cornerQuads;
using test::cornerScene;
using test::finite;
using test::patternEnergy;
using test::Quads;
using test::quadScene;

using Result = test::AoFrame;

class SsaoTest : public test::EffectTest {
 protected:
  std::string effectName() const override { return "ssao"; }
  Result render(const Scene& scene, const std::vector<std::string>& sets, uint32_t w = kW,
                uint32_t h = kH) {
    Renderer r(ctx(), scene, settingsFor(scene, sets, w, h), &registry);
    r.renderFrame();
    return {r.readTarget("ao"), r.readTarget("depth"), r.camera(), int(w), int(h)};
  }
};

// ---- the estimator on the CPU ---------------------------------------------------------------

// The SSAO estimator of ssao_kernel.h evaluated against the exact scene (quads) instead of a
// depth buffer: a tap is occluded when the first surface on the camera ray through it lies in
// front of it by more than the bias and less than R (view-axis distances), as in the shader.
struct CpuSsao {
  Quads quads;
  CameraView camera;
  float radius, bias;  // bias absolute (setting x radius)

  // Ray parameter of the first quad hit by eye + t dir (t > 0), or infinity.
  float firstHit(glm::vec3 eye, glm::vec3 dir) const {
    float best = std::numeric_limits<float>::infinity();
    for (const auto& [m, half] : quads) {
      const glm::mat4 inv = glm::inverse(m);
      const glm::vec3 o = glm::vec3(inv * glm::vec4(eye, 1)),
                      d = glm::vec3(inv * glm::vec4(dir, 0));
      if (std::abs(d.z) < 1e-12f) continue;
      const float t = -o.z / d.z;
      const glm::vec3 h = o + t * d;
      if (t > 0 && t < best && std::abs(h.x) <= half && std::abs(h.y) <= half) best = t;
    }
    return best;
  }
  bool occluded(glm::vec3 qView) const {
    const glm::vec4 clip = camera.proj * glm::vec4(qView, 1);
    if (clip.w <= 0 || std::abs(clip.x) > clip.w || std::abs(clip.y) > clip.w) return false;
    const glm::mat4 invView = glm::inverse(camera.view);
    const glm::vec3 eye = glm::vec3(invView[3]), q = glm::vec3(invView * glm::vec4(qView, 1));
    const float t = firstHit(eye, q - eye);             // the tap itself is at t = 1
    const float zq = -qView.z, diff = (1.0f - t) * zq;  // zq - zS: view depth scales with t
    return std::isfinite(t) && diff > bias && diff < radius;
  }
  // Tap position in view space, with the shader's tangent frame and interleave rotation.
  glm::vec3 tap(glm::vec3 p, glm::vec3 n, float angle, ssao::Tap k) const {
    const float s = n.z >= 0 ? 1.0f : -1.0f, a = -1.0f / (s + n.z), b = n.x * n.y * a;
    const glm::vec3 t(1 + s * n.x * n.x * a, s * b, -s * n.x), bt(b, s + n.y * n.y * a, -n.y);
    const glm::vec3 tr = std::cos(angle) * t + std::sin(angle) * bt;
    const glm::vec3 br = std::cos(angle) * bt - std::sin(angle) * t;
    return p + radius * (tr * k.x + br * k.y + n * k.z);
  }
  // Discrete: the plugin's own n-tap kernel and pixel (x, y)'s rotation.
  float aoDiscrete(glm::vec3 p, glm::vec3 n, int x, int y, int samples, bool interleave) const {
    const double angle = ssao::rotationAngle(x, y, samples, interleave);
    int occ = 0;
    for (int i = 0; i < samples; ++i)
      occ += occluded(tap(p, n, float(angle), ssao::kernelTap(i, samples)));
    return 1.0f - float(occ) / samples;
  }
  // Continuous form: midpoint rule over the uniform cube mapped by ssao::tapFromUniform.
  float aoContinuous(glm::vec3 p, glm::vec3 n, int m = 48) const {
    int occ = 0;
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        for (int k = 0; k < m; ++k)
          occ += occluded(
              tap(p, n, 0.0f, ssao::tapFromUniform((i + 0.5) / m, (j + 0.5) / m, (k + 0.5) / m)));
    return 1.0f - float(occ) / float(m * m * m);
  }
};

// Closed form for an infinite wall at distance d from the shaded point of the floor, without
// bias or range check: for cosine-distributed w the component towards the wall, t, has density
// (2/pi) sqrt(1 - t^2); a tap s R w is inside the wall when s R t > d. Occluded fraction =
// Int_a^1 (2/pi) sqrt(1-t^2) (1 - a/t) dt with a = d / R.
double cornerOcclusion(double a) {
  const int n = 20000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = a + (1.0 - a) * (i + 0.5) / n;
    sum += (2.0 / M_PI) * std::sqrt(1.0 - t * t) * (1.0 - a / t);
  }
  return sum * (1.0 - a) / n;
}

// ---- tests ----------------------------------------------------------------------------------

TEST_F(SsaoTest, LonePlaneIsUnoccluded) {
  Scene s = quadScene({{glm::mat4(1.0f), 1.0f}}, glm::vec3(0, 0, 5), glm::vec3(0));
  for (const char* blur : {"ssao.blur_radius=0", "ssao.blur_radius=2"}) {
    Result r = render(s, {"ssao.radius=0.5", blur});
    ASSERT_TRUE(finite(r.ao));
    int sky = 0;
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x) {
        ASSERT_NEAR(r.at(x, y), 1.0f, 0.02f) << blur << " pixel " << x << "," << y;
        if (r.depthAt(x, y) <= 0.0f) {
          ++sky;
          ASSERT_EQ(r.at(x, y), 1.0f) << "sky pixel " << x << "," << y;  // guard: no work
        }
      }
    EXPECT_GT(sky, 1000);
  }
}

TEST_F(SsaoTest, CornerMatchesTheDiscreteEstimator) {
  // The plugin's own kernel and rotations evaluated on the CPU against the exact scene, pixel by
  // pixel (no blur, interleave on). Differences come from the depth buffer's texel grid: the
  // shader slides each tap onto its texel centre's ray, so a tap near the wall's image edge can
  // flip (1/16 each; measured mean 0.004-0.008, and exactly 0 with the slide disabled).
  const float R = 0.5f, d = 0.25f * R;
  const int n = 16;
  Result r = render(cornerScene(),
                    {"ssao.radius=0.5", "ssao.samples=16", "ssao.blur_radius=0",
                     "ssao.interleave=true", "ssao.bias=0.025"},
                    320, 240);
  const CpuSsao cpu{cornerQuads(), r.camera, R, 0.025f * R};
  const glm::vec3 nView = glm::mat3(r.camera.view) * glm::vec3(0, 1, 0);
  const std::vector<glm::ivec2> pixels = cornerLinePixels(r, d);
  ASSERT_GE(pixels.size(), 100u);
  double sumAbs = 0.0, worst = 0.0;
  for (glm::ivec2 p : pixels) {
    const double e =
        std::abs(r.at(p.x, p.y) - cpu.aoDiscrete(r.viewAt(p.x, p.y), nView, p.x, p.y, n, true));
    sumAbs += e;
    worst = std::max(worst, e);
  }
  std::printf("discrete estimator: mean |diff| %.4f, worst %.4f over %zu pixels\n",
              sumAbs / pixels.size(), worst, pixels.size());
  EXPECT_LT(sumAbs / pixels.size(), 0.02) << "mean |AO - CPU estimator|";
  EXPECT_LE(worst, 2.0 / n + 1e-3) << "at most two taps may flip";
}

TEST_F(SsaoTest, CornerMatchesTheContinuousEstimator) {
  // 64 interleaved taps, blurred (the default radius 2): 16 rotations x 64 taps average the
  // estimator over 1024 azimuth-stratified taps; the continuous form is integrated on the CPU at
  // each pixel (48^3 midpoint rule). Tolerance 0.02 (the measured gap is ~0.001).
  const float R = 0.5f, d = 0.25f * R;
  Result r = render(cornerScene(),
                    {"ssao.radius=0.5", "ssao.samples=64", "ssao.blur_radius=2",
                     "ssao.interleave=true", "ssao.bias=0.025"},
                    320, 240);
  ASSERT_TRUE(finite(r.ao));
  const CpuSsao cpu{cornerQuads(), r.camera, R, 0.025f * R};
  const glm::vec3 nView = glm::mat3(r.camera.view) * glm::vec3(0, 1, 0);
  const std::vector<glm::ivec2> pixels = cornerLinePixels(r, d);
  ASSERT_GE(pixels.size(), 100u);
  double rendered = 0.0, expected = 0.0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const glm::ivec2 p = pixels[i];
    rendered += r.at(p.x, p.y);
    if (i % 8 == 0) expected += 8 * cpu.aoContinuous(r.viewAt(p.x, p.y), nView);  // subsampled
  }
  rendered /= pixels.size();
  expected /= 8 * ((pixels.size() + 7) / 8);
  std::printf("continuous estimator: rendered %.4f, expected %.4f over %zu pixels\n", rendered,
              expected, pixels.size());
  EXPECT_NEAR(rendered, expected, 0.02) << "over " << pixels.size() << " pixels";
  EXPECT_LT(rendered, 0.9) << "the corner must be visibly occluded";

  // The integrator itself against the closed form (no bias; this view's range check never
  // triggers for taps behind the wall), at the exact point x = d on the floor.
  const CpuSsao noBias{cornerQuads(), r.camera, R, 0.0f};
  const glm::vec3 onLine = glm::vec3(r.camera.view * glm::vec4(d, 0, 0, 1));
  const double closed = 1.0 - cornerOcclusion(d / R),
               integrated = noBias.aoContinuous(onLine, nView, 64);
  std::printf("closed form %.4f, integrated %.4f\n", closed, integrated);
  EXPECT_NEAR(integrated, closed, 0.01);
}

TEST_F(SsaoTest, ScaleInvariant) {
  Result a = render(cornerScene(1.0f), {"ssao.radius=0.5", "ssao.samples=16"});
  for (float scale : {1e-3f, 1e3f}) {
    Result b = render(cornerScene(scale),
                      {"ssao.radius=" + std::to_string(0.5f * scale), "ssao.samples=16"});
    double diff = 0.0;
    size_t over = 0, n = a.ao.pixels.size() / 4;
    for (size_t i = 0; i < n; ++i) {
      const double e = std::abs(a.ao.pixels[i * 4] - b.ao.pixels[i * 4]);
      diff += e;
      over += e > 0.05;
    }
    std::printf("scale x%g: mean |diff| %.5f, %zu of %zu pixels differ by > 0.05\n", scale,
                diff / n, over, n);
    EXPECT_LT(diff / n, 0.005) << "mean |AO(x1) - AO(x" << scale << ")|";
    EXPECT_LT(double(over) / n, 0.01) << "pixels differing by more than 0.05, x" << scale;
  }
}

TEST_F(SsaoTest, FlatFacesStayOpenWhenTheRadiusIsTinyForTheViewDistance) {
  // A plane seen at 20 degrees of elevation from 5 units, with radii from a fraction of a pixel's
  // footprint down to 1e-6 (a model 1e6 wide at radius 0.5 is this case): no tap may find the
  // plane itself in front of it (no false occlusion, no banding along the depth quantisation).
  const glm::mat4 floor = glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), glm::vec3(1, 0, 0));
  Scene s = quadScene({{floor, 100.0f}}, glm::vec3(0, 1.7f, 4.7f), glm::vec3(0));
  for (const char* radius : {"ssao.radius=1e-2", "ssao.radius=1e-4", "ssao.radius=1e-6"}) {
    Result r = render(s, {radius, "ssao.blur_radius=0"}, 320, 240);
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x)
        ASSERT_GT(r.at(x, y), 0.99f) << radius << " pixel " << x << "," << y;
  }
}

TEST_F(SsaoTest, NoNaNAtGrazingAnglesOrExtremeClipPlanes) {
  const glm::mat4 floor = glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), glm::vec3(1, 0, 0));
  // Camera skimming a huge plane, near = 1e-4, far = 1e5. The camera is level, so the floor's
  // view-space normal is exactly +y (the helper axis of the usual tangent-frame construction).
  Scene grazing = quadScene({{floor, 1000.0f}}, glm::vec3(0, 0.01f, 0), glm::vec3(0, 0.01f, -10),
                            1.0f, 1e-4f, 1e5f);
  for (const char* radius : {"ssao.radius=0.5", "ssao.radius=1e-4", "ssao.radius=1e4"}) {
    Result r = render(grazing, {radius});
    EXPECT_TRUE(finite(r.ao)) << radius;
    double sum = 0.0;
    int floorPixels = 0;
    for (int y = 0; y < r.h; ++y)
      for (int x = 0; x < r.w; ++x) {
        ASSERT_GE(r.at(x, y), 0.0f);
        ASSERT_LE(r.at(x, y), 1.0f);
        if (r.depthAt(x, y) > 0.0f) sum += r.at(x, y), ++floorPixels;
      }
    // A flat floor does not occlude itself, even at grazing angles (texel-centre slide).
    ASSERT_GT(floorPixels, 1000);
    std::printf("grazing floor, %s: mean AO %.4f\n", radius, sum / floorPixels);
    EXPECT_GT(sum / floorPixels, 0.98) << radius;
  }
  EXPECT_TRUE(finite(render(cornerScene(), {"ssao.radius=0.5"}).ao));

  // Higher up, looking far along the floor (1.4 degrees at the image centre): without the
  // texel-centre slide, depth-texel quantization made this flat floor occlude itself.
  Scene far = quadScene({{floor, 1000.0f}}, glm::vec3(0, 0.5f, 0), glm::vec3(0, 0, -20));
  Result r = render(far, {"ssao.radius=0.5", "ssao.samples=16", "ssao.blur_radius=0"});
  double sum = 0.0;
  int floorPixels = 0;
  for (int y = 0; y < r.h; ++y)
    for (int x = 0; x < r.w; ++x)
      if (r.depthAt(x, y) > 0.0f) sum += r.at(x, y), ++floorPixels;
  ASSERT_GT(floorPixels, 1000);
  std::printf("far grazing floor: mean AO %.4f\n", sum / floorPixels);
  EXPECT_GT(sum / floorPixels, 0.995);  // 1.0 measured; 0.986 without the slide
}

TEST_F(SsaoTest, BlurRemovesTheInterleavePattern) {
  auto with = [&](const char* blur) {
    return render(cornerScene(),
                  {"ssao.radius=0.5", "ssao.samples=8", "ssao.interleave=true", blur}, 320, 240);
  };
  Result raw = with("ssao.blur_radius=0"), blurred = with("ssao.blur_radius=2");
  // Occluded floor near the corner, away from the edge itself. Measured: ~300x less energy.
  const double eRaw = patternEnergy(raw, 0.05f, 0.4f), eBlur = patternEnergy(blurred, 0.05f, 0.4f);
  std::printf("pattern energy: raw %.3g, blurred %.3g (%.0fx less)\n", eRaw, eBlur, eRaw / eBlur);
  EXPECT_GT(eRaw, 1e-4) << "the raw interleaved estimate should show its 4x4 pattern";
  EXPECT_LT(eBlur, eRaw / 50.0) << "raw " << eRaw << " blurred " << eBlur;
}

TEST_F(SsaoTest, NoDarkPixelsOnTheOutlineOfACurvedObject) {
  // A tessellated sphere, then a thin vertical "cylinder" (the sphere scaled to 0.1 x 2 x 0.1):
  // convex, so their AO is 1 everywhere, 10 radii in front of a wall. Near an outline
  // interpolated normals face slightly away from the camera; turned toward the viewer they
  // pointed into the object, whose pixels then read AO ~0.1 (isolated dots the blur keeps, as it
  // does not average across the outline). Every pixel of the object must stay open.
  for (const char* scale : {"1", "[0.1, 2, 0.1]"}) {
    const Scene s = test::outlineScene(scale, test::makeTempDir("scenes") + "/ssao_outline.json");
    for (const char* blur : {"ssao.blur_radius=0", "ssao.blur_radius=2"}) {
      Result r = render(s, {"ssao.radius=0.5", "ssao.samples=16", blur}, 320, 240);
      auto onSphere = [&](int x, int y) { return r.worldAt(x, y).z > -1.0f; };
      int outline = 0;
      for (int y = 1; y < r.h - 1; ++y)
        for (int x = 1; x < r.w - 1; ++x) {
          if (!onSphere(x, y)) continue;
          const bool edge = !onSphere(x - 1, y) || !onSphere(x + 1, y) || !onSphere(x, y - 1) ||
                            !onSphere(x, y + 1);
          outline += edge;
          ASSERT_GT(r.at(x, y), 0.97f)
              << "scale " << scale << ", " << blur << (edge ? " outline" : " inner") << " pixel "
              << x << "," << y;
        }
      EXPECT_GT(outline, 100) << "scale " << scale << ", " << blur;
    }
  }
}

TEST_F(SsaoTest, NoHaloAcrossDepthDiscontinuities) {
  // A wall at z = 0 and, 3 units (6 radii) in front of it, an open book: two small quads
  // meeting at 90 degrees, opening towards the camera, so the pages are dark up to their
  // silhouettes (intensity 2 makes them darker; unoccluded pixels stay at 1). Wall pixels around
  // the silhouettes must not be darkened: not by the pages as occluders (range check) and not by
  // blurring the pages' AO into them (edge stopping).
  Scene s = quadScene(test::openBookQuads(), test::kOpenBookEye, glm::vec3(0));
  for (const char* blur : {"ssao.blur_radius=0", "ssao.blur_radius=2", "ssao.blur_radius=8"}) {
    Result r = render(s, {"ssao.radius=0.5", "ssao.samples=16", "ssao.intensity=2", blur});
    const test::BookOutline o = test::bookOutline(r);
    for (const auto& [px, v] : o.wall)
      ASSERT_GT(v, 0.99f) << blur << " wall pixel " << px.x << "," << px.y << " darkened";
    std::printf("%s: darkest page pixel next to the wall %.3f\n", blur, o.darkestPage);
    EXPECT_GT(o.wall.size(), 50u) << blur;
    ASSERT_GT(o.pages, 50) << blur;
    EXPECT_LT(o.darkestPage, 0.85f) << blur << ": the pages must be dark for the test to bite";
  }
}

TEST_F(SsaoTest, SsaoOnlyPassList) {
  Scene scene = cornerScene();  // no lights: no shadow pass
  Renderer r(ctx(), scene, settingsFor(scene, {}, kW, kH), &registry);
  r.renderFrame();
  EXPECT_EQ(r.passNames(),
            (std::vector<std::string>{"gbuffer", "ssao", "ssao_blur", "lighting", "tonemap"}));
}

TEST_F(SsaoTest, DebugViewRunsOnlyWhatFeedsIt) {
  Scene scene = cornerScene();
  RenderSettings rs = settingsFor(scene, {}, kW, kH);
  rs.view = registry.info("ssao").debugView;
  Renderer r(ctx(), scene, rs, &registry);
  r.renderFrame();
  EXPECT_EQ(r.passNames(), (std::vector<std::string>{"gbuffer", "ssao", "ssao_blur"}));
}

TEST_F(SsaoTest, BlurRadiusZeroDropsThePassAndSettingsApplyLive) {
  Scene scene = cornerScene();
  RenderSettings rs = settingsFor(scene, {"ssao.blur_radius=0"}, kW, kH);
  rs.view = "ao";
  Renderer r(ctx(), scene, rs, &registry);
  r.renderFrame();
  EXPECT_EQ(r.passNames(), (std::vector<std::string>{"gbuffer", "ssao"}));
  auto meanAO = [&] {
    const ImageRGBA32F ao = r.readTarget("ao");
    double sum = 0.0;
    for (size_t i = 0; i < ao.pixels.size(); i += 4) sum += ao.pixels[i];
    return sum / (ao.pixels.size() / 4);
  };
  const double before = meanAO();

  // Uniform-only settings (intensity, samples) apply on the next frame without a recompile.
  SettingValues values = rs.effects[0].settings;
  values.set("intensity", 0.0, "test");
  values.set("samples", 32, "test");
  r.setEffectSettings("ssao", values);
  EXPECT_FALSE(r.graphRecompiledByLastChange());
  r.renderFrame();
  EXPECT_LT(before, 0.99) << "the corner should be occluded at intensity 1";
  EXPECT_EQ(meanAO(), 1.0) << "intensity 0 must give AO 1 everywhere";

  // The blur radius changes the graph.
  values.set("blur_radius", 2, "test");
  r.setEffectSettings("ssao", values);
  EXPECT_TRUE(r.graphRecompiledByLastChange());
  r.renderFrame();
  EXPECT_EQ(r.passNames(), (std::vector<std::string>{"gbuffer", "ssao", "ssao_blur"}));
}

}  // namespace
}  // namespace gi
