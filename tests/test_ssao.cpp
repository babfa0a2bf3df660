// The SSAO plugin against analytic cases: a lone plane is unoccluded, a 90-degree corner
// matches the continuous form of the same estimator, the result is scale invariant, never
// NaN, and the blur removes the 4x4 interleave pattern without bleeding across depth edges.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/effect_config.h"
#include "gi/renderer.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

constexpr uint32_t kW = 160, kH = 120;

Mesh quad(float half) {
  Mesh m;
  m.name = "quad";
  for (auto [x, y] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}})
    m.vertices.push_back({glm::vec3(x * half, y * half, 0), glm::vec3(0, 0, 1), glm::vec2(0)});
  m.indices = {0, 1, 2, 0, 2, 3};
  m.boundsMin = glm::vec3(-half, -half, 0);
  m.boundsMax = glm::vec3(half, half, 0);
  m.triangleAreas = {2 * half * half, 2 * half * half};
  return m;
}

// Scene of quads (each given by its world transform, facing local +z) and a camera looking
// from `eye` at `target`. `scale` multiplies every length (scale-invariance test).
Scene quadScene(const std::vector<std::pair<glm::mat4, float>>& quads, glm::vec3 eye,
                glm::vec3 target, float scale = 1.0f, float znear = 0.05f, float zfar = 100.0f) {
  Scene s;
  s.materials.push_back(Material{});
  const glm::mat4 S = glm::scale(glm::mat4(1.0f), glm::vec3(scale));
  for (const auto& [transform, half] : quads) {
    s.meshes.push_back(quad(half));
    int n = s.addNode("quad", S * transform);
    s.nodes[n].meshes = {int(s.meshes.size()) - 1};
  }
  Camera cam;
  cam.yfov = glm::radians(60.0f);
  cam.znear = znear * scale;
  cam.zfar = zfar * scale;
  s.cameras.push_back(cam);
  int c = s.addNode("camera",
                    glm::inverse(glm::lookAt(eye * scale, target * scale, glm::vec3(0, 1, 0))));
  s.nodes[c].camera = 0;
  s.activeCameraNode = c;
  s.updateWorldTransforms();
  return s;
}

// A floor (y = 0, facing +y) and a wall (x = 0, facing +x): a 90-degree concave corner.
Scene cornerScene(float scale = 1.0f) {
  const glm::mat4 floor = glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), glm::vec3(1, 0, 0));
  const glm::mat4 wall = glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 1, 0));
  return quadScene({{floor, 20.0f}, {wall, 20.0f}}, glm::vec3(2.5f, 1.6f, 0.0f),
                   glm::vec3(0.0f, 0.0f, 0.0f), scale);
}

class SsaoTest : public test::VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    registry.scanDirectory(test::binPath("plugins"));
    ASSERT_TRUE(registry.has("ssao")) << "ssao plugin missing from " << test::binPath("plugins");
  }
  struct Result {
    ImageRGBA32F ao, depth;
    glm::mat4 invViewProj;
  };
  Result render(const Scene& scene, const std::vector<std::string>& sets) {
    EffectOverrides cli;
    cli.effects = std::vector<std::string>{"ssao"};
    cli.sets = sets;
    RenderSettings rs;
    rs.width = kW;
    rs.height = kH;
    rs.effects = resolveEffects(scene, nullptr, cli, registry);
    Renderer r(ctx(), scene, rs, &registry);
    r.renderFrame();
    return {r.readTarget("ao"), r.readTarget("depth"),
            glm::inverse(r.camera().proj * r.camera().view)};
  }
  static glm::vec3 worldAt(const Result& res, int x, int y) {
    const float d = res.depth.pixels[(size_t(y) * kW + x) * 4];
    glm::vec4 w =
        res.invViewProj * glm::vec4((x + 0.5f) / kW * 2 - 1, (y + 0.5f) / kH * 2 - 1, d, 1.0f);
    return glm::vec3(w) / w.w;
  }
  static float aoAt(const Result& res, int x, int y) {
    return res.ao.pixels[(size_t(y) * kW + x) * 4];
  }
  EffectRegistry registry;
};

bool finite(const ImageRGBA32F& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}

TEST_F(SsaoTest, LonePlaneIsUnoccluded) {
  Scene s = quadScene({{glm::mat4(1.0f), 1.0f}}, glm::vec3(0, 0, 5), glm::vec3(0));
  Result r = render(s, {"ssao.radius=0.5"});
  ASSERT_TRUE(finite(r.ao));
  for (size_t i = 0; i < r.ao.pixels.size(); i += 4)
    ASSERT_NEAR(r.ao.pixels[i], 1.0f, 0.02f) << "pixel " << i / 4;
}

// Continuous form of the estimator (see effects/ssao/ssao_kernel.h): taps P + s R w with w
// cosine-distributed about the floor normal and s uniform in [0, 1]. For cosine-distributed w
// the component towards the wall, t = -w.x, has density (2/pi) sqrt(1 - t^2); the tap is
// inside the wall when s R t > d. Occluded fraction = Int_a^1 (2/pi) sqrt(1-t^2) (1 - a/t) dt
// with a = d / R.
double cornerOcclusion(double a) {
  const int n = 20000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = a + (1.0 - a) * (i + 0.5) / n;
    sum += (2.0 / M_PI) * std::sqrt(1.0 - t * t) * (1.0 - a / t);
  }
  return sum * (1.0 - a) / n;
}

TEST_F(SsaoTest, CornerMatchesTheContinuousEstimator) {
  const float R = 0.5f, d = 0.25f * R;
  // 64 taps without interleave or blur: the discrete Hammersley sum is within ~1/64 of the
  // integral; the bias (2.5% of R) removes taps just behind the wall. Tolerance 0.04.
  Result r = render(cornerScene(), {"ssao.radius=0.5", "ssao.samples=64", "ssao.interleave=false",
                                    "ssao.blur_radius=0", "ssao.bias=0.025"});
  ASSERT_TRUE(finite(r.ao));
  double sum = 0.0;
  int count = 0;
  for (int y = 8; y < int(kH) - 8; ++y)
    for (int x = 8; x < int(kW) - 8; ++x) {
      glm::vec3 p = worldAt(r, x, y);
      if (std::abs(p.y) > 1e-3f || std::abs(p.x - d) > 0.01f || std::abs(p.z) > 1.0f) continue;
      sum += aoAt(r, x, y);
      ++count;
    }
  ASSERT_GT(count, 10) << "no floor pixels at distance 0.25 r from the edge";
  const double expected = 1.0 - cornerOcclusion(d / R);
  EXPECT_NEAR(sum / count, expected, 0.04)
      << "expected AO " << expected << " over " << count << " pixels";
  EXPECT_LT(sum / count, 0.95) << "the corner must be visibly occluded";
}

TEST_F(SsaoTest, ScaleInvariant) {
  Result a = render(cornerScene(1.0f), {"ssao.radius=0.5", "ssao.samples=16"});
  Result b = render(cornerScene(1000.0f), {"ssao.radius=500", "ssao.samples=16"});
  double diff = 0.0;
  size_t over = 0, n = a.ao.pixels.size() / 4;
  for (size_t i = 0; i < n; ++i) {
    const double e = std::abs(a.ao.pixels[i * 4] - b.ao.pixels[i * 4]);
    diff += e;
    over += e > 0.05;
  }
  EXPECT_LT(diff / n, 0.005) << "mean |AO(x1) - AO(x1000)|";
  EXPECT_LT(double(over) / n, 0.01) << "pixels differing by more than 0.05";
}

TEST_F(SsaoTest, NoNaNAtGrazingAnglesOrExtremeClipPlanes) {
  const glm::mat4 floor = glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), glm::vec3(1, 0, 0));
  // Camera skimming a huge plane, near = 1e-4, far = 1e5.
  Scene grazing = quadScene({{floor, 1000.0f}}, glm::vec3(0, 0.01f, 0), glm::vec3(0, 0.01f, -10),
                            1.0f, 1e-4f, 1e5f);
  for (const char* radius : {"ssao.radius=0.5", "ssao.radius=1e-4", "ssao.radius=1e4"}) {
    Result r = render(grazing, {radius});
    EXPECT_TRUE(finite(r.ao)) << radius;
    for (size_t i = 0; i < r.ao.pixels.size(); i += 4) {
      ASSERT_GE(r.ao.pixels[i], 0.0f);
      ASSERT_LE(r.ao.pixels[i], 1.0f);
    }
  }
  EXPECT_TRUE(finite(render(cornerScene(), {"ssao.radius=0.5"}).ao));
}

// Energy of the 4x4 pattern: squared difference between each pixel and its 4x4 box mean.
double patternEnergy(const ImageRGBA32F& ao, const std::function<bool(int, int)>& inside) {
  double e = 0.0;
  int n = 0;
  for (int y = 4; y < int(kH) - 4; ++y)
    for (int x = 4; x < int(kW) - 4; ++x) {
      if (!inside(x, y)) continue;
      double mean = 0.0;
      for (int j = -2; j < 2; ++j)
        for (int i = -2; i < 2; ++i) mean += ao.pixels[(size_t(y + j) * kW + x + i) * 4];
      mean /= 16.0;
      const double v = ao.pixels[(size_t(y) * kW + x) * 4] - mean;
      e += v * v;
      ++n;
    }
  return n ? e / n : 0.0;
}

TEST_F(SsaoTest, BlurRemovesTheInterleavePattern) {
  const std::vector<std::string> base = {"ssao.radius=0.5", "ssao.samples=8",
                                         "ssao.interleave=true"};
  auto with = [&](const char* blur) {
    auto s = base;
    s.push_back(blur);
    return render(cornerScene(), s);
  };
  Result raw = with("ssao.blur_radius=0"), blurred = with("ssao.blur_radius=4");
  // Occluded floor pixels near the corner, away from the edge itself.
  auto region = [&](int x, int y) {
    glm::vec3 p = worldAt(raw, x, y);
    return std::abs(p.y) < 1e-3f && p.x > 0.05f && p.x < 0.4f && std::abs(p.z) < 1.0f;
  };
  const double eRaw = patternEnergy(raw.ao, region), eBlur = patternEnergy(blurred.ao, region);
  EXPECT_GT(eRaw, 1e-5) << "the raw interleaved estimate should show its 4x4 pattern";
  EXPECT_LT(eBlur, eRaw / 4.0) << "raw " << eRaw << " blurred " << eBlur;
}

TEST_F(SsaoTest, NoHaloAcrossDepthDiscontinuities) {
  // A wall at z = 0 and, 3 units in front of it (6 radii), a smaller quad: the wall around the
  // quad's silhouette must not be darkened (range check), before or after the blur.
  const glm::mat4 front = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 3));
  Scene s = quadScene({{glm::mat4(1.0f), 10.0f}, {front, 0.6f}}, glm::vec3(0, 0, 6), glm::vec3(0));
  for (const char* blur : {"ssao.blur_radius=0", "ssao.blur_radius=4"}) {
    Result r = render(s, {"ssao.radius=0.5", "ssao.samples=16", blur});
    int wallPixels = 0;
    for (int y = 0; y < int(kH); ++y)
      for (int x = 0; x < int(kW); ++x) {
        glm::vec3 p = worldAt(r, x, y);
        if (std::abs(p.z) > 1e-3f) continue;  // only wall pixels
        ++wallPixels;
        ASSERT_GT(aoAt(r, x, y), 0.97f) << blur << " wall pixel " << x << "," << y << " darkened";
      }
    EXPECT_GT(wallPixels, 1000);
  }
}

TEST_F(SsaoTest, SsaoOnlyPassList) {
  EffectOverrides cli;
  cli.effects = std::vector<std::string>{"ssao"};
  RenderSettings rs;
  rs.width = kW;
  rs.height = kH;
  Scene scene = cornerScene();  // no lights: no shadow pass
  rs.effects = resolveEffects(scene, nullptr, cli, registry);
  Renderer r(ctx(), scene, rs, &registry);
  r.renderFrame();
  EXPECT_EQ(r.passNames(),
            (std::vector<std::string>{"gbuffer", "ssao", "ssao_blur", "lighting", "tonemap"}));
}

TEST_F(SsaoTest, DebugViewRunsOnlyWhatFeedsIt) {
  EffectOverrides cli;
  cli.effects = std::vector<std::string>{"ssao"};
  RenderSettings rs;
  rs.width = kW;
  rs.height = kH;
  rs.view = registry.info("ssao").debugView;
  Scene scene = cornerScene();
  rs.effects = resolveEffects(scene, nullptr, cli, registry);
  Renderer r(ctx(), scene, rs, &registry);
  r.renderFrame();
  EXPECT_EQ(r.passNames(), (std::vector<std::string>{"gbuffer", "ssao", "ssao_blur"}));
}

}  // namespace
}  // namespace gi
