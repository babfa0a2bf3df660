#include "render/view_uniforms.h"

#include <algorithm>

namespace gi {

void setCamera(FrameUniforms& f, const CameraView& c, VkExtent2D extent,
               const glm::mat4& prevViewProj) {
  f.view = c.view;
  f.proj = c.proj;
  f.viewProj = c.proj * c.view;
  f.invView = glm::inverse(c.view);
  f.invProj = glm::inverse(c.proj);
  f.prevViewProj = prevViewProj;
  const float w = float(std::max(extent.width, 1u)), h = float(std::max(extent.height, 1u));
  f.viewport = glm::vec4(w, h, 1.0f / w, 1.0f / h);
  f.cameraPos = glm::vec4(c.position, 1.0f);
  f.params.z = c.znear;
  f.params.w = c.zfar;
}

FrameUniforms mainViewUniforms(const RenderSettings& settings, const Environment& e,
                               const EnvironmentGpu& environmentGpu, uint32_t lightCount,
                               const CameraView& camera, const glm::mat4& prevViewProj,
                               const FrameClock& clock) {
  FrameUniforms f{};
  const bool constant = e.kind == Environment::Kind::Constant;
  const float kind = float(environmentGpu.kind());
  const float scale = std::max(settings.environmentIntensity, 0.0f);
  f.skyZenith = glm::vec4(e.zenithColor, std::max(e.intensity, 0.0f) * scale);
  f.skyHorizon = glm::vec4(e.horizonColor, kind);
  f.skyGround = glm::vec4(constant ? e.constantColor : e.groundColor, 0.0f);
  f.params = glm::vec4(settings.exposure, float(lightCount), 0.0f, 0.0f);
  setCamera(f, camera, {settings.width, settings.height}, prevViewProj);
  const SH9& sh = environmentGpu.irradiance();
  for (int i = 0; i < 9; ++i) f.irradianceSH[i] = glm::vec4(sh[i] * scale, 0.0f);
  const bool first = clock.framesRendered == 0;
  f.time = glm::vec4(float(clock.seconds), float(clock.framesRendered),
                     first ? 0.0f : float(clock.seconds - clock.previousSeconds), 0.0f);
  f.options = glm::vec4(float(settings.pcfRadius), 0.0f, 0.0f, 0.0f);
  return f;
}

ExtraViewUniforms::ExtraViewUniforms(vk::Context& ctx)
    : buffer_(ctx, sizeof(FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true) {}

void ExtraViewUniforms::setCamera(const CameraView& camera, VkExtent2D extent) {
  camera_ = camera;
  extent_ = extent;
}

void ExtraViewUniforms::refresh(const FrameUniforms& main) {
  const glm::mat4 viewProj = camera_.proj * camera_.view;
  data_ = main;
  gi::setCamera(data_, camera_, extent_, seen_ ? prevViewProj_ : viewProj);
  buffer_.write(&data_, sizeof data_);
  prevViewProj_ = viewProj;
  seen_ = true;
}

}  // namespace gi
