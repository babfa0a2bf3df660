// The camera uniforms every pass reads (FrameUniforms, common.glsl's Frame block): the main
// view's, built once per frame from the renderer's state, and the extra views effects ask for
// (EffectContext::createView), which copy the main view's frame-wide values.
#pragma once

#include <cstdint>

#include <vulkan/vulkan.h>

#include "gi/effect.h"
#include "gi/frame_uniforms.h"
#include "gi/render_settings.h"
#include "gi/vk/resources.h"
#include "render/environment_gpu.h"

namespace gi {

// The animation clock as the shaders see it (FrameUniforms::time).
struct FrameClock {
  double seconds = 0.0, previousSeconds = 0.0;  // this frame's and the last rendered frame's
  uint64_t framesRendered = 0;
};

// The camera part of a view's uniforms: matrices, viewport, position, depth range.
void setCamera(FrameUniforms& f, const CameraView& camera, VkExtent2D extent,
               const glm::mat4& prevViewProj);

// The main view's uniforms: environment (scaled by engine.environment_intensity), exposure,
// light count, camera (motion against `prevViewProj`), clock, PCF radius.
FrameUniforms mainViewUniforms(const RenderSettings& settings, const Environment& environment,
                               const EnvironmentGpu& environmentGpu, uint32_t lightCount,
                               const CameraView& camera, const glm::mat4& prevViewProj,
                               const FrameClock& clock);

// An extra view's uniforms: the main view's frame-wide values with this view's camera.
class ExtraViewUniforms final : public ViewUniforms {
 public:
  explicit ExtraViewUniforms(vk::Context& ctx);
  void setCamera(const CameraView& camera, VkExtent2D extent) override;
  VkBuffer buffer() const override { return buffer_.handle(); }
  const FrameUniforms& current() const override { return data_; }
  // Called by the renderer before each frame; motion is against the last refreshed camera.
  void refresh(const FrameUniforms& main);
  void forgetHistory() { seen_ = false; }  // no motion into the next frame (resize)

 private:
  vk::Buffer buffer_;
  CameraView camera_;
  VkExtent2D extent_{1, 1};
  FrameUniforms data_{};
  glm::mat4 prevViewProj_{1.0f};
  bool seen_ = false;
};

}  // namespace gi
