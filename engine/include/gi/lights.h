// Lights and shadow maps as the engine publishes them to effects: the GPU records (lights.glsl
// reads them), the world-space description of the current pose, and the frame-graph names.
//
// Blackboard (every frame): uniform buffer "lights" (GpuLight per light, camera view space, count
// in FrameUniforms.params.y; kMaxLights records), uniform buffer "shadow_views" (GpuShadowView,
// kMaxShadowViews records), texture "shadow_maps" (D32
// reverse-Z 2-D array, one layer per shadowed light; a 1x1 one-layer array cleared to "no
// occluder" when no light casts shadows). lights.glsl: Light, ShadowView, shadowFactor().
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

namespace resources {
inline constexpr const char* kLights = "lights";
inline constexpr const char* kShadowViews = "shadow_views";
inline constexpr const char* kShadowMaps = "shadow_maps";
}  // namespace resources

// Sizes of the two uniform buffers (lights.glsl's GI_MAX_LIGHTS and GI_MAX_SHADOW_VIEWS): uniform,
// not storage, buffers because llvmpipe loads storage buffers lane by lane. 160 views of 96 bytes
// fit the 16 KiB every Vulkan device offers; a point light takes six views, any other one.
inline constexpr uint32_t kMaxLights = 128;
inline constexpr uint32_t kMaxShadowViews = 160;

// std140 (= std430 here: vec4 members only) mirror of `Light` in lights.glsl.
struct GpuLight {
  glm::vec4 positionRange;  // camera view-space position, range (0: infinite)
  glm::vec4
      directionType;   // view-space direction the light points to, type (0 dir, 1 point, 2 spot)
  glm::vec4 radiance;  // colour x intensity (lux for directional, candela otherwise)
  glm::vec4 cone;      // cos(inner), cos(outer)
  glm::vec4 shadow;    // first shadow view (-1: unshadowed), bias constant, bias slope, layer
};

// One rendered shadow view: a directional/spot map or one cube face of a point light (the six
// faces of a point light share its layer as a 3x2 atlas).
struct GpuShadowView {
  glm::mat4 viewToClip;  // camera view space -> light clip space (reverse-Z)
  glm::vec4 params;      // perspective (1) / orthographic (0), near, far, texel footprint
  glm::vec4 tile;        // texel offset x, y, size of the view inside its layer
};

// A light of the current pose in world space (EffectContext::lights()), e.g. to draw its
// reflective shadow map with GpuScene::drawRsm or to sample it in an effect.
struct LightInfo {
  LightType type = LightType::Point;
  glm::vec3 position{0.0f};                // world (point, spot)
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  // world, unit: where the light points
  glm::vec3 radiance{1.0f};                // colour x intensity
  float range = 0.0f;                      // 0: infinite
  float cosInner = 1.0f, cosOuter = 0.0f;  // spot cone
  int shadowLayer = -1;                    // layer in "shadow_maps", -1: no shadow map
  uint32_t index = 0;                      // its record in "lights"
};

static_assert(sizeof(GpuLight) == 5 * sizeof(glm::vec4));
static_assert(sizeof(GpuShadowView) == sizeof(glm::mat4) + 2 * sizeof(glm::vec4));

}  // namespace gi
