// The SSDO sample sets and the effect's uniform block: one definition shared by the plugin
// (which uploads it) and tests/test_ssdo.cpp.
//
// Sample i of a pixel is the point P + R s_i w_i: w_i a unit direction in the hemisphere
// around the normal N, s_i in (0, 1] (seed 000: a random step in [0, r_max]). Directions are
// cosine-distributed (density cos / pi), so the directional-occlusion estimator of seed 000,
//   L_dir = sum_i (rho / pi) L_in(w_i) V(w_i) cos(theta_i) (2 pi / N)  (uniform directions),
// becomes, with the same expectation and less variance,
//   L_dir = rho (1 / N) sum_i L_in(w_i) V(w_i),
// exact for a constant environment without occluders (ambient = rho L).
//
// Sets: M x N points (M = `pattern_sets` <= 16) of one 3-D Hammersley set of M N points
// (shifted off zero): set m holds points m, m + M, m + 2M, ..., so the union of the sets seen
// by a 4x4 pixel block, which the blur averages, is the whole low-discrepancy set. Pixel
// (x, y) uses set rank(x & 3, y & 3) mod M, the rank from a 4x4 Bayer matrix (neighbours
// differ most). The table is uploaded by pixel phase: entry [phase][i].
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace gi::ssdo {

inline constexpr int kMaxSamples = 32;
inline constexpr int kPhases = 16;  // 4x4 interleave
inline constexpr int kMaxBlurRadius = 8;
// An occluder must lie this fraction of R in front of a sample (self-occlusion guard).
inline constexpr float kBias = 0.025f;
// Blur edge stopping: a neighbour farther than this fraction of R from the centre's tangent
// plane, or whose normal differs by more than acos(kBlurMinCos), gets no weight.
inline constexpr float kBlurPlaneTolerance = 0.25f;
inline constexpr float kBlurMinCos = 0.8f;

// Depth layers: the front one and up to three peeled; consecutive pairs are solid intervals.
inline constexpr int kMaxLayers = 4;
inline constexpr int kMaxCameras = 4;  // additional cameras

// std140 mirror of `SsdoCamera` in ssdo_common.glsl (column-major matrices).
struct Camera {
  float toCamera[16];    // main view space -> the camera's view space
  float fromCamera[16];  // its inverse
  float proj[4];         // p00, p11, p20, p21
  float size[4];         // width, height, 1 / width, 1 / height
};
static_assert(sizeof(Camera) == 160, "std140 layout");

// std140 mirror of `SsdoParams` in ssdo_common.glsl.
struct Uniforms {
  float radius;          // R, world units
  float bias;            // absolute (kBias x R)
  float bounceScale;     // A_s / pi = bounce_strength x R^2 / N
  float distanceClamp2;  // d_min^2 of the bounce's 1 / max(d^2, d_min^2)
  float blurTolerance;   // absolute (kBlurPlaneTolerance x R)
  float blurMinCos;
  float pad0, pad1;
  Camera cameras[kMaxCameras];                     // written every frame by the plugin
  uint32_t samples[kPhases * kMaxSamples / 4][4];  // [phase][i] at flat phase * kMaxSamples + i
};
static_assert(sizeof(Uniforms) == 32 + kMaxCameras * 160 + kPhases * kMaxSamples * 4,
              "std140 layout");

inline double radicalInverse(uint32_t i, uint32_t base) {
  double inv = 1.0 / base, f = inv, r = 0.0;
  for (; i > 0; i /= base, f *= inv) r += f * double(i % base);
  return r;
}

struct Sample {
  float x, y, z;  // unit direction about +z (z >= 0)
  float s;        // step as a fraction of R, (0, 1]
};

// One sample in 32 bits: direction x and y with 12 bits each in [-1, 1] (z = sqrt(1 - x^2 -
// y^2)), the step with 8 bits as (code + 1) / 256 (never 0).
inline uint32_t pack(Sample v) {
  auto q = [](float a) {
    return uint32_t(std::lround((std::clamp(a, -1.0f, 1.0f) + 1.0f) * 2047.5f));
  };
  const uint32_t s = uint32_t(std::clamp(std::lround(v.s * 256.0f) - 1, 0L, 255L));
  return std::min(q(v.x), 4095u) | std::min(q(v.y), 4095u) << 12 | s << 24;
}
// Exactly what ssdo.comp decodes.
inline Sample unpack(uint32_t p) {
  const float x = float(p & 4095u) * (2.0f / 4095.0f) - 1.0f;
  const float y = float((p >> 12) & 4095u) * (2.0f / 4095.0f) - 1.0f;
  return {x, y, std::sqrt(std::max(0.0f, 1.0f - x * x - y * y)), float((p >> 24) + 1u) / 256.0f};
}

// Point g of the n-point set, before quantization.
inline Sample exactPoint(int g, int n) {
  const double shift = 0.5 / n;
  const double u = (g + 0.5) / n;
  const double v = std::fmod(radicalInverse(uint32_t(g), 2) + shift, 1.0);
  const double w = std::fmod(radicalInverse(uint32_t(g), 3) + shift, 1.0);
  const double phi = 2.0 * 3.14159265358979323846 * u;
  const double sinTheta = std::sqrt(v), cosTheta = std::sqrt(1.0 - v);
  return {float(std::cos(phi) * sinTheta), float(std::sin(phi) * sinTheta), float(cosTheta),
          float(w)};
}

inline constexpr std::array<int, 16> kBayer4 = {0, 8,  2, 10, 12, 4, 14, 6,
                                                3, 11, 1, 9,  15, 7, 13, 5};

// Set used by pixel (x, y) with m sets.
inline int setOf(int x, int y, int m) {
  return kBayer4[size_t(y & 3) * 4 + size_t(x & 3)] % std::max(m, 1);
}

// Sample i of pixel (x, y), as the shader sees it.
inline Sample sampleAt(int x, int y, int i, int n, int m) {
  return unpack(pack(exactPoint(i * m + setOf(x, y, m), n * m)));
}

inline Uniforms makeUniforms(double radius, int samples, int sets, double bounceStrength,
                             double distanceClamp) {
  Uniforms u{};
  const int n = std::clamp(samples, 1, kMaxSamples), m = std::clamp(sets, 1, kPhases);
  u.radius = float(radius);
  u.bias = float(kBias * radius);
  u.bounceScale = float(bounceStrength * radius * radius / n);
  u.distanceClamp2 = float(distanceClamp * distanceClamp);
  u.blurTolerance = float(kBlurPlaneTolerance * radius);
  u.blurMinCos = kBlurMinCos;
  for (int phase = 0; phase < kPhases; ++phase)
    for (int i = 0; i < n; ++i) {
      const int f = phase * kMaxSamples + i;
      u.samples[f / 4][f % 4] = pack(exactPoint(i * m + setOf(phase & 3, phase >> 2, m), n * m));
    }
  return u;
}

}  // namespace gi::ssdo
