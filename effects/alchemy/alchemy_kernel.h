// The Alchemy ambient obscurance estimator (McGuire et al. 2011, seed 003 eq. 10): the tap
// pattern, the uniform block and a CPU evaluation of the same estimator on a depth/normal
// buffer. Shared by the plugin (alchemy.cpp uploads the block, alchemy.comp runs the estimator)
// and tests/test_alchemy.cpp (which evaluates it on the CPU and compares pixel by pixel).
//
// Estimator, for a pixel with view-space position C (view distance z = -C.z) and normal n:
//   A = max(0, 1 - (2 sigma / s) * sum_i max(0, v_i . n - beta z) H(r^2 - v_i . v_i)
//                                      / (v_i . v_i + epsilon))^k
// with v_i = P_i - C, P_i the view-space position the depth buffer holds at tap i. The bias
// term is the paper's z_C beta with its z_C < 0 (depth-proportional, against depth-precision
// self-occlusion). H keeps eq. 9's Heaviside (occluders farther than r count nothing), so a
// foreground object far in front casts no halo. epsilon is the guard of the denominator: a
// tap at zero distance (v = 0) contributes 0 / epsilon = 0, and since v.n <= |v| a tap never
// contributes more than 1 / (2 sqrt(epsilon)), so the sum stays finite for any epsilon > 0.
//
// Taps: s points of a golden-angle spiral on the screen-space disk whose radius is the
// projection of r at C's depth (r |P11| H / (2 z) pixels, clamped to the image size):
//   tap i at radius (i + 0.5) / s of the disk, angle i * kGoldenAngle + phi(x, y),
// phi = 2 pi j / 16 with j the 4x4 Bayer rank of the pixel (x & 3, y & 3): 16 rotations that a
// box filter of even radius (weights [.5 1 ... 1 .5]) averages exactly. A tap reads the depth
// texel it falls in and is reconstructed at that texel's centre, so taps on a plane lie on the
// plane exactly. Taps outside the depth image (without a guard band: off screen) and sky taps
// count as unoccluded.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace gi::alchemy {

inline constexpr int kMaxSamples = 64;
inline constexpr int kMaxBlurRadius = 8;
inline constexpr int kMaxGuardBand = 256;
// pi (3 - sqrt 5): consecutive spiral taps are as far apart in angle as possible.
inline constexpr double kGoldenAngle = 2.39996322972865332;
// Blur: neighbours whose view distance differs from the centre's tangent plane by more than this
// fraction of the radius get no weight (the edge-stopping threshold).
inline constexpr float kBlurDepthTolerance = 0.25f;

// std140 mirror of the `AlchemyParams` uniform block in alchemy.comp and alchemy_blur.glsl.
struct Uniforms {
  float radius;         // r, world units
  float bias;           // beta
  float scale;          // 2 sigma / s
  float contrast;       // k
  float epsilon;        // denominator guard
  float blurTolerance;  // absolute, world units (kBlurDepthTolerance x r)
  float radius2;        // r^2
  float pad;
  uint32_t taps[kMaxSamples / 4][4];  // tap i at [i / 4][i % 4]: packTap(exactTapOffset(i, s))
};
static_assert(sizeof(Uniforms) == 32 + kMaxSamples * 4, "std140 layout");

// Unit-disk offset of tap i of s, before the pixel's rotation.
inline glm::vec2 exactTapOffset(int i, int s) {
  const double radius = (i + 0.5) / s, angle = i * kGoldenAngle;
  return glm::vec2(float(radius * std::cos(angle)), float(radius * std::sin(angle)));
}
// One tap in 32 bits, GLSL's packSnorm2x16 (steps of 3e-5 of the disk radius): the shader reads
// one uint per tap (a UBO value indexed by the tap counter is gathered lane by lane on llvmpipe;
// sin and cos per tap measured 5x the cost of the rest of the tap).
inline uint32_t packTap(glm::vec2 o) {
  auto q = [](float v) {
    return uint32_t(uint16_t(int16_t(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f))));
  };
  return q(o.x) | q(o.y) << 16;
}
// Exactly what alchemy.comp decodes (unpackSnorm2x16).
inline glm::vec2 unpackTap(uint32_t p) {
  auto u = [](uint32_t bits) { return std::max(float(int16_t(uint16_t(bits))) / 32767.0f, -1.0f); };
  return {u(p & 0xffffu), u(p >> 16)};
}
// Tap i of s as the shader sees it.
inline glm::vec2 tapOffset(int i, int s) {
  return unpackTap(packTap(exactTapOffset(i, s)));
}

// The `epsilon` setting is relative to r^2: the guard of v.v scales with the squared distances
// it guards, so a scene scaled by L (r and sigma scaled by L) gives the same image. The
// default 4e-4 is the paper's 1e-4 at r = 0.5.
constexpr double kDefaultRelativeEpsilon = 4e-4;
inline double absoluteEpsilon(double relative, double radius) {
  return relative * radius * radius;
}

inline Uniforms makeUniforms(double radius, double bias, double intensity, double contrast,
                             double epsilon, int samples) {
  const int s = std::clamp(samples, 1, kMaxSamples);
  Uniforms u{};
  u.radius = float(radius);
  u.bias = float(bias);
  u.scale = float(2.0 * intensity / s);
  u.contrast = float(contrast);
  u.epsilon = float(epsilon);
  u.blurTolerance = float(kBlurDepthTolerance * radius);
  u.radius2 = float(radius * radius);
  for (int i = 0; i < s; ++i) u.taps[i / 4][i % 4] = packTap(exactTapOffset(i, s));
  return u;
}

// 4x4 Bayer rank of pixel (x, y), 0..15, computed the way the shader does (bit interleave of
// x ^ y and y, reversed): neighbours differ most.
inline int bayerRank(int x, int y) {
  const int b = (x ^ y) & 3;
  return ((b & 1) << 3) | ((y & 1) << 2) | ((b >> 1) << 1) | ((y >> 1) & 1);
}

// A depth/normal buffer as the CPU estimator reads it: reverse-Z depth (0 = sky), view-space
// normals, the projection and the image size.
struct DepthView {
  const float* depth;       // w x h, row-major
  const glm::vec3* normal;  // w x h
  int w, h;
  glm::mat4 proj;

  float depthAt(int x, int y) const { return depth[size_t(y) * w + x]; }
  glm::vec3 position(int x, int y) const {  // view space at the texel centre
    const float p32 = proj[3][2], p22 = proj[2][2];
    const float dist = p32 / std::max(depthAt(x, y) + p22, 1e-30f);
    const glm::vec2 ndc = (glm::vec2(x, y) + 0.5f) * 2.0f / glm::vec2(w, h) - 1.0f;
    return {(ndc.x + proj[2][0]) * dist / proj[0][0], (ndc.y + proj[2][1]) * dist / proj[1][1],
            -dist};
  }
};

// The estimator for output pixel (x, y) reading input pixel (x, y) + band (the shader's
// arithmetic, in float, on the CPU).
inline float estimate(const DepthView& in, int x, int y, int band, const Uniforms& u, int samples) {
  const int qx = x + band, qy = y + band;
  if (in.depthAt(qx, qy) <= 0.0f) return 1.0f;
  const glm::vec3 c = in.position(qx, qy);
  const float dist = -c.z;
  glm::vec3 n = in.normal[size_t(qy) * in.w + qx];
  const float len2 = glm::dot(n, n);
  n = len2 > 1e-30f ? n / std::sqrt(len2) : glm::vec3(0, 0, 1);
  const float rpx =
      std::min(u.radius * std::abs(in.proj[1][1]) * 0.5f * float(in.h) / std::max(dist, 1e-30f),
               float(std::max(in.w, in.h)));
  const float phi = float(bayerRank(x, y)) * (2.0f * 3.14159265f / 16.0f);
  const glm::vec2 rot(std::cos(phi), std::sin(phi));
  float sum = 0.0f;
  for (int i = 0; i < samples; ++i) {
    const glm::vec2 o = tapOffset(i, samples);
    const glm::vec2 d(o.x * rot.x - o.y * rot.y, o.x * rot.y + o.y * rot.x);
    const glm::vec2 t = glm::floor(glm::vec2(qx, qy) + 0.5f + d * rpx);
    if (t.x < 0 || t.y < 0 || t.x >= in.w || t.y >= in.h) continue;
    const int tx = int(t.x), ty = int(t.y);
    if (in.depthAt(tx, ty) <= 0.0f) continue;
    const glm::vec3 v = in.position(tx, ty) - c;
    const float vv = glm::dot(v, v);
    if (!(vv < u.radius2)) continue;
    sum += std::max(0.0f, glm::dot(v, n) - u.bias * dist) / (vv + u.epsilon);
  }
  const float a = std::max(0.0f, 1.0f - u.scale * sum);
  return a > 0.0f ? std::min(std::pow(a, u.contrast), 1.0f) : 0.0f;
}

}  // namespace gi::alchemy
