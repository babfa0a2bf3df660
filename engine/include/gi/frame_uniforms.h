// The per-view uniforms every engine and effect shader sees as `FrameUniforms` (common.glsl,
// std140). The main camera has one buffer (EffectContext::frameUniforms()); each extra view an
// effect creates (EffectContext::createView()) has its own with the same layout. Only vec4 and
// mat4 members, so the C++ layout equals std140 and std430.
#pragma once

#include <glm/glm.hpp>

namespace gi {

struct FrameUniforms {
  glm::mat4 view, proj, viewProj, invView, invProj, prevViewProj;
  glm::vec4 viewport;    // width, height, 1/width, 1/height
  glm::vec4 cameraPos;   // world space
  glm::vec4 skyZenith;   // rgb, intensity (environment intensity x engine.environment_intensity)
  glm::vec4 skyHorizon;  // rgb, environment kind (0 sky, 1 constant, 2 map)
  glm::vec4 skyGround;   // rgb (constant colour when kind is 1)
  glm::vec4 params;      // exposure, light count, near, far
  glm::vec4 irradianceSH[9];  // rgb: SH9 irradiance (gi::irradianceSH), world space, intensity in
  glm::vec4 time;             // seconds (animation clock), frame index, seconds since last frame, 0
  glm::vec4 options;          // PCF radius in texels, 0, 0, 0
};

static_assert(sizeof(FrameUniforms) == 6 * sizeof(glm::mat4) + 17 * sizeof(glm::vec4),
              "std140 mirror of common.glsl");

}  // namespace gi
