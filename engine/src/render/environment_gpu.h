// The scene's environment on the GPU: its equirect radiance map, the importance-sampling
// tables of gi::EnvironmentSampler and its SH9 irradiance. Shaders read the map and the tables
// through engine/shaders/environment.glsl (sampleEnvironment, environmentPdf,
// environmentMapRadiance), which also documents the sampling buffer's layout.
#pragma once

#include <cstdint>

#include "gi/environment.h"
#include "gi/vk/resources.h"

namespace gi {

class EnvironmentGpu {
 public:
  // Uploads everything once (the environment does not change while a renderer lives). Throws
  // gi::Error (Unsupported) when the sampling tables exceed the device's storage-buffer range.
  EnvironmentGpu(vk::Context& ctx, const Environment& env);

  // Equirect RGBA32F radiance (alpha 1), intensity NOT applied (like Environment::mapRGB),
  // SHADER_READ_ONLY_OPTIMAL. Kind Map: the map itself (a 1x1 black map when mapRGB does not
  // match its size, as environmentLookup sees it); Sky and Constant: tabulated at
  // kTabulatedWidth x kTabulatedHeight exactly as irradianceSH() does, so every kind samples.
  const vk::Image& map() const { return map_; }
  // std430 storage buffer (layout in environment.glsl): header, intensity, the CDFs searched
  // by sampleEnvironment, the per-texel pdf and the rows' cos(theta).
  VkBuffer samplingBuffer() const { return sampling_.handle(); }
  VkDeviceSize samplingBytes() const { return sampling_.size(); }
  const SH9& irradiance() const { return irradiance_; }  // gi::irradianceSH(env)
  // What shaders light with (FrameUniforms.skyHorizon.w): 0 the procedural sky (also a map whose
  // texels do not match its size), 1 the constant colour, 2 the equirect map.
  uint32_t kind() const { return kind_; }
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }

  // Float offsets of the tables in the buffer's data[] array (after the 32-byte header).
  struct Layout {
    uint32_t marginal, conditional, texelPdf, rowCos, floats;
  };
  static Layout layout(uint32_t width, uint32_t height);

 private:
  vk::Image map_;
  vk::Buffer sampling_;
  SH9 irradiance_{};
  uint32_t width_ = 1, height_ = 1, kind_ = 0;
};

}  // namespace gi
