#include "render/environment_gpu.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "gi/errors.h"

namespace gi {

namespace {

constexpr VkDeviceSize kHeaderBytes = 32;  // uvec4 header + vec4 scale

}  // namespace

EnvironmentGpu::Layout EnvironmentGpu::layout(uint32_t width, uint32_t height) {
  Layout l{};
  l.marginal = 0;
  l.conditional = l.marginal + height + 1;
  l.texelPdf = l.conditional + height * (width + 1);
  l.rowCos = l.texelPdf + width * height;
  l.floats = l.rowCos + height + 1;
  return l;
}

EnvironmentGpu::EnvironmentGpu(vk::Context& ctx, const Environment& env) {
  // The radiance map without intensity: the scene's map, or Sky/Constant tabulated.
  int w = 1, h = 1;
  std::vector<float> tabulated;
  const std::vector<float>* rgb = &tabulated;
  if (env.kind == Environment::Kind::Map) {
    if (env.mapWidth > 0 && env.mapHeight > 0 &&
        env.mapRGB.size() == size_t(env.mapWidth) * env.mapHeight * 3) {
      w = env.mapWidth;
      h = env.mapHeight;
      rgb = &env.mapRGB;
      kind_ = 2;
    } else {
      tabulated.assign(3, 0.0f);  // what environmentLookup returns for a broken map
    }
  } else {
    kind_ = env.kind == Environment::Kind::Constant ? 1 : 0;
    w = kTabulatedWidth;
    h = kTabulatedHeight;
    tabulated = tabulateEnvironment(env, w, h);
  }
  width_ = uint32_t(w);
  height_ = uint32_t(h);
  irradiance_ = irradianceSH(env);

  // Sizes in 64 bits first: a huge map must fail clearly, not wrap the offsets.
  const uint64_t floats =
      2ull * (uint64_t(h) + 1) + uint64_t(h) * (uint64_t(w) + 1) + uint64_t(w) * uint64_t(h);
  const uint64_t bytes = kHeaderBytes + floats * sizeof(float);
  const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
  if (width_ > limits.maxImageDimension2D || height_ > limits.maxImageDimension2D)
    throw Error(ErrorKind::Unsupported, env.file,
                "environment map " + std::to_string(w) + "x" + std::to_string(h) +
                    " exceeds this device's maxImageDimension2D (" +
                    std::to_string(limits.maxImageDimension2D) + ")");
  const uint64_t range = limits.maxStorageBufferRange;
  if (bytes > range)
    throw Error(ErrorKind::Unsupported, env.file,
                "environment map " + std::to_string(w) + "x" + std::to_string(h) + " needs a " +
                    std::to_string(bytes) +
                    "-byte sampling buffer, more than this device's maxStorageBufferRange (" +
                    std::to_string(range) + " bytes)");

  // Same tables as the CPU sampler, so the GPU's binary search picks the same texels.
  const EnvironmentSampler sampler(w, h, *rgb);
  const Layout l = layout(width_, height_);
  std::vector<float> data(l.floats, 0.0f);
  std::copy(sampler.marginalCdf().begin(), sampler.marginalCdf().end(), data.begin() + l.marginal);
  std::copy(sampler.conditionalCdf().begin(), sampler.conditionalCdf().end(),
            data.begin() + l.conditional);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) data[l.texelPdf + size_t(y) * w + x] = sampler.texelPdf(x, y);
  for (int y = 0; y <= h; ++y) data[l.rowCos + size_t(y)] = sampler.rowCosTheta(y);

  std::vector<char> bytesOut(kHeaderBytes + data.size() * sizeof(float));
  const uint32_t header[4] = {width_, height_, kind_, 0};
  const float scale[4] = {std::max(env.intensity, 0.0f), 0.0f, 0.0f, 0.0f};
  std::memcpy(bytesOut.data(), header, sizeof header);
  std::memcpy(bytesOut.data() + sizeof header, scale, sizeof scale);
  std::memcpy(bytesOut.data() + kHeaderBytes, data.data(), data.size() * sizeof(float));
  sampling_ = vk::createDeviceBuffer(ctx, bytesOut.data(), bytesOut.size(),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

  // RGBA32F as the renderer uploads it (alpha 1); TRANSFER_SRC so tests can read it back.
  std::vector<float> rgba(size_t(w) * h * 4, 1.0f);
  for (size_t i = 0; i < size_t(w) * h; ++i)
    for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = (*rgb)[i * 3 + c];
  vk::ImageDesc desc;
  desc.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  desc.width = width_;
  desc.height = height_;
  desc.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
               VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  map_ = vk::Image(ctx, desc);
  vk::uploadImage(ctx, map_, rgba.data(), rgba.size() * sizeof(float));
}

}  // namespace gi
