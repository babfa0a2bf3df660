// The CPU twin of engine/shaders/gbuffer.glsl: the same operations in the same order.
#include "gi/gbuffer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace gi::gbuffer {

namespace {

glm::vec2 octWrap(glm::vec2 v) {
  return (1.0f - glm::abs(glm::vec2(v.y, v.x))) *
         glm::vec2(v.x >= 0.0f ? 1.0f : -1.0f, v.y >= 0.0f ? 1.0f : -1.0f);
}

}  // namespace

uint32_t encodeNormal(const glm::vec3& n) {
  const float l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  if (!(l1 > 1e-30f) || std::isinf(l1))
    return glm::packSnorm2x16(glm::vec2(0.0f));  // GLSL's packing
  const glm::vec3 p = n / l1;
  return glm::packSnorm2x16(p.z >= 0.0f ? glm::vec2(p.x, p.y) : octWrap(glm::vec2(p.x, p.y)));
}

glm::vec3 decodeNormal(uint32_t bits) {
  const glm::vec2 e = glm::unpackSnorm2x16(bits);
  glm::vec3 n(e, 1.0f - std::abs(e.x) - std::abs(e.y));
  if (n.z < 0.0f) {
    const glm::vec2 w = octWrap(glm::vec2(n.x, n.y));
    n.x = w.x;
    n.y = w.y;
  }
  return glm::normalize(n);
}

uint32_t encodeRgb9e5(const glm::vec3& in) {
  glm::vec3 c;
  for (int i = 0; i < 3; ++i)
    c[i] = std::isnan(in[i]) ? 0.0f : std::clamp(in[i], 0.0f, kMaxEmission);
  const float maxc = std::max(c.r, std::max(c.g, c.b));
  int exponent = 0;
  std::frexp(std::max(maxc, 1e-30f), &exponent);
  int e = std::max(-16, exponent - 1) + 16;
  float scale = std::exp2(float(e - 24));
  if (std::floor(maxc / scale + 0.5f) >= 512.0f) {
    ++e;
    scale *= 2.0f;
  }
  uint32_t m[3];
  for (int i = 0; i < 3; ++i) m[i] = uint32_t(std::min(std::floor(c[i] / scale + 0.5f), 511.0f));
  return m[0] | (m[1] << 9) | (m[2] << 18) | (uint32_t(e) << 27);
}

glm::vec3 decodeRgb9e5(uint32_t bits) {
  const float scale = std::exp2(float(int(bits >> 27) - 24));
  return glm::vec3(float(bits & 0x1FFu), float((bits >> 9) & 0x1FFu),
                   float((bits >> 18) & 0x1FFu)) *
         scale;
}

uint8_t linearToSrgb8(float c) {
  c = std::isnan(c) ? 0.0f : std::clamp(c, 0.0f, 1.0f);
  const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return uint8_t(std::floor(s * 255.0f + 0.5f));  // as gbuffer.glsl: ties up
}

float srgb8ToLinear(uint8_t code) {
  const float s = float(code) / 255.0f;
  return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
}

glm::uvec4 encode(const Texel& t) {
  auto unorm8 = [](float v) {
    return uint32_t(std::floor((std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f)) * 255.0f + 0.5f));
  };
  const uint32_t albedo = uint32_t(linearToSrgb8(t.albedo.r)) |
                          (uint32_t(linearToSrgb8(t.albedo.g)) << 8) |
                          (uint32_t(linearToSrgb8(t.albedo.b)) << 16) | (unorm8(t.roughness) << 24);
  return {encodeNormal(t.normal), albedo, unorm8(t.metallic) | (t.geometry ? kGeometryBit : 0u),
          encodeRgb9e5(t.emission)};
}

Texel decode(const glm::uvec4& g) {
  Texel t;
  t.normal = decodeNormal(g.x);
  t.albedo = glm::vec3(srgb8ToLinear(uint8_t(g.y)), srgb8ToLinear(uint8_t(g.y >> 8)),
                       srgb8ToLinear(uint8_t(g.y >> 16)));
  t.roughness = float(g.y >> 24) / 255.0f;
  t.metallic = float(g.z & 0xFFu) / 255.0f;
  t.geometry = (g.z & kGeometryBit) != 0u;
  t.emission = decodeRgb9e5(g.w);
  return t;
}

ImageRGBA32F unpackChannel(const std::vector<uint8_t>& texels, int width, int height,
                           size_t channel) {
  ImageRGBA32F img{width, height, std::vector<float>(size_t(width) * height * 4, 0.0f)};
  for (size_t i = 0; i < size_t(width) * height && (i + 1) * 16 <= texels.size(); ++i) {
    glm::uvec4 bits;
    std::memcpy(&bits, &texels[i * 16], 16);
    const Texel t = decode(bits);
    const float g = t.geometry ? 1.0f : 0.0f;
    glm::vec4 v;
    switch (channel) {  // as gbuffer_decode.comp
      case 0:
        v = t.geometry ? glm::vec4(t.normal, 1.0f) : glm::vec4(0.0f);
        break;
      case 1:
        v = glm::vec4(t.albedo, g);
        break;
      case 2:
        v = glm::vec4(t.roughness, t.metallic, 0.0f, g);
        break;
      default:
        v = glm::vec4(t.emission, g);
        break;
    }
    std::memcpy(&img.pixels[i * 4], &v, sizeof v);
  }
  return img;
}

}  // namespace gi::gbuffer
