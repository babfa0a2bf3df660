// CPU mirrors of the shader-side structs (engine/shaders/*.glsl). Only vec4/mat4 members so
// std140/std430 layouts equal the C++ layout.
#pragma once

#include <glm/glm.hpp>

namespace gi::gpu {

struct FrameUniforms {
  glm::mat4 view, proj, viewProj, invView, invProj, prevViewProj;
  glm::vec4 viewport;         // width, height, 1/width, 1/height
  glm::vec4 cameraPos;        // world space
  glm::vec4 skyZenith;        // rgb, intensity
  glm::vec4 skyHorizon;       // rgb, environment kind (0 sky, 1 constant, 2 map)
  glm::vec4 skyGround;        // rgb (constant colour when kind is 1)
  glm::vec4 params;           // exposure, light count, near, far
  glm::vec4 irradianceSH[9];  // rgb: SH9 irradiance (gi::irradianceSH), world space
};

struct Instance {
  glm::mat4 model, prevModel;
  glm::mat4 normalMatrix;
  glm::uvec4 material;
};

struct Material {
  glm::vec4 baseColor;
  glm::vec4 emission;
  glm::vec4 params;  // roughness, metallic, texture index (-1 none)
};

struct Light {
  glm::vec4 positionRange;
  glm::vec4 directionType;
  glm::vec4 radiance;
  glm::vec4 cone;
  glm::vec4 shadow;  // first shadow view (-1 none), bias constant, bias slope, map slot
};

// One rendered shadow view: a directional/spot map or one cube face of a point light.
struct ShadowView {
  glm::mat4 viewToClip;  // camera view space -> light clip space (reverse-Z)
  glm::vec4 params;      // perspective (1) / orthographic (0), near, far, texel footprint
  glm::vec4 tile;        // texel offset x, y, size
};

static_assert(sizeof(FrameUniforms) == 6 * 64 + 6 * 16 + 9 * 16);
static_assert(sizeof(Instance) == 3 * 64 + 16);

}  // namespace gi::gpu
