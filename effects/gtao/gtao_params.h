// The GTAO plugin's uniform block, per-pixel noise and multi-bounce fit: one definition shared
// by the plugin (which uploads it) and tests/test_horizon_ao.cpp.
//
// Estimator (gtao.comp). For kSlices planes through the view vector V at angles
// phi_i = pi (i + rotation) / kSlices, the horizon on each side is the highest direction to a
// depth-buffer sample within the radius R (never below the tangent plane), found by kSteps
// samples at pixel distances ((j + jitter) / kSteps) R_px + 1. Uniform steps: the reference
// counts occluders up to R alike (a squared distribution measured NRMSE 0.130 against 0.112 at
// 8 steps). Horizons are elevations above the slice's tangent line (exact for planes at
// texel-centre samples; README.md). With n the angle of the normal projected into the slice
// and h0 <= 0 <= h1 the horizon angles from V,
//   visible_i = |N_proj| (arc(h0) + arc(h1)),  arc(h) = (cos n + 2 h sin n - cos(2h - n)) / 4
// (Jimenez et al. 2016, eq. 10: the integral of cos(theta - n) |sin theta| from 0 to h), and
//   AO = sum_i visible_i / sum_i |N_proj| (cos n + n sin n),
// the cosine-weighted visibility (1/pi) Int V(w) cos(w, N) dw that gi-reference's `ao`
// computes, as a ratio to the same slice sum without occluders (exact 1 on planes).
#pragma once

#include <algorithm>
#include <cstdint>

#include "gi/interleave.h"

namespace gi::gtao {

inline constexpr int kMaxSlices = 16, kMaxSteps = 32;
// Blur: neighbours whose depth differs from the centre's tangent plane by more than this
// fraction of the radius get no weight (the edge-stopping threshold).
inline constexpr float kBlurDepthTolerance = 0.25f;

// std140 mirror of the `GtaoParams` uniform block in gtao.comp.
struct Uniforms {
  float radius;        // R, world units
  float falloffSlope;  // 1 / (falloff x R): weight = clamp((R - distance) x slope, 0, 1)
  float thickness;     // horizon blend towards lower samples, 0 = off
  float pad;
  float noise[16][4];  // per 4x4 phase: cos, sin of the slice rotation, step jitter, 0
};
static_assert(sizeof(Uniforms) == 16 + 16 * 16, "std140 layout");

// falloff: the fraction of R over which an occluder's weight fades to 0 (0: hard cut-off).
// slices: the rotation of phase e is interleaveNoise(e).x x pi / slices (one slice's angle,
// stratified).
inline Uniforms makeUniforms(double radius, double falloff, double thickness, bool interleave,
                             int slices) {
  Uniforms u{};
  u.radius = float(radius);
  // Guard: falloff 0 is a step; the slope stays finite (1e30 per world unit).
  u.falloffSlope = float(1.0 / std::max(falloff * radius, 1e-30));
  u.thickness = float(thickness);
  interleaveRotations(u.noise, 3.14159265358979323846, slices, interleave);
  return u;
}

// Jimenez et al. 2016 multi-bounce fit, as gtao.comp applies it to the albedo's luminance.
inline float multiBounce(float ao, float albedo) {
  const float a = 2.0404f * albedo - 0.3324f, b = -4.7951f * albedo + 0.6417f,
              c = 2.7552f * albedo + 0.6903f;
  return std::clamp(std::max(ao, ((a * ao + b) * ao + c) * ao), 0.0f, 1.0f);
}

}  // namespace gi::gtao
