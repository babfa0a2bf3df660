// The packed G-buffer's layout on the C++ side: its targets and formats, and the same encoding
// as engine/shaders/gbuffer.glsl (the one GLSL interface every shader reads it through), for
// code that packs or unpacks texels on the CPU (tests, read-backs).
//
// Precision (tests/test_gbuffer_layout.cpp checks each bound):
//   normal    octahedral, 2 x 16-bit snorm: angle error below kNormalMaxErrorDeg
//   albedo    8-bit sRGB codes: the value an sRGB8 target would hold, exactly
//   roughness, metallic  8-bit unorm (error <= 1/510)
//   emission  RGB9E5: each channel within 2^-9 of the largest channel (relative) when that is
//             at least 2^-15, within 2^-24 (absolute) below; finite values up to kMaxEmission;
//             NaN and negatives become 0, larger values kMaxEmission
//   motion    RG16F UV units: relative error <= 2^-11 (0.03 pixel at 64 pixels of motion, at
//             any resolution); 0 exactly for a still pixel
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/image_io.h"

namespace gi::gbuffer {

// The targets the G-buffer pass writes besides depth (colour attachment order).
inline constexpr VkFormat kPackedFormat = VK_FORMAT_R32G32B32A32_UINT;  // resource "gbuffer"
inline constexpr VkFormat kMotionFormat = VK_FORMAT_R16G16_SFLOAT;      // resource "motion"

inline constexpr uint32_t kGeometryBit = 0x100u;
inline constexpr float kMaxEmission = 65408.0f;
inline constexpr double kNormalMaxErrorDeg = 0.004;

// One decoded texel.
struct Texel {
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  // unit, view space
  glm::vec3 albedo{0.0f};              // linear
  float roughness = 0.0f, metallic = 0.0f;
  glm::vec3 emission{0.0f};  // linear radiance
  bool geometry = false;
};

// The decoded channels the engine offers as views and read-backs (a pass unpacks each on
// request, "gbuffer_<name>"): RGBA32F normal (w 1 on geometry), albedo (w 1), material
// (roughness, metallic, 0, 1), emission (w 1).
inline constexpr std::array<const char*, 4> kChannels = {"normal", "albedo", "material",
                                                         "emission"};

glm::uvec4 encode(const Texel& t);
Texel decode(const glm::uvec4& bits);
// Channel `channel` (kChannels order) of `width` x `height` packed texels (16 bytes each, rows
// tightly packed) as the RGBA32F image the unpacking pass writes.
ImageRGBA32F unpackChannel(const std::vector<uint8_t>& texels, int width, int height,
                           size_t channel);

// The pieces, as gbuffer.glsl names them.
uint32_t encodeNormal(const glm::vec3& n);
glm::vec3 decodeNormal(uint32_t bits);
uint32_t encodeRgb9e5(const glm::vec3& c);
glm::vec3 decodeRgb9e5(uint32_t bits);
uint8_t linearToSrgb8(float c);
float srgb8ToLinear(uint8_t code);

}  // namespace gi::gbuffer
