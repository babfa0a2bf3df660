// The environment on the GPU (render/environment_gpu.h, shaders/environment.glsl): samples
// drawn by sampleEnvironment equal the CPU EnvironmentSampler's, follow the texel
// probabilities, stay finite at the poles and for black maps, give an unbiased irradiance
// estimate, and the map and SH9 are what the renderer uploaded before this class.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "render/environment_gpu.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

// One invocation per input: sampleEnvironment(u[i]), environmentPdf at the sampled direction,
// and environmentPdf / environmentMapRadiance at a probe direction.
constexpr const char* kShader = R"(#version 460
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;
#define GI_ENVIRONMENT_SET 0
#define GI_ENVIRONMENT_BINDING_MAP 5
#define GI_ENVIRONMENT_BINDING_SAMPLING 6
#include "environment.glsl"
layout(set = 0, binding = 0, std430) readonly buffer Us { vec2 us[]; };
layout(set = 0, binding = 1, std430) readonly buffer Probes { vec4 probes[]; };
layout(set = 0, binding = 2, std430) writeonly buffer Out { vec4 outs[]; };
layout(push_constant) uniform Push { uint count; } pc;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  EnvironmentSample s = sampleEnvironment(us[i]);
  outs[i * 3 + 0] = vec4(s.direction, s.pdf);
  outs[i * 3 + 1] = vec4(s.radiance, environmentPdf(s.direction));
  outs[i * 3 + 2] = vec4(environmentMapRadiance(probes[i].xyz), environmentPdf(probes[i].xyz));
}
)";

struct GpuResult {
  glm::vec3 direction;
  float pdf;
  glm::vec3 radiance;
  float pdfAtDirection;
  glm::vec3 probeRadiance;
  float probePdf;
};
static_assert(sizeof(GpuResult) == 48);

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Texel solid angle in double (independent of the engine's float version).
double solidAngle(int y, int w, int h) {
  return 2.0 * M_PI / w * (std::cos(M_PI * y / h) - std::cos(M_PI * (y + 1) / h));
}

// A 64x32 map: a smooth gradient, a black bottom row and a black column (probability 0,
// never sampled), and one bright "sun" texel holding about a third of the probability.
constexpr int kW = 64, kH = 32, kSunX = 40, kSunY = 9;
Environment sunMap(float intensity = 2.0f) {
  Environment env;
  env.kind = Environment::Kind::Map;
  env.mapWidth = kW;
  env.mapHeight = kH;
  env.intensity = intensity;
  env.mapRGB.resize(size_t(kW) * kH * 3);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      float* p = &env.mapRGB[(size_t(y) * kW + x) * 3];
      const float g = 0.1f + 0.5f * float(x) / kW + 0.3f * (1.0f - float(y) / kH);
      p[0] = g;
      p[1] = 0.8f * g;
      p[2] = 0.5f + 0.2f * float(y) / kH;
      if (y == kH - 1 || x == 7) p[0] = p[1] = p[2] = 0.0f;
      if (x == kSunX && y == kSunY) p[0] = p[1] = p[2] = 400.0f;
    }
  return env;
}

Environment skyEnv() {
  Environment env;  // kind Sky, default colours
  env.intensity = 1.5f;
  return env;
}

// The CPU sampler over exactly the map EnvironmentGpu samples (Sky/Constant tabulated).
EnvironmentSampler cpuSampler(const Environment& env) {
  if (env.kind == Environment::Kind::Map) return EnvironmentSampler(env);
  return EnvironmentSampler(kTabulatedWidth, kTabulatedHeight,
                            tabulateEnvironment(env, kTabulatedWidth, kTabulatedHeight));
}
// ... and that map as a Kind::Map environment (for CPU radiance lookups).
Environment asMap(const Environment& env) {
  if (env.kind == Environment::Kind::Map) return env;
  Environment m;
  m.kind = Environment::Kind::Map;
  m.mapWidth = kTabulatedWidth;
  m.mapHeight = kTabulatedHeight;
  m.mapRGB = tabulateEnvironment(env, kTabulatedWidth, kTabulatedHeight);
  m.intensity = env.intensity;
  return m;
}

// Offsets off the half-cell: a sky's rows have uniform column CDFs, on which u = (j + 0.5) / n
// would hit texel edges exactly.
std::vector<glm::vec2> uGrid(int n) {
  std::vector<glm::vec2> us;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) us.push_back({(i + 0.3f) / n, (j + 0.6f) / n});
  return us;
}

std::vector<glm::vec2> uRandom(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<glm::vec2> us(n);
  for (glm::vec2& u : us) u = {uni(rng), uni(rng)};
  return us;
}

class EnvironmentGpuTest : public VulkanTest {
 protected:
  // Runs the shader over `us` (probes[i] defaults to +y) and reads the results back.
  std::vector<GpuResult> run(const EnvironmentGpu& env, const std::vector<glm::vec2>& us,
                             std::vector<glm::vec4> probes = {}) {
    const uint32_t n = uint32_t(us.size());
    probes.resize(n, glm::vec4(0, 1, 0, 0));
    const std::string dir = std::string(GI_SOURCE_DIR) + "/engine/shaders";
    const auto ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    vk::Pipeline pipeline = vk::Pipeline::compute(
        ctx(),
        vk::compileGlsl(kShader, VK_SHADER_STAGE_COMPUTE_BIT, "environment_test.comp", {dir}),
        {{0, ssbo},
         {1, ssbo},
         {2, ssbo},
         {5, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
         {6, ssbo}},
        sizeof(uint32_t));
    vk::Buffer uBuffer(ctx(), n * sizeof(glm::vec2), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    vk::Buffer probeBuffer(ctx(), n * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    vk::Buffer out(ctx(), n * sizeof(GpuResult), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    uBuffer.write(us.data(), n * sizeof(glm::vec2));
    probeBuffer.write(probes.data(), n * sizeof(glm::vec4));
    // Any filter works: environment.glsl reads the map with texelFetch.
    vk::Sampler sampler(ctx(), VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT);
    vk::DescriptorArena arena(ctx());
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
      vk::DescriptorWriter w;
      w.buffer(0, ssbo, uBuffer.handle())
          .buffer(1, ssbo, probeBuffer.handle())
          .buffer(2, ssbo, out.handle())
          .sampled(5, env.map().view(), sampler.handle())
          .buffer(6, ssbo, env.samplingBuffer());
      arena.bind(cmd, pipeline, w);
      vkCmdPushConstants(cmd, pipeline.layout(), VK_SHADER_STAGE_ALL, 0, sizeof n, &n);
      vkCmdDispatch(cmd, (n + 63) / 64, 1, 1);
      hostBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    });
    std::vector<GpuResult> results(n);
    std::memcpy(results.data(), out.mapped(), n * sizeof(GpuResult));
    return results;
  }

  // The map image's texels (RGBA32F), copied back through a host-visible buffer.
  std::vector<float> readMap(const EnvironmentGpu& env) {
    const vk::Image& image = env.map();
    const size_t floats = size_t(env.width()) * env.height() * 4;
    vk::Buffer staging(ctx(), floats * sizeof(float), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
      vk::imageBarrier(cmd, image.handle(), image.aspect(),
                       VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                       VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                       0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
      VkBufferImageCopy copy{};
      copy.imageSubresource = {image.aspect(), 0, 0, 1};
      copy.imageExtent = {env.width(), env.height(), 1};
      vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             staging.handle(), 1, &copy);
      vk::imageBarrier(cmd, image.handle(), image.aspect(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                       VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
      hostBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    });
    std::vector<float> texels(floats);
    std::memcpy(texels.data(), staging.mapped(), floats * sizeof(float));
    return texels;
  }

 private:
  // Device writes made visible to the host before the fence wait returns.
  static void hostBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 stage, VkAccessFlags2 access) {
    VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    barrier.srcStageMask = stage;
    barrier.srcAccessMask = access;
    barrier.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    barrier.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &barrier;
    vkCmdPipelineBarrier2(cmd, &dep);
  }
};

float maxAbsDiff(const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 d = glm::abs(a - b);
  return std::max({d.x, d.y, d.z});
}

// GPU atan/acos are approximations (lavapipe's acos is off by ~2e-5 rad): near the sun a
// bilinear lookup changes by 0.2% over that. So `gpu` must lie within 1e-4 relative of the
// range of CPU lookups at uv +- 1e-5 (a box; bilinear extremes lie at its corners and edges).
void expectLookup(const Environment& map, const glm::vec3& dir, const glm::vec3& gpu) {
  const glm::vec2 uv = equirectUV(dir);
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j) {
      const glm::vec2 p = uv + 1e-5f * glm::vec2(i, j);
      const glm::vec3 L =
          environmentLookup(map, equirectDirection({p.x, std::clamp(p.y, 0.0f, 1.0f)}));
      lo = glm::min(lo, L);
      hi = glm::max(hi, L);
    }
  for (int c = 0; c < 3; ++c) {
    EXPECT_GE(gpu[c], lo[c] - 1e-4f * (1.0f + lo[c]))
        << "channel " << c << " uv " << uv.x << "," << uv.y;
    EXPECT_LE(gpu[c], hi[c] + 1e-4f * (1.0f + hi[c]))
        << "channel " << c << " uv " << uv.x << "," << uv.y;
  }
}

// Distance of a direction to its texel's nearest edge, in texels (0 = on an edge).
float edgeDistance(const glm::vec3& dir, int w, int h) {
  const glm::vec2 uv = equirectUV(dir) * glm::vec2(w, h);
  const glm::vec2 f = uv - glm::floor(uv);
  return std::min({f.x, 1.0f - f.x, f.y, 1.0f - f.y});
}

// 1. The same u gives the CPU sampler's direction (1e-4) and pdf (1e-3 relative); the pdf of
// the sampled direction is the sample's pdf; the radiance is the CPU's bilinear lookup.
void expectMatchesCpu(const Environment& env, const std::vector<glm::vec2>& us,
                      const std::vector<GpuResult>& gpu) {
  const EnvironmentSampler cpu = cpuSampler(env);
  const Environment map = asMap(env);
  int nearEdge = 0;
  for (size_t i = 0; i < us.size(); ++i) {
    const EnvironmentSampler::Sample s = cpu.sample(us[i].x, us[i].y);
    const GpuResult& g = gpu[i];
    ASSERT_LE(maxAbsDiff(g.direction, s.direction), 1e-4f)
        << "u " << us[i].x << "," << us[i].y << " texel " << s.pixel;
    ASSERT_NEAR(g.pdf, s.pdf, 1e-3f * s.pdf) << "u " << us[i].x << "," << us[i].y;
    ASSERT_GT(g.pdf, 0.0f);
    expectLookup(map, g.direction, g.radiance);
    if (::testing::Test::HasFailure()) return;  // one sample's report, not thousands
    // A direction within float rounding of a texel edge may land in the neighbour.
    if (edgeDistance(s.direction, cpu.width(), cpu.height()) < 1e-3f) {
      ++nearEdge;
      continue;
    }
    ASSERT_NEAR(g.pdfAtDirection, g.pdf, 1e-6f * g.pdf) << "u " << us[i].x << "," << us[i].y;
    ASSERT_NEAR(g.pdfAtDirection, cpu.pdf(g.direction), 1e-6f * g.pdf);
  }
  EXPECT_LT(nearEdge, int(us.size() / 100)) << "too few samples checked against environmentPdf";
}

TEST_F(EnvironmentGpuTest, SamplesMatchCpuSamplerOnSunMap) {
  const Environment env = sunMap();
  const EnvironmentGpu gpu(ctx(), env);
  const std::vector<glm::vec2> us = uGrid(64);
  expectMatchesCpu(env, us, run(gpu, us));
}

TEST_F(EnvironmentGpuTest, SamplesMatchCpuSamplerOnProceduralSky) {
  const Environment env = skyEnv();
  const EnvironmentGpu gpu(ctx(), env);
  EXPECT_EQ(gpu.width(), uint32_t(kTabulatedWidth));
  EXPECT_EQ(gpu.height(), uint32_t(kTabulatedHeight));
  const std::vector<glm::vec2> us = uGrid(64);
  expectMatchesCpu(env, us, run(gpu, us));
}

// 2. Binned per texel, 2^18 random samples follow the texel probabilities: Pearson's
// chi-square over bins expecting >= 5 samples (the rest pooled) stays under dof + 5 sqrt(2 dof)
// (about p = 1e-4 for this dof; the seed is fixed, so the test is deterministic), and the
// sun texel's share is within 5 binomial sigmas. Zero-probability texels get no sample.
TEST_F(EnvironmentGpuTest, SampleHistogramFollowsTexelProbabilities) {
  const Environment env = sunMap();
  const EnvironmentGpu gpu(ctx(), env);
  const EnvironmentSampler cpu(env);
  const size_t n = size_t(1) << 18;
  const std::vector<GpuResult> samples = run(gpu, uRandom(n, 12345));
  std::vector<double> count(size_t(kW) * kH, 0.0);
  for (const GpuResult& s : samples) {
    ASSERT_TRUE(finite(s.direction));
    const glm::vec2 uv = equirectUV(s.direction);
    const int x = std::clamp(int(uv.x * kW), 0, kW - 1), y = std::clamp(int(uv.y * kH), 0, kH - 1);
    count[size_t(y) * kW + x] += 1.0;
  }
  double chi2 = 0.0, pooledExpected = 0.0, pooledCount = 0.0, probSum = 0.0;
  int bins = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double p = double(cpu.texelPdf(x, y)) * solidAngle(y, kW, kH);
      const double expected = p * double(n), seen = count[size_t(y) * kW + x];
      probSum += p;
      if (p == 0.0) {
        EXPECT_EQ(seen, 0.0) << "texel " << x << "," << y << " has probability 0";
      } else if (expected < 5.0) {
        pooledExpected += expected;
        pooledCount += seen;
      } else {
        chi2 += (seen - expected) * (seen - expected) / expected;
        ++bins;
      }
    }
  if (pooledExpected > 0.0) {
    chi2 += (pooledCount - pooledExpected) * (pooledCount - pooledExpected) / pooledExpected;
    ++bins;
  }
  EXPECT_NEAR(probSum, 1.0, 1e-4);
  const double dof = bins - 1;
  EXPECT_GT(dof, 1000.0);
  EXPECT_LT(chi2, dof + 5.0 * std::sqrt(2.0 * dof)) << "dof " << dof;
  const double pSun = double(cpu.texelPdf(kSunX, kSunY)) * solidAngle(kSunY, kW, kH);
  EXPECT_GT(pSun, 0.2);
  EXPECT_NEAR(count[size_t(kSunY) * kW + kSunX] / double(n), pSun,
              5.0 * std::sqrt(pSun * (1.0 - pSun) / double(n)));
}

// 3. A black map samples uniformly (1 / 4pi, like the CPU fallback); u at or past the ends,
// NaN u, the poles and degenerate probe directions stay finite.
TEST_F(EnvironmentGpuTest, BlackMapIsUniformAndEdgesStayFinite) {
  Environment env = sunMap();
  std::fill(env.mapRGB.begin(), env.mapRGB.end(), 0.0f);
  const EnvironmentGpu gpu(ctx(), env);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<glm::vec2> us = uGrid(32);
  const std::vector<glm::vec2> edges = {{0.0f, 0.0f},  {0.99999994f, 0.99999994f},
                                        {1.0f, 1.0f},  {0.0f, 0.99999994f},
                                        {1.5f, -0.5f}, {nan, nan},
                                        {nan, 0.25f},  {0.99999994f, 0.0f}};
  us.insert(us.end(), edges.begin(), edges.end());
  const std::vector<glm::vec4> probes = {{0, 1, 0, 0},      {0, -1, 0, 0},    {0, 0, 0, 0},
                                         {nan, 0, 0, 0},    {inf, 1, 0, 0},   {1e30f, 1e30f, 0, 0},
                                         {1e-30f, 0, 0, 0}, {0, 1e-40f, 0, 0}};
  const std::vector<GpuResult> r = run(gpu, us, probes);
  const float uniform = 1.0f / (4.0f * kPi);
  for (size_t i = 0; i < r.size(); ++i) {
    ASSERT_TRUE(finite(r[i].direction)) << "sample " << i;
    EXPECT_NEAR(glm::length(r[i].direction), 1.0f, 1e-5f) << "sample " << i;
    EXPECT_NEAR(r[i].pdf, uniform, 1e-3f * uniform) << "sample " << i;
    EXPECT_NEAR(r[i].pdfAtDirection, uniform, 1e-3f * uniform) << "sample " << i;
    EXPECT_EQ(r[i].radiance, glm::vec3(0.0f)) << "sample " << i;
    EXPECT_NEAR(r[i].probePdf, uniform, 1e-3f * uniform) << "probe " << i;
    EXPECT_EQ(r[i].probeRadiance, glm::vec3(0.0f)) << "probe " << i;
  }
  // u.x = 0 starts at the north pole; u.x just below 1 ends within one ulp of the south pole.
  const size_t e = us.size() - edges.size();
  EXPECT_EQ(r[e].direction.y, 1.0f);
  EXPECT_LT(r[e + 1].direction.y, -0.9999f);
  EXPECT_NEAR(r[e + 1].direction.y, r[e + 2].direction.y, 1e-6f) << "u = 1 reads as 1 - eps";
}

// The sun map's poles and degenerate probes: finite pdf and radiance, equal to the CPU's.
TEST_F(EnvironmentGpuTest, SunMapPolesAreFiniteAndMatchCpu) {
  const Environment env = sunMap();
  const EnvironmentGpu gpu(ctx(), env);
  const EnvironmentSampler cpu(env);
  const std::vector<glm::vec4> probes = {{0, 1, 0, 0}, {0, -1, 0, 0}, {0, 0, 0, 0}};
  const std::vector<GpuResult> r =
      run(gpu, {{0.0f, 0.5f}, {0.99999994f, 0.5f}, {0.5f, 0.5f}}, probes);
  for (size_t i = 0; i < probes.size(); ++i) {
    ASSERT_TRUE(finite(r[i].direction) && std::isfinite(r[i].pdf)) << i;
    ASSERT_TRUE(finite(r[i].probeRadiance) && std::isfinite(r[i].probePdf)) << i;
    EXPECT_NEAR(r[i].probePdf, cpu.pdf(glm::vec3(probes[i])),
                1e-6f * cpu.pdf(glm::vec3(probes[i])));
    const glm::vec3 L = environmentLookup(env, glm::vec3(probes[i]));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(r[i].probeRadiance[c], L[c], 1e-4f * (1.0f + L[c]));
  }
}

// Pole rows of a tall map have tiny solid angles (1 - cos(pi / 16384) rounds to 0 in float):
// their pdf stays finite and positive on both sides.
TEST_F(EnvironmentGpuTest, TallMapPoleRowsHaveFinitePdf) {
  const int h = 16384;
  if (ctx().properties().limits.maxImageDimension2D < uint32_t(h))
    GTEST_SKIP() << "device limits images to " << ctx().properties().limits.maxImageDimension2D;
  Environment env;
  env.kind = Environment::Kind::Map;
  env.mapWidth = 2;
  env.mapHeight = h;
  env.mapRGB.assign(size_t(2) * h * 3, 1.0f);
  const EnvironmentGpu gpu(ctx(), env);
  const std::vector<GpuResult> r =
      run(gpu, {{0.0f, 0.0f}, {0.99999994f, 0.5f}}, {{0, 1, 0, 0}, {0, -1, 0, 0}});
  const float uniform = 1.0f / (4.0f * kPi);
  for (const GpuResult& s : r) {
    ASSERT_TRUE(finite(s.direction));
    EXPECT_NEAR(s.pdf, uniform, 1e-3f * uniform);
    EXPECT_NEAR(s.probePdf, uniform, 1e-3f * uniform);
  }
}

// Constant environments sample uniformly and return the colour times the intensity; a Map
// whose texels do not match its size is black (as environmentLookup sees it), 1x1, uniform.
TEST_F(EnvironmentGpuTest, ConstantAndBrokenMapEnvironments) {
  Environment constant;
  constant.kind = Environment::Kind::Constant;
  constant.constantColor = {0.5f, 1.0f, 2.0f};
  constant.intensity = 3.0f;
  const EnvironmentGpu gpu(ctx(), constant);
  const float uniform = 1.0f / (4.0f * kPi);
  for (const GpuResult& s : run(gpu, uGrid(16))) {
    EXPECT_NEAR(s.pdf, uniform, 1e-3f * uniform);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.radiance[c], 3.0f * constant.constantColor[c], 1e-5f);
  }
  Environment broken = sunMap();
  broken.mapRGB.resize(10);
  const EnvironmentGpu black(ctx(), broken);
  EXPECT_EQ(black.width(), 1u);
  EXPECT_EQ(black.height(), 1u);
  for (const GpuResult& s : run(black, uGrid(8))) {
    EXPECT_NEAR(s.pdf, uniform, 1e-3f * uniform);
    EXPECT_EQ(s.radiance, glm::vec3(0.0f));
  }
  for (int i = 0; i < 9; ++i) EXPECT_EQ(black.irradiance()[i], glm::vec3(0.0f));
}

// A map wider than the device's images can be fails with a clear error, before any upload.
TEST_F(EnvironmentGpuTest, OversizedMapIsAClearError) {
  Environment env;
  env.kind = Environment::Kind::Map;
  env.file = "huge.hdr";
  env.mapWidth = int(ctx().properties().limits.maxImageDimension2D) + 1;
  env.mapHeight = 1;
  env.mapRGB.assign(size_t(env.mapWidth) * 3, 1.0f);
  try {
    EnvironmentGpu gpu(ctx(), env);
    FAIL() << "expected gi::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Unsupported);
    EXPECT_NE(std::string(e.what()).find("huge.hdr"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("maxImageDimension2D"), std::string::npos) << e.what();
  }
}

// 4. Unbiasedness: the importance-sampled estimate of E(n) = integral L max(0, n.w) dw with
// 2^18 GPU samples equals, for a smooth sky, (a) a dense CPU quadrature of the same bilinear
// map within 1% (Monte Carlo noise) and (b) the SH9 irradiance the renderer lights with within
// 3% (SH9's band limit on the sky's kink at the horizon).
TEST_F(EnvironmentGpuTest, MonteCarloIrradianceMatchesSH9OfSmoothSky) {
  const Environment env = skyEnv();
  const EnvironmentGpu gpu(ctx(), env);
  const Environment map = asMap(env);
  const size_t n = size_t(1) << 18;
  const std::vector<GpuResult> samples = run(gpu, uRandom(n, 777));
  const std::vector<glm::vec3> normals = {{0, 1, 0},
                                          {0, -1, 0},
                                          {1, 0, 0},
                                          {0, 0, -1},
                                          glm::normalize(glm::vec3(0.3f, 0.8f, -0.5f)),
                                          glm::normalize(glm::vec3(-0.4f, -0.6f, 0.7f))};
  for (const glm::vec3& nrm : normals) {
    glm::dvec3 mc(0.0);
    for (const GpuResult& s : samples)
      mc += glm::dvec3(s.radiance) * double(std::max(0.0f, glm::dot(nrm, s.direction))) /
            double(s.pdf);
    mc /= double(n);
    // Midpoint quadrature on a grid 4x finer than the map (the bilinear map is smooth).
    glm::dvec3 quad(0.0);
    const int qw = 4 * kTabulatedWidth, qh = 4 * kTabulatedHeight;
    for (int y = 0; y < qh; ++y)
      for (int x = 0; x < qw; ++x) {
        const glm::vec3 d = equirectDirection({(x + 0.5f) / qw, (y + 0.5f) / qh});
        quad += glm::dvec3(environmentLookup(map, d)) * double(std::max(0.0f, glm::dot(nrm, d))) *
                solidAngle(y, qw, qh);
      }
    const glm::vec3 sh = evalIrradiance(gpu.irradiance(), nrm);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(mc[c], quad[c], 0.01 * quad[c])
          << "normal " << nrm.x << "," << nrm.y << "," << nrm.z << " channel " << c;
      EXPECT_NEAR(mc[c], sh[c], 0.03 * sh[c])
          << "normal " << nrm.x << "," << nrm.y << "," << nrm.z << " channel " << c;
    }
  }
}

// 5. The map holds the renderer's upload (RGBA32F, the scene's texels, alpha 1) for maps and
// the tabulated radiance (no intensity) for Sky; the SH9 is irradianceSH(env), bit for bit.
TEST_F(EnvironmentGpuTest, MapAndSHEqualTheRenderersUpload) {
  const Environment env = sunMap();
  const EnvironmentGpu gpu(ctx(), env);
  ASSERT_EQ(gpu.width(), uint32_t(kW));
  ASSERT_EQ(gpu.height(), uint32_t(kH));
  EXPECT_EQ(gpu.map().desc().format, VK_FORMAT_R32G32B32A32_SFLOAT);
  const std::vector<float> texels = readMap(gpu);
  for (size_t i = 0; i < size_t(kW) * kH; ++i) {
    for (int c = 0; c < 3; ++c) ASSERT_EQ(texels[i * 4 + c], env.mapRGB[i * 3 + c]) << i;
    ASSERT_EQ(texels[i * 4 + 3], 1.0f);
  }
  const SH9 expected = irradianceSH(env);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(gpu.irradiance()[i], expected[i]) << "SH " << i;
  const EnvironmentGpu::Layout l = EnvironmentGpu::layout(kW, kH);
  EXPECT_EQ(gpu.samplingBytes(), 32u + l.floats * sizeof(float));
  EXPECT_EQ(l.floats, uint32_t(2 * (kH + 1) + kH * (kW + 1) + kW * kH));

  const Environment sky = skyEnv();
  const EnvironmentGpu skyGpu(ctx(), sky);
  Environment unit = sky;
  unit.intensity = 1.0f;
  const std::vector<float> skyTexels = readMap(skyGpu);
  for (int y = 0; y < kTabulatedHeight; ++y)
    for (int x = 0; x < kTabulatedWidth; ++x) {
      const glm::vec3 L = environmentLookup(
          unit, equirectDirection({(x + 0.5f) / kTabulatedWidth, (y + 0.5f) / kTabulatedHeight}));
      const float* t = &skyTexels[(size_t(y) * kTabulatedWidth + x) * 4];
      ASSERT_EQ(glm::vec3(t[0], t[1], t[2]), L) << x << "," << y;
    }
  const SH9 skySH = irradianceSH(sky);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(skyGpu.irradiance()[i], skySH[i]) << "SH " << i;
}

}  // namespace
}  // namespace gi
