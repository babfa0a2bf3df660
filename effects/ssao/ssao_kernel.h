// The SSAO sample kernel, the 4x4 interleave rotations and the effect's uniform block: one
// definition shared by the plugin (which uploads it) and tests/test_ssao.cpp (which evaluates
// the same discrete estimator and its continuous form on the CPU).
//
// Estimator. For a pixel with view-space position P and normal N, tap i is the point
//   Q_i = P + R * (T' x_i + B' y_i + N z_i)
// with (x_i, y_i, z_i) = r_i * w_i, w_i a unit direction in the hemisphere around +z and
// r_i in (0, 1]. (T', B') is the tangent frame rotated about N by the pixel's interleave
// angle. A tap is occluded when the depth buffer's surface at Q_i's pixel lies in front of
// Q_i by more than the bias and by less than R (seed 001 §4.3: 0 < z - z* < R, so distant
// foreground objects cast no false shadows). AO = clamp(1 - intensity * occluded / n, 0, 1).
//
// Distribution (what the tests integrate): directions are cosine-distributed about N and
// distances uniform in [0, R] (density cos(theta) / pi per steradian times 1 / R):
//   xi = ((i + 0.5) / n, frac(radicalInverse2(i) + 0.5 / n), frac(radicalInverse3(i) + 0.5 / n))
//   w  = (cos(2 pi xi.x) sqrt(xi.y), sin(2 pi xi.x) sqrt(xi.y), sqrt(1 - xi.y)),  r = xi.z
// a 3-D Hammersley set shifted off zero. Its continuous form is
//   occluded fraction = (1/pi) Int_hemisphere cos(theta) Int_0^1 occ(P + s R w) ds dw,
// i.e. obscurance with the linear falloff mu(d) = d / R of seed 001 (for a surface hit at
// distance d along w, the taps beyond d are inside it: fraction 1 - d / R).
//
// Interleaving (seed 001 §4.2): pixel (x, y) uses rotation table entry (y & 3) * 4 + (x & 3);
// entry j (ranked by a 4x4 Bayer matrix, so that neighbours differ most) rotates the kernel by
// 2 pi j (n + 1) / (16 n) = 2 pi j / 16 + 2 pi j / (16 n). The first term sends each tap's 16
// copies round the whole circle (a 4x4 box then averages every tap over all azimuths instead of
// showing one shifted silhouette per tap); the second keeps the 16 n azimuths of the union
// distinct: for even n they are exactly the 16 n strata 2 pi (k + 0.5) / (16 n).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace gi::ssao {

inline constexpr int kMaxSamples = 64;
// Blur: neighbours whose depth differs from the centre's tangent plane by more than this
// fraction of the radius get no weight (the edge-stopping threshold).
inline constexpr float kBlurDepthTolerance = 0.25f;

// std140 mirror of the `SsaoParams` uniform block in ssao.comp.
struct Uniforms {         // mirrors ssao.comp's SsaoParams (checked when the pipeline is made)
  float params[4];        // R (world units), bias (absolute: setting x R), intensity, 0
  int32_t counts[4];      // taps used (1..kMaxSamples), 0, 0, 0
  float rotation[16][4];  // cos, sin of each 4x4 phase's kernel rotation, 0, 0
  uint32_t kernel[kMaxSamples / 4][4];  // tap i at [i / 4][i % 4], packed by packTap()
};
static_assert(sizeof(Uniforms) == 32 + 16 * 16 + kMaxSamples * 4, "std140 layout");

inline double radicalInverse(uint32_t i, uint32_t base) {
  double inv = 1.0 / base, f = inv, r = 0.0;
  for (; i > 0; i /= base, f *= inv) r += f * double(i % base);
  return r;
}

struct Tap {
  float x, y, z;
};

// The unit-radius hemisphere point for uniform numbers (u, v, w) in [0, 1)^3.
inline Tap tapFromUniform(double u, double v, double w) {
  const double phi = 2.0 * 3.14159265358979323846 * u;
  const double sinTheta = std::sqrt(v), cosTheta = std::sqrt(1.0 - v);
  return {float(w * std::cos(phi) * sinTheta), float(w * std::sin(phi) * sinTheta),
          float(w * cosTheta)};
}

// One tap in 32 bits: x and y in [-1, 1] with 11 bits each, z in [0, 1] with 10 bits (steps
// of 1e-3 R at most). The shader unpacks one uint per tap: llvmpipe gathers a UBO value indexed
// by the loop counter lane by lane, so three floats per tap cost three gathers.
inline uint32_t packTap(Tap t) {
  auto q = [](float v, float lo, float hi, uint32_t maxCode) {
    const float c = std::round((std::clamp(v, lo, hi) - lo) / (hi - lo) * float(maxCode));
    return uint32_t(c);
  };
  return q(t.x, -1.0f, 1.0f, 2047) | q(t.y, -1.0f, 1.0f, 2047) << 11 |
         q(t.z, 0.0f, 1.0f, 1023) << 22;
}
// Exactly what ssao.comp decodes.
inline Tap unpackTap(uint32_t p) {
  return {float(p & 2047u) * (2.0f / 2047.0f) - 1.0f,
          float((p >> 11) & 2047u) * (2.0f / 2047.0f) - 1.0f, float(p >> 22) * (1.0f / 1023.0f)};
}

// Tap i of the n-tap kernel before quantization: the shifted 3-D Hammersley point, mapped.
inline Tap exactKernelTap(int i, int n) {
  const double shift = 0.5 / n;
  const double u = (i + 0.5) / n;
  const double v = std::fmod(radicalInverse(uint32_t(i), 2) + shift, 1.0);
  const double w = std::fmod(radicalInverse(uint32_t(i), 3) + shift, 1.0);
  return tapFromUniform(u, v, w);
}
// Tap i of the n-tap kernel as the shader sees it (quantized by packTap).
inline Tap kernelTap(int i, int n) {
  return unpackTap(packTap(exactKernelTap(i, n)));
}

// 4x4 Bayer order: entry (y & 3) * 4 + (x & 3) holds the phase's rank j in 0..15.
inline constexpr std::array<int, 16> kBayer4 = {0, 8,  2, 10, 12, 4, 14, 6,
                                                3, 11, 1, 9,  15, 7, 13, 5};

// Kernel rotation angle (radians) of pixel (x, y); 0 without interleaving.
inline double rotationAngle(int x, int y, int n, bool interleave) {
  if (!interleave) return 0.0;
  const int j = kBayer4[size_t((y & 3) * 4 + (x & 3))];
  return 2.0 * 3.14159265358979323846 * j * (n + 1) / (16.0 * n);
}

inline Uniforms makeUniforms(double radius, double bias, double intensity, int samples,
                             bool interleave) {
  Uniforms u{};
  const int n = samples < 1 ? 1 : samples > kMaxSamples ? kMaxSamples : samples;
  u.params[0] = float(radius);
  u.params[1] = float(bias * radius);
  u.params[2] = float(intensity);
  u.counts[0] = n;
  for (int e = 0; e < 16; ++e) {
    const double a = rotationAngle(e & 3, e >> 2, n, interleave);
    u.rotation[e][0] = float(std::cos(a));
    u.rotation[e][1] = float(std::sin(a));
  }
  for (int i = 0; i < n; ++i) u.kernel[i / 4][i % 4] = packTap(exactKernelTap(i, n));
  return u;
}

}  // namespace gi::ssao
