// The HBAO plugin's uniform block and per-pixel noise: one definition shared by the plugin
// (which uploads it) and tests/test_horizon_ao.cpp.
//
// Estimator (hbao.comp; Bavoil, Sainz and Dimitrov 2008). For kDirections screen directions
// phi_i = 2 pi (i + noise.x) / kDirections and kSteps samples at pixel distances
// ((j + noise.y) / kSteps) R_px + 1, elevations are measured from the view-space image plane;
// the tangent angle t is that of the tangent plane within the slice the samples lie in (exact
// for planes). The horizon starts at the tangent angle t(phi) + angle bias; a sample within R whose
// elevation a exceeds the horizon h adds W(r) (sin a - sin h), W(r) = 1 - r^2 / R^2, and
// becomes the horizon. AO = 1 - (1 / kDirections) sum_i (occlusion of direction i): the
// attenuated horizon-based occlusion, which is not the cosine-weighted AO of gi-reference
// (no cosine term, elevations from the image plane, attenuation instead of a hard radius).
#pragma once

#include <cmath>
#include <cstdint>

#include "gi/interleave.h"

namespace gi::hbao {

inline constexpr int kMaxDirections = 32, kMaxSteps = 32;
inline constexpr float kBlurDepthTolerance = 0.25f;  // fraction of the radius

// std140 mirror of the `HbaoParams` uniform block in hbao.comp.
struct Uniforms {
  float radius;            // R, world units
  float invRadius2;        // 1 / R^2 (W(r) = 1 - r^2 / R^2)
  float cosBias, sinBias;  // of the angle bias
  float noise[16][4];      // per 4x4 phase: cos, sin of the direction rotation, step jitter, 0
};
static_assert(sizeof(Uniforms) == 16 + 16 * 16, "std140 layout");

// directions: the rotation of phase e is interleaveNoise(e).x x 2 pi / directions (stratified).
inline Uniforms makeUniforms(double radius, double angleBiasDegrees, bool interleave,
                             int directions) {
  constexpr double kPi = 3.14159265358979323846;
  Uniforms u{};
  u.radius = float(radius);
  u.invRadius2 = float(1.0 / (radius * radius));  // radius >= 1e-4 (the setting's range)
  u.cosBias = float(std::cos(angleBiasDegrees * kPi / 180.0));
  u.sinBias = float(std::sin(angleBiasDegrees * kPi / 180.0));
  interleaveRotations(u.noise, 2.0 * kPi, directions, interleave);
  return u;
}

}  // namespace gi::hbao
