// The packed G-buffer (gi/gbuffer.h, gbuffer.glsl): each channel's stated precision on the CPU
// twin of the encoding, and on the GPU that the shader packs the same bits as the CPU for known
// materials, that the unpacked views equal the CPU decode of the packed texels, and that two
// colour targets are all the geometry pass writes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include <glm/gtc/constants.hpp>

#include "gi/gbuffer.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

namespace gb = gbuffer;

// The angle between two directions, from the chord (acos loses its precision near 0).
double angleDeg(const glm::vec3& a, const glm::vec3& b) {
  const double chord = glm::length(glm::dvec3(glm::normalize(a)) - glm::dvec3(glm::normalize(b)));
  return glm::degrees(2.0 * std::asin(std::min(1.0, 0.5 * chord)));
}

TEST(GBufferLayout, NormalsRoundTripWithinTheStatedAngle) {
  // A Fibonacci sphere of 200k directions, the axes and the octahedron's folds.
  std::vector<glm::vec3> dirs;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const float y = 1.0f - 2.0f * (float(i) + 0.5f) / float(n);
    const float r = std::sqrt(std::max(0.0f, 1.0f - y * y));
    const float phi = float(i) * glm::pi<float>() * (3.0f - std::sqrt(5.0f));
    dirs.emplace_back(r * std::cos(phi), y, r * std::sin(phi));
  }
  for (glm::vec3 a : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1),
                      glm::vec3(1, 1, 0), glm::vec3(1, -1, -1e-7f), glm::vec3(-1, 1, -1)}) {
    dirs.push_back(a);
    dirs.push_back(-a);
  }
  double worst = 0.0;
  for (const glm::vec3& d : dirs) {
    const glm::vec3 back = gb::decodeNormal(gb::encodeNormal(d));
    ASSERT_NEAR(glm::length(back), 1.0f, 1e-6f);
    worst = std::max(worst, angleDeg(back, d));
  }
  EXPECT_LT(worst, gb::kNormalMaxErrorDeg);
  RecordProperty("worst_normal_error_deg", std::to_string(worst));
  std::printf("normal: worst angle error %.5f deg over %zu directions\n", worst, dirs.size());
  // Guard: a zero or non-finite normal encodes as +z.
  for (glm::vec3 bad : {glm::vec3(0.0f), glm::vec3(NAN, 0, 0), glm::vec3(INFINITY, 1, 0)})
    EXPECT_EQ(gb::decodeNormal(gb::encodeNormal(bad)), glm::vec3(0, 0, 1));
}

TEST(GBufferLayout, AlbedoIsExactIn8BitSrgbAndMaterialIn8Bits) {
  // Every 8-bit sRGB code comes back as itself.
  for (int code = 0; code < 256; ++code)
    ASSERT_EQ(gb::linearToSrgb8(gb::srgb8ToLinear(uint8_t(code))), code) << code;
  // Any linear value lands on its nearest sRGB code, as an sRGB8 target rounds it.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 100000; ++i) {
    const float a = u(rng);
    const float s = a <= 0.0031308f ? 12.92f * a : 1.055f * std::pow(a, 1.0f / 2.4f) - 0.055f;
    ASSERT_LE(std::abs(float(gb::linearToSrgb8(a)) - s * 255.0f), 0.5f + 1e-4f) << a;
  }
  gb::Texel t;
  t.geometry = true;
  for (int i = 0; i < 1000; ++i) {
    t.albedo = {u(rng), u(rng), u(rng)};
    t.roughness = u(rng);
    t.metallic = u(rng);
    const gb::Texel back = gb::decode(gb::encode(t));
    EXPECT_NEAR(back.roughness, t.roughness, 1.0f / 510.0f + 1e-7f);
    EXPECT_NEAR(back.metallic, t.metallic, 1.0f / 510.0f + 1e-7f);
    EXPECT_TRUE(back.geometry);
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(back.albedo[c], gb::srgb8ToLinear(gb::linearToSrgb8(t.albedo[c])));
  }
  // Out of range and NaN clamp; an empty texel (the cleared sky) is no geometry.
  t.albedo = {-1.0f, 2.0f, NAN};
  EXPECT_EQ(gb::decode(gb::encode(t)).albedo, glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_FALSE(gb::decode(glm::uvec4(0)).geometry);
}

TEST(GBufferLayout, EmissionKeepsNineBitsOfTheLargestChannel) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> expo(-20.0f, 15.9f), frac(0.0f, 1.0f);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const float scale = std::exp2(expo(rng));
    const glm::vec3 c(scale * frac(rng), scale * frac(rng), scale * frac(rng));
    const glm::vec3 back = gb::decodeRgb9e5(gb::encodeRgb9e5(c));
    const float largest = std::max(c.r, std::max(c.g, c.b));
    for (int k = 0; k < 3; ++k) {
      if (largest < std::exp2(-15.0f)) {  // the smallest exponents: steps of 2^-24 or 2^-23
        ASSERT_LE(std::abs(back[k] - c[k]), std::exp2(-24.0f)) << c[k];
        continue;
      }
      const double err = std::abs(back[k] - c[k]) / largest;
      worst = std::max(worst, err);
      ASSERT_LE(err, std::exp2(-9.0) + 1e-7) << c[k] << " of " << largest;
    }
  }
  std::printf("emission: worst error %.3g of the largest channel\n", worst);
  // Exactly representable values stay exact; guards at the format's edges.
  EXPECT_EQ(gb::decodeRgb9e5(gb::encodeRgb9e5({1.0f, 0.5f, 0.0f})), glm::vec3(1.0f, 0.5f, 0.0f));
  EXPECT_EQ(gb::decodeRgb9e5(gb::encodeRgb9e5({20.0f, 20.0f, 20.0f})), glm::vec3(20.0f));
  EXPECT_EQ(gb::decodeRgb9e5(gb::encodeRgb9e5({1e38f, INFINITY, 65408.0f})),
            glm::vec3(gb::kMaxEmission));
  EXPECT_EQ(gb::decodeRgb9e5(gb::encodeRgb9e5({NAN, -5.0f, -INFINITY})), glm::vec3(0.0f));
  EXPECT_EQ(gb::decodeRgb9e5(gb::encodeRgb9e5(glm::vec3(0.0f))), glm::vec3(0.0f));
}

TEST(GBufferLayout, MotionInHalfFloatsIsWithinAThirtiethOfAPixelAt64Pixels) {
  // The G-buffer stores motion in UV units as half floats: round-to-nearest keeps 11 bits.
  for (int width : {320, 1280, 4096})
    for (const double px : {0.25, 0.7, 1.0, 1.9, 3.3, 7.77, 13.0, 25.1, 41.7, 63.9, 64.0}) {
      const float uv = float(px / width);
      const float back = glm::unpackHalf2x16(glm::packHalf2x16(glm::vec2(uv, -uv))).x;
      const double errPx = std::abs(double(back) - uv) * width;
      ASSERT_LE(errPx, px * std::exp2(-11.0) + 1e-9) << px << " px at " << width;
      ASSERT_LE(errPx, 0.032) << px << " px at " << width;
    }
  EXPECT_EQ(glm::unpackHalf2x16(glm::packHalf2x16(glm::vec2(0.0f))), glm::vec2(0.0f));
}

class GBufferGpuTest : public test::VulkanTest {};

// Five quads facing the camera with known materials (albedo, roughness, metallic, emission);
// the packed texel at each quad's centre must equal the CPU encoding of that material, and the
// unpacked views equal the CPU decoding of every packed texel.
TEST_F(GBufferGpuTest, ShaderPacksWhatTheCpuPacksAndTheViewsUnpackIt) {
  struct Mat {
    glm::vec3 albedo, emission;
    float roughness, metallic;
  };
  const std::vector<Mat> mats = {{{0.8f, 0.1f, 0.05f}, {0, 0, 0}, 0.3f, 0.0f},
                                 {{0.02f, 0.5f, 0.99f}, {12.5f, 0.25f, 3e-3f}, 0.9f, 1.0f},
                                 {{1.0f, 1.0f, 1.0f}, {0, 0, 0}, 0.0f, 0.5f},
                                 {{0.0f, 0.0f, 0.0f}, {60000.0f, 1.0f, 0.0f}, 1.0f, 0.25f},
                                 {{0.5f, 0.5f, 0.5f}, {0.01f, 0.02f, 0.03f}, 0.5f, 0.75f}};
  std::string models;
  for (size_t i = 0; i < mats.size(); ++i) {
    const Mat& m = mats[i];
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  R"(%s{"primitive": "plane", "size": 0.5, "translation": [%g, 0, 0],
                     "rotation": [90, 0, 0], "material": {"base_color": [%.9g, %.9g, %.9g],
                     "emission": [%.9g, %.9g, %.9g], "roughness": %.9g, "metallic": %.9g}})",
                  i ? "," : "", (float(i) - 2.0f) * 0.6f, m.albedo.r, m.albedo.g, m.albedo.b,
                  m.emission.r, m.emission.g, m.emission.b, m.roughness, m.metallic);
    models += buf;
  }
  test::TempDir dir("gbuffer_layout");
  const Scene scene = loadScene(dir.write("quads.json", R"({"models": [)" + models + R"(],
      "camera": {"position": [0, 0, 3], "target": [0, 0, 0], "yfov_deg": 40}})"));
  RenderSettings rs;
  rs.width = 200;
  rs.height = 80;
  rs.view = "lit";
  rs.keepForReadback = {"gbuffer", "normal", "albedo", "material", "emission", "motion"};
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  // The scene has no light: the default sun (shadowed) lights it.
  EXPECT_EQ(r.passNames(), (std::vector<std::string>{"gbuffer", "gbuffer_normal", "gbuffer_albedo",
                                                     "gbuffer_material", "gbuffer_emission",
                                                     "shadow_0", "lighting"}));
  const std::vector<uint8_t> raw = r.readTargetBytes("gbuffer");
  ASSERT_EQ(raw.size(), size_t(rs.width) * rs.height * 16);
  auto packed = [&](int x, int y) {
    glm::uvec4 g;
    std::memcpy(&g, &raw[(size_t(y) * rs.width + x) * 16], 16);
    return g;
  };
  const ImageRGBA32F normal = r.readTarget("normal"), albedo = r.readTarget("albedo"),
                     material = r.readTarget("material"), emission = r.readTarget("emission");
  // The unpacked views are the CPU decode of every packed texel.
  size_t geometry = 0;
  for (int y = 0; y < int(rs.height); ++y)
    for (int x = 0; x < int(rs.width); ++x) {
      const gb::Texel t = gb::decode(packed(x, y));
      const float* nv = &normal.pixels[(size_t(y) * rs.width + x) * 4];
      const float* av = &albedo.pixels[(size_t(y) * rs.width + x) * 4];
      const float* mv = &material.pixels[(size_t(y) * rs.width + x) * 4];
      const float* ev = &emission.pixels[(size_t(y) * rs.width + x) * 4];
      geometry += t.geometry ? 1 : 0;
      ASSERT_EQ(nv[3], t.geometry ? 1.0f : 0.0f);
      if (!t.geometry) continue;
      for (int c = 0; c < 3; ++c) {
        ASSERT_NEAR(nv[c], t.normal[c], 1e-6f);
        ASSERT_NEAR(av[c], t.albedo[c], 1e-6f * std::max(1.0f, t.albedo[c]));
        ASSERT_NEAR(ev[c], t.emission[c], 1e-6f * std::max(1.0f, t.emission[c]));
      }
      ASSERT_NEAR(mv[0], t.roughness, 1e-6f);
      ASSERT_NEAR(mv[1], t.metallic, 1e-6f);
    }
  EXPECT_GT(geometry, 1500u);  // five quads of ~18 x 18 pixels
  // The shader packs what the CPU packs: each quad's centre pixel.
  for (size_t i = 0; i < mats.size(); ++i) {
    SCOPED_TRACE(i);
    // The quad's centre (x, 0, 0) seen from (0, 0, 3): ndc x = x / (3 tan(20 deg) aspect).
    const double ndcX = (double(i) - 2.0) * 0.6 / (3.0 * std::tan(glm::radians(20.0)) * 2.5);
    const int x = int((0.5 * ndcX + 0.5) * rs.width);
    const int y = int(rs.height) / 2;
    gb::Texel expect;
    expect.normal = {0, 0, 1};
    expect.albedo = mats[i].albedo;
    expect.emission = mats[i].emission;
    expect.roughness = mats[i].roughness;
    expect.metallic = mats[i].metallic;
    expect.geometry = true;
    const glm::uvec4 want = gb::encode(expect), got = packed(x, y);
    EXPECT_EQ(got.y, want.y) << "albedo + roughness";
    EXPECT_EQ(got.z, want.z) << "metallic + flags";
    EXPECT_EQ(got.w, want.w) << "emission";
    EXPECT_LT(angleDeg(gb::decodeNormal(got.x), expect.normal), gb::kNormalMaxErrorDeg);
  }
}

}  // namespace
}  // namespace gi
