// Environment lighting on the CPU: SH9 irradiance, importance sampling of equirect maps and
// loading .hdr maps from JSON scenes.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/scene_io.h"
#include "process.h"

namespace gi {
namespace {

// Writes a flat (non-RLE) Radiance RGBE file.
void writeHdr(const std::string& path, int w, int h, const std::vector<float>& rgb) {
  std::ofstream out(path, std::ios::binary);
  out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " << h << " +X " << w << "\n";
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    const float m = std::max({rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]});
    unsigned char px[4] = {0, 0, 0, 0};
    if (m > 1e-32f) {
      int e = 0;
      const float scale = std::frexp(m, &e) * 256.0f / m;
      for (int c = 0; c < 3; ++c) px[c] = static_cast<unsigned char>(rgb[i * 3 + c] * scale);
      px[3] = static_cast<unsigned char>(e + 128);
    }
    out.write(reinterpret_cast<const char*>(px), 4);
  }
}

std::string writeText(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const std::vector<glm::vec3> kNormals = {{0, 1, 0},          {0, -1, 0},
                                         {1, 0, 0},          {0, 0, -1},
                                         {0.6f, 0.0f, 0.8f}, {0.57735f, 0.57735f, 0.57735f}};

TEST(EnvironmentSH, ConstantEnvironmentGivesPiTimesRadianceOnEveryNormal) {
  Environment env;
  env.kind = Environment::Kind::Constant;
  env.constantColor = {1.0f, 2.0f, 0.5f};
  env.intensity = 1.5f;
  const SH9 sh = irradianceSH(env);
  for (const glm::vec3& n : kNormals) {
    const glm::vec3 e = evalIrradiance(sh, n);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(e[c], kPi * env.constantColor[c] * 1.5f,
                  0.01f * kPi * env.constantColor[c] * 1.5f)
          << "normal " << n.x << "," << n.y << "," << n.z;
  }
}

TEST(EnvironmentSH, ConstantMapProjectsToPiTimesRadiance) {
  const int w = 64, h = 32;
  const std::vector<float> rgb(size_t(w) * h * 3, 0.75f);
  const SH9 sh = irradianceSHFromMap(w, h, rgb, 2.0f);
  for (const glm::vec3& n : kNormals)
    EXPECT_NEAR(evalIrradiance(sh, n).g, kPi * 1.5f, 0.01f * kPi * 1.5f);
}

TEST(EnvironmentSH, SkyIsBrighterFromAboveThanBelow) {
  Environment sky;  // default procedural sky: bright zenith, dark ground
  const SH9 sh = irradianceSH(sky);
  EXPECT_GT(evalIrradiance(sh, {0, 1, 0}).b, evalIrradiance(sh, {0, -1, 0}).b);
  // Close to the brute-force cosine integral of the sky for the up normal.
  glm::vec3 ref(0.0f);
  const int n = 256;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const float ct = (i + 0.5f) / n;  // cos(theta) uniform over the upper hemisphere
      const float st = std::sqrt(1.0f - ct * ct), phi = 2.0f * kPi * (j + 0.5f) / (2 * n);
      ref += environmentLookup(sky, {st * std::cos(phi), ct, st * std::sin(phi)}) * ct;
    }
  ref *= 2.0f * kPi / float(n * 2 * n);
  const glm::vec3 e = evalIrradiance(sh, {0, 1, 0});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], ref[c], 0.05f * ref[c]);
}

TEST(EnvironmentMapping, UVAndDirectionRoundTrip) {
  for (const glm::vec3& n : kNormals) {
    if (std::abs(n.y) > 0.99f) continue;  // u undefined at the poles
    const glm::vec3 back = equirectDirection(equirectUV(n));
    EXPECT_NEAR(glm::length(back - glm::normalize(n)), 0.0f, 1e-4f);
  }
  EXPECT_NEAR(equirectUV({0, 1, 0}).y, 0.0f, 1e-6f);  // row 0 looks up
}

TEST(EnvironmentSampling, OneBrightPixelGetsAlmostAllSamples) {
  const int w = 64, h = 32, bx = 40, by = 10;
  std::vector<float> rgb(size_t(w) * h * 3, 0.001f);
  for (int c = 0; c < 3; ++c) rgb[(size_t(by) * w + bx) * 3 + c] = 1000.0f;
  EnvironmentSampler sampler(w, h, rgb);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  const int n = 20000;
  int inPixel = 0;
  for (int i = 0; i < n; ++i) {
    const EnvironmentSampler::Sample s = sampler.sample(U(rng), U(rng));
    const glm::vec2 uv = equirectUV(s.direction);
    const int x = std::min(int(uv.x * w), w - 1), y = std::min(int(uv.y * h), h - 1);
    EXPECT_EQ(y * w + x, s.pixel);
    if (s.pixel == by * w + bx) ++inPixel;
    EXPECT_GT(s.pdf, 0.0f);
    EXPECT_NEAR(s.pdf, sampler.pdf(s.direction), 1e-3f * s.pdf);
  }
  EXPECT_GT(inPixel, int(0.95 * n));
}

TEST(EnvironmentSampling, PdfIntegratesToOne) {
  const int w = 32, h = 16;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  std::vector<float> rgb(size_t(w) * h * 3);
  for (float& v : rgb) v = 0.1f + U(rng);
  EnvironmentSampler sampler(w, h, rgb);
  // Monte Carlo over uniform sphere directions: E[pdf(d) / (1 / 4pi)] = 1.
  const int n = 400000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - 2.0f * U(rng), phi = 2.0f * kPi * U(rng);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    sum += sampler.pdf({r * std::cos(phi), z, r * std::sin(phi)}) * 4.0 * kPi;
  }
  EXPECT_NEAR(sum / n, 1.0, 0.01);
  // Samples follow the pdf: the mean of 1/pdf estimates the sphere's solid angle.
  double inv = 0.0;
  for (int i = 0; i < n / 4; ++i) inv += 1.0 / sampler.sample(U(rng), U(rng)).pdf;
  EXPECT_NEAR(inv / (n / 4), 4.0 * kPi, 0.02 * 4.0 * kPi);
}

TEST(EnvironmentMap, LoadsFromJsonScene) {
  const std::string dir = test::makeTempDir("env-map");
  const int w = 16, h = 8;
  std::vector<float> rgb(size_t(w) * h * 3, 0.5f);
  writeHdr(dir + "/sky.hdr", w, h, rgb);
  const std::string scene = writeText(dir, "scene.json",
                                      R"({"models": [{"primitive": "plane"}],
          "environment": {"type": "map", "file": "sky.hdr", "intensity": 2}})");
  const Scene s = loadScene(scene);
  EXPECT_EQ(s.environment.kind, Environment::Kind::Map);
  EXPECT_EQ(s.environment.mapWidth, w);
  EXPECT_EQ(s.environment.mapHeight, h);
  EXPECT_NEAR(environmentLookup(s.environment, {0.3f, 0.2f, 0.9f}).r, 1.0f, 0.01f);
  EXPECT_NEAR(evalIrradiance(irradianceSH(s.environment), {0, 1, 0}).r, kPi, 0.01f * kPi);
}

TEST(EnvironmentMap, MissingFileIsAClearError) {
  const std::string dir = test::makeTempDir("env-missing");
  const std::string scene = writeText(dir, "scene.json",
                                      R"({"models": [{"primitive": "plane"}],
          "environment": {"type": "map", "file": "nowhere.hdr"}})");
  try {
    loadScene(scene);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::MissingResource);
    EXPECT_NE(std::string(e.what()).find("nowhere.hdr"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("environment.file"), std::string::npos) << e.what();
  }
  Environment env;
  EXPECT_THROW(loadEnvironmentMap(env, dir + "/nowhere.hdr"), Error);
  // A map without a file, or a file for another type, is a schema error.
  for (const char* bad : {R"({"models": [{"primitive": "plane"}], "environment": {"type": "map"}})",
                          R"({"models": [{"primitive": "plane"}],
                              "environment": {"type": "sky", "file": "x.hdr"}})"}) {
    try {
      loadScene(writeText(dir, "bad.json", bad));
      FAIL() << "expected an error for " << bad;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Schema) << e.what();
    }
  }
}

}  // namespace
}  // namespace gi
