// The packed G-buffer: the one place that knows its format. C++ mirror (layout, formats, the
// same encode/decode on the CPU, stated precision): engine/include/gi/gbuffer.h.
//
// Two colour targets beside the D32 reverse-Z depth:
//   "gbuffer" RGBA32UI, one texel = one fetch:
//     x  normal: view space, octahedral, 2 x 16-bit snorm (angle error < 0.004 deg)
//     y  albedo rgb as 8-bit sRGB codes (as an sRGB8 target stores it), roughness 8-bit unorm
//     z  metallic 8-bit unorm | geometry flag (bit 8) | 23 bits reserved (0)
//     w  emission rgb, shared exponent (RGB9E5: 9-bit mantissas, error <= 2^-9 of the largest
//        channel above 2^-15, <= 2^-24 absolute below; finite values up to 65408, the rest
//        clamped)
//   "motion" RG16F: current minus previous position of the surface, UV units (+x right, +y down)
// Cleared texels (sky) are 0: no geometry, zero normal, black albedo and emission.
//
// Reading: before including, define the set and binding of the main view's G-buffer texture
// (and, optionally, of its depth) to get the fetching helpers:
//   #define GI_GBUFFER_SET 0
//   #define GI_GBUFFER_BINDING 3   // usampler2D "gbuffer" (nearest sampler)
//   #define GI_DEPTH_BINDING 2     // sampler2D "depth" (optional; needs FrameUniforms `frame`)
//   #include "gbuffer.glsl"
//   uvec4 g = giGBufferLoad(p);  vec3 n = giGBufferNormal(g);  vec3 a = giGBufferAlbedo(g);
// The decoders take a texel, so G-buffers drawn from other views (GpuScene::drawGBuffer) decode
// the same way from their own texture. Writers (the scene's G-buffer draws) use
// giGBufferEncode.
#ifndef GI_GBUFFER_GLSL
#define GI_GBUFFER_GLSL

const uint kGBufferGeometryBit = 0x100u;

#include "normal_codec.glsl"  // giEncodeNormal, giDecodeNormal

// ---- albedo: 8-bit sRGB codes (IEC 61966-2-1), exactly as an sRGB8 attachment stores them -
float giLinearToSrgb(float c) {
  c = clamp(c, 0.0, 1.0);  // NaN clamps to 0 or 1, both finite
  return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}
float giSrgbToLinear(float s) {
  return s <= 0.04045 ? s * (1.0 / 12.92) : pow((s + 0.055) * (1.0 / 1.055), 2.4);
}

// ---- emission: RGB9E5 (EXT_texture_shared_exponent's encoding) ----------------------------
const float kGBufferMaxEmission = 65408.0;  // (511 / 512) x 2^16, the format's largest value

// Guard: NaN and negative channels encode as 0, +Inf and larger values as 65408.
uint giEncodeRgb9e5(vec3 c) {
  c = vec3(isnan(c.r) ? 0.0 : c.r, isnan(c.g) ? 0.0 : c.g, isnan(c.b) ? 0.0 : c.b);
  c = clamp(c, vec3(0.0), vec3(kGBufferMaxEmission));
  float maxc = max(c.r, max(c.g, c.b));
  int exponent;  // maxc = f x 2^exponent, f in [0.5, 1): floor(log2(maxc)) = exponent - 1, exactly
  frexp(max(maxc, 1e-30), exponent);
  int e = max(-16, exponent - 1) + 16;  // the stored exponent: bias 15, + 1
  float scale = exp2(float(e - 24));    // 2^(e - bias - mantissa bits)
  if (floor(maxc / scale + 0.5) >= 512.0) {
    ++e;
    scale *= 2.0;
  }
  uvec3 m = uvec3(min(floor(c / scale + 0.5), vec3(511.0)));
  return m.r | (m.g << 9) | (m.b << 18) | (uint(e) << 27);
}

vec3 giDecodeRgb9e5(uint bits) {
  uvec3 m = uvec3(bits, bits >> 9, bits >> 18) & 0x1FFu;
  return vec3(m) * exp2(float(int(bits >> 27) - 24));
}

// ---- the texel ---------------------------------------------------------------------------
uvec4 giGBufferEncode(vec3 normal, vec3 albedo, float roughness, float metallic, vec3 emission) {
  // floor(x + 0.5), not round(): GLSL leaves the direction of round(n + 0.5) to the driver.
  uvec3 srgb = uvec3(floor(vec3(giLinearToSrgb(albedo.r), giLinearToSrgb(albedo.g),
                                giLinearToSrgb(albedo.b)) *
                               255.0 +
                           0.5));
  uint r8 = uint(floor(clamp(roughness, 0.0, 1.0) * 255.0 + 0.5));
  uint m8 = uint(floor(clamp(metallic, 0.0, 1.0) * 255.0 + 0.5));
  return uvec4(giEncodeNormal(normal), srgb.r | (srgb.g << 8) | (srgb.b << 16) | (r8 << 24),
               m8 | kGBufferGeometryBit, giEncodeRgb9e5(emission));
}

bool giGBufferIsGeometry(uvec4 g) { return (g.z & kGBufferGeometryBit) != 0u; }
// Unit view-space normal; +z on sky texels.
vec3 giGBufferNormal(uvec4 g) { return giDecodeNormal(g.x); }
// Linear albedo (0 on sky texels).
vec3 giGBufferAlbedo(uvec4 g) {
  vec3 s = vec3(uvec3(g.y, g.y >> 8, g.y >> 16) & 0xFFu) * (1.0 / 255.0);
  return vec3(giSrgbToLinear(s.r), giSrgbToLinear(s.g), giSrgbToLinear(s.b));
}
float giGBufferRoughness(uvec4 g) { return float(g.y >> 24) * (1.0 / 255.0); }
float giGBufferMetallic(uvec4 g) { return float(g.z & 0xFFu) * (1.0 / 255.0); }
// Linear emitted radiance.
vec3 giGBufferEmission(uvec4 g) { return giDecodeRgb9e5(g.w); }

// ---- fetching the main view's G-buffer -----------------------------------------------------
#ifndef GI_GBUFFER_SET
#define GI_GBUFFER_SET 0
#endif
#ifdef GI_GBUFFER_BINDING
layout(set = GI_GBUFFER_SET, binding = GI_GBUFFER_BINDING) uniform usampler2D giGBuffer;
uvec4 giGBufferLoad(ivec2 p) { return texelFetch(giGBuffer, p, 0); }
vec3 giGBufferNormal(ivec2 p) { return giGBufferNormal(giGBufferLoad(p)); }
vec3 giGBufferAlbedo(ivec2 p) { return giGBufferAlbedo(giGBufferLoad(p)); }
bool giGBufferIsGeometry(ivec2 p) { return giGBufferIsGeometry(giGBufferLoad(p)); }
#endif

#ifdef GI_DEPTH_BINDING
layout(set = GI_GBUFFER_SET, binding = GI_DEPTH_BINDING) uniform sampler2D giDepth;
float giGBufferDepth(ivec2 p) { return texelFetch(giDepth, p, 0).r; }
// View-space position of pixel p's centre (needs the FrameUniforms block named `frame`).
vec3 giGBufferViewPosition(ivec2 p) {
  return viewPositionFromDepth(frame.invProj, (vec2(p) + 0.5) * frame.viewport.zw,
                               giGBufferDepth(p));
}
#endif

#endif
