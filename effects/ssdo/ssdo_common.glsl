// Shared by the SSDO shaders: the parameter block (C++ mirror: gi::ssdo::Uniforms in
// ssdo_samples.h) and the packings that keep every per-tap read to one texelFetch.
//
// "ssdo_surface" texel (RGBA32UI), written by ssdo_surface.comp, read once per tap by ssdo.comp:
//   x 1 / view distance (float bits; 0: sky or no geometry), y view normal (octahedral,
//   snorm 16x2), z, w the sender's outgoing radiance (half rg, half b) and, with depth peeling,
//   w's high half the 1 / view distance of the second depth layer (half; 0: none).
// Raw / x-blurred texel (RGBA32UI), written by ssdo.comp and the x blur, read by the blur:
//   x directional term (rgb9e5), y bounce term (rgb9e5), z 1 / view distance, w view normal
//   (packBlurNormal; 0 on sky pixels).
#ifndef SSDO_COMMON_GLSL
#define SSDO_COMMON_GLSL

#include "normal_codec.glsl"  // giEncodeNormal, giDecodeNormal: the ssdo_surface normal

// An additional camera (seed 000 §4): its view space relative to the main one and its image.
struct SsdoCamera {
  mat4 toCamera;    // main view space -> this camera's view space
  mat4 fromCamera;  // its inverse
  vec4 proj;        // p00, p11, p20, p21 of its (perspective, reverse-Z) projection
  vec4 size;        // width, height, 1 / width, 1 / height of its image
};

layout(set = 0, binding = 1, std140) uniform SsdoParams {
  float radius;          // R, world units
  float bias;            // absolute (world)
  float bounceScale;     // A_s / pi
  float distanceClamp2;  // d_min^2 of the bounce's 1 / max(d^2, d_min^2)
  float blurTolerance;   // plane tolerance (world)
  float blurMinCos;      // min normal cosine
  float pad0, pad1;
  SsdoCamera cameras[4];  // the `cameras` first are valid (gi::ssdo::kMaxCameras)
  uvec4 samples[128];  // [phase][i] at flat phase * 32 + i (gi::ssdo::pack)
} ssdo;

// The blur's normal (raw texel w): 10-bit snorm x, y, z, decoded per tap in a third of the
// octahedral decode's instructions. Unnormalized on decode (within 1/511 of unit length).
uint packBlurNormal(vec3 n) {
  uvec3 q = uvec3(clamp(n * 511.5 + 511.5, 0.0, 1023.0));
  return q.x | (q.y << 10) | (q.z << 20);
}
vec3 unpackBlurNormal(uint p) {
  return vec3(uvec3(p, p >> 10, p >> 20) & 1023u) * (2.0 / 1023.0) - 1.0;
}

// Shared-exponent RGB (9-bit mantissas, 5-bit exponent; as VK_FORMAT_E5B9G9R9): non-negative,
// at most 65408; relative error 2^-9 of the largest channel. Guard: NaN and negatives read 0.
const float kRgb9e5Max = 65408.0;
uint packRgb9e5(vec3 c) {
  c = vec3(c.r > 0.0 ? min(c.r, kRgb9e5Max) : 0.0, c.g > 0.0 ? min(c.g, kRgb9e5Max) : 0.0,
           c.b > 0.0 ? min(c.b, kRgb9e5Max) : 0.0);
  float m = max(c.r, max(c.g, c.b));
  // floor(log2(m)) read from the float's exponent bits (exact; llvmpipe's log2 and exp2 are
  // polynomial approximations and cost more than the rest of the packing), then the biased
  // shared exponent e >= 0 (below 2^-16 every channel rounds to 0 anyway).
  int e = max(-16, int(floatBitsToUint(max(m, 1e-30)) >> 23) - 127) + 16;
  // 2^(24 - e) built from its bits (exponent 120..151: a normal float): multiplying by it is
  // exact, where dividing by 2^(e - 24) cost a division per channel.
  float scale = uintBitsToFloat(uint(151 - e) << 23);
  if (floor(m * scale + 0.5) >= 512.0) {
    scale *= 0.5;
    e += 1;
  }
  uvec3 q = uvec3(min(floor(c * scale + 0.5), vec3(511.0)));
  return q.r | (q.g << 9) | (q.b << 18) | (uint(clamp(e, 0, 31)) << 27);
}
vec3 unpackRgb9e5(uint p) {
  // 2^(e - 24) built from its bits (e - 24 + 127 in [103, 134]: a normal float): no exp2.
  float scale = uintBitsToFloat(((p >> 27) + 103u) << 23);
  return vec3(uvec3(p, p >> 9, p >> 18) & 511u) * scale;
}

// environmentIrradianceOverPi (common.glsl) reading `frame` in place: the common.glsl helpers
// take FrameUniforms by value, and uniform-block reads inside the sample loop cost llvmpipe
// dearly (the sky through them was 2/3 of the SSDO pass; hoisted out of the loop, a tenth).
vec3 ssdoIrradianceOverPi(vec3 n) {
  float x = n.x, y = n.y, z = n.z;
  vec3 e = frame.irradianceSH[0].rgb * 0.282095 + frame.irradianceSH[1].rgb * (0.488603 * y) +
           frame.irradianceSH[2].rgb * (0.488603 * z) + frame.irradianceSH[3].rgb * (0.488603 * x) +
           frame.irradianceSH[4].rgb * (1.092548 * x * y) +
           frame.irradianceSH[5].rgb * (1.092548 * y * z) +
           frame.irradianceSH[6].rgb * (0.315392 * (3.0 * z * z - 1.0)) +
           frame.irradianceSH[7].rgb * (1.092548 * x * z) +
           frame.irradianceSH[8].rgb * (0.546274 * (x * x - y * y));
  return max(e, vec3(0.0)) * (1.0 / 3.14159265358979);
}
// View-space position of pixel-centre coordinates `pix` (pixels) at inverse view distance `iz`
// (> 0), for the perspective projection's non-zero terms.
vec3 ssdoViewPosition(vec2 pix, float iz, vec2 invSize, float p00, float p11, float p20,
                      float p21) {
  vec2 ndc = pix * 2.0 * invSize - 1.0;
  float d = 1.0 / iz;
  return vec3((ndc.x + p20) * d / p00, (ndc.y + p21) * d / p11, -d);
}

#endif
