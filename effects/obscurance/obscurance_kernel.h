// Obscurance and the ambient transfer function of Umenhoffer, Toth and Szirmay-Kalos (seed 001):
// the sample set, the membership functions, the transfer guard and the effect's uniform block.
// One definition shared by the plugin (which uploads it) and tests/test_obscurance.cpp.
//
// Estimator (seed 001 §4, eqs. 7-9). Samples (w_i, r_i) have density mu'(r) cos(theta) / pi:
// w_i cosine-distributed about N, r_i = R mu^-1(xi_z). Along ray i, m = 1 or 2 test points
// x + w_i r_i k / m (k = 1..m) are tested against the depth buffer; the ray is open (J_i = 1)
// when none of them is inside. A point counts as inside only when 0 < z - z* < R (z its view
// distance, z* the depth buffer's): an occluder far in front casts no false silhouette shadow.
//   O ~= (1/n) sum J_i                                          (eq. 5: obscurance)
//   W ~= sum J_i / (n - sum (1 - J_i) a_i)                      (eq. 9: ambient transfer)
// with a_i the albedo at the first inside point's pixel. The denominator is evaluated as
//   D = sum J_i + sum (1 - J_i) (1 - a_i)   (>= N = sum J_i for a_i in [0, 1], no cancellation),
// so W = N / D lies in [0, 1]; D = 0 only when every ray is closed (N = 0) by white occluders.
// Guard ("phantom open sample"): W = (N/n + eta) / (D/n + eta), i.e. eta n extra rays that are
// open in both sums. It keeps D + eta > 0, W in [0, 1] (N <= D), gives W = 1 for a fully
// occluded white neighbourhood (the limit a -> 1 at any O > 0: a white room has no dark
// corners), and biases W by eta (1 - W) / (D/n + eta) elsewhere: at most eta (1 - O) for
// black occluders (D = n), growing only where D/n is small, i.e. where W -> 1 anyway.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace gi::obscurance {

inline constexpr int kMaxSamples = 64;
inline constexpr double kPi = 3.14159265358979323846;
// Guard of the transfer ratio (see above), in units of the sample mean.
inline constexpr float kTransferGuard = 1e-3f;
// Filter: neighbours farther than this fraction of R from the centre's tangent plane are not
// averaged (the depth-difference limit of seed 001 §4.2).
inline constexpr float kFilterDepthTolerance = 0.25f;
// Lloyd relaxation of the sample set: candidates per sample and iterations, fixed seed.
inline constexpr int kLloydCandidatesPerSample = 256;
inline constexpr int kLloydIterations = 8;
inline constexpr uint32_t kLloydSeed = 20090001u;

// Fuzzy memberships mu(d / R) of seed 001 §3 (gi-reference --membership names). Step gives
// ambient occlusion (mu = 0 below R, 1 beyond).
enum class Membership { Sqrt = 0, Step = 1, Linear = 2, Smoothstep = 3 };
inline const std::vector<std::string>& membershipNames() {
  static const std::vector<std::string> names = {"sqrt", "step", "linear", "smoothstep"};
  return names;
}
// What the transfer mode estimates and outputs: through "ao" obscurance O, the transfer W with
// the occluders' albedo, or W with their emission (emission + albedo x ambient, clamped to 1);
// through "ambient" (RGB, per unit albedo) the ambient radiance with the occluders' direct
// radiance (emission + albedo x the scene's lights): colour bleeding, not clamped.
enum class Transfer { Off = 0, Albedo = 1, Emission = 2, Radiance = 3 };
inline const std::vector<std::string>& transferNames() {
  static const std::vector<std::string> names = {"off", "albedo", "emission", "radiance"};
  return names;
}

inline double membership(Membership m, double x) {  // x = d / R
  x = std::max(x, 0.0);
  if (x >= 1.0) return 1.0;
  switch (m) {
    case Membership::Sqrt:
      return std::sqrt(x);
    case Membership::Step:
      return 0.0;
    case Membership::Linear:
      return x;
    case Membership::Smoothstep:
      return x * x * (3.0 - 2.0 * x);
  }
  return 1.0;
}

// r / R with density mu'(r): the inverse of mu at u in [0, 1]. Step: mu' is a unit impulse at R.
inline double membershipInverse(Membership m, double u) {
  u = std::clamp(u, 0.0, 1.0);
  switch (m) {
    case Membership::Sqrt:
      return u * u;
    case Membership::Step:
      return 1.0;
    case Membership::Linear:
      return u;
    case Membership::Smoothstep:  // 3t^2 - 2t^3 = u
      return 0.5 - std::sin(std::asin(1.0 - 2.0 * u) / 3.0);
  }
  return 1.0;
}

// n points in [0, 1]^dims (dims 2 or 3; unused coordinates 0.5) relaxed by Lloyd's algorithm
// over a dense uniform candidate set: a Poisson-disc-like, blue-noise set (seed 001 §4.1),
// then with rank-stratified marginals (below).
// Deterministic: std::mt19937 is fully specified, and the floats are built from its bits.
inline std::vector<std::array<double, 3>> lloydPoints(int n, int dims) {
  std::mt19937 rng(kLloydSeed + uint32_t(n) * 7u + uint32_t(dims));
  auto uniform = [&] { return double(rng() >> 8) * (1.0 / 16777216.0); };
  const size_t candidates = size_t(n) * kLloydCandidatesPerSample;
  std::vector<std::array<double, 3>> cand(candidates), sites(static_cast<size_t>(n));
  for (auto& c : cand)
    for (int d = 0; d < 3; ++d) c[size_t(d)] = d < dims ? uniform() : 0.5;
  for (int i = 0; i < n; ++i) sites[size_t(i)] = cand[size_t(i)];
  std::vector<std::array<double, 4>> sum(static_cast<size_t>(n));
  for (int it = 0; it < kLloydIterations; ++it) {
    std::fill(sum.begin(), sum.end(), std::array<double, 4>{});
    for (const auto& c : cand) {
      size_t best = 0;
      double bestD = 1e300;
      for (size_t s = 0; s < sites.size(); ++s) {
        double d2 = 0.0;
        for (int d = 0; d < dims; ++d)
          d2 += (c[size_t(d)] - sites[s][size_t(d)]) * (c[size_t(d)] - sites[s][size_t(d)]);
        if (d2 < bestD) bestD = d2, best = s;
      }
      for (int d = 0; d < 3; ++d) sum[best][size_t(d)] += c[size_t(d)];
      sum[best][3] += 1.0;
    }
    for (size_t s = 0; s < sites.size(); ++s)  // a site without candidates stays put
      if (sum[s][3] > 0.0)
        for (int d = 0; d < 3; ++d) sites[s][size_t(d)] = sum[s][size_t(d)] / sum[s][3];
  }
  // Marginals stratified by rank: coordinate d of the k-th smallest site becomes (k + 0.5) / n.
  // Lloyd's centroids keep away from the cube's faces unevenly for small n (16 sites: mean
  // xi_y 0.546 instead of 0.5, which made corner AO 0.014 too dark on average); ranks keep the
  // relaxed arrangement and make every 1-D projection (elevation, distance) exactly stratified.
  std::vector<size_t> order(sites.size());
  for (int d = 0; d < dims; ++d) {
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return sites[a][size_t(d)] < sites[b][size_t(d)] ||
             (sites[a][size_t(d)] == sites[b][size_t(d)] && a < b);
    });
    for (size_t k = 0; k < order.size(); ++k)
      sites[order[k]][size_t(d)] = (double(k) + 0.5) / double(n);
  }
  return sites;
}

struct Tap {
  float x, y, z;  // w r / R in the tangent frame (+z = normal)
};

// Seed 001 §4.1: cosine-distributed direction from (xi_x, xi_y), distance r = mu^-1(xi_z).
inline Tap tapFromUniform(Membership m, double u, double v, double w) {
  const double phi = 2.0 * kPi * u, sinTheta = std::sqrt(v), cosTheta = std::sqrt(1.0 - v);
  const double r = membershipInverse(m, w);
  return {float(r * std::cos(phi) * sinTheta), float(r * std::sin(phi) * sinTheta),
          float(r * cosTheta)};
}

// One tap in 32 bits: x, y in [-1, 1] with 11 bits, z in [0, 1] with 10 bits (as the SSAO
// kernel: one UBO word per tap).
inline uint32_t packTap(Tap t) {
  auto q = [](float v, float lo, float hi, uint32_t maxCode) {
    return uint32_t(std::round((std::clamp(v, lo, hi) - lo) / (hi - lo) * float(maxCode)));
  };
  return q(t.x, -1.0f, 1.0f, 2047) | q(t.y, -1.0f, 1.0f, 2047) << 11 |
         q(t.z, 0.0f, 1.0f, 1023) << 22;
}
// Exactly what obscurance.comp decodes.
inline Tap unpackTap(uint32_t p) {
  return {float(p & 2047u) * (2.0f / 2047.0f) - 1.0f,
          float((p >> 11) & 2047u) * (2.0f / 2047.0f) - 1.0f, float(p >> 22) * (1.0f / 1023.0f)};
}

// The n-sample set of a membership, unquantized. Step relaxes (xi_x, xi_y) only: every sample
// has r = R, so a third coordinate would only thin out the directions.
inline std::vector<Tap> sampleSet(Membership m, int n) {
  const auto pts = lloydPoints(n, m == Membership::Step ? 2 : 3);
  std::vector<Tap> taps;
  for (const auto& p : pts) taps.push_back(tapFromUniform(m, p[0], p[1], p[2]));
  return taps;
}

// 4x4 interleave (seed 001 §4.2): entry (y & 3) * 4 + (x & 3) rotates the set about N by
// 2 pi rank / 16, ranks from a 4x4 Bayer matrix (neighbours differ most).
inline constexpr std::array<int, 16> kBayer4 = {0, 8,  2, 10, 12, 4, 14, 6,
                                                3, 11, 1, 9,  15, 7, 13, 5};
inline double rotationAngle(int x, int y, bool interleave) {
  return interleave ? 2.0 * kPi * kBayer4[size_t((y & 3) * 4 + (x & 3))] / 16.0 : 0.0;
}

// The guarded transfer ratio on sample means (nMean = N / n, dMean = D / n), as the shader.
inline float transferRatio(float nMean, float dMean) {
  return (nMean + kTransferGuard) / (dMean + kTransferGuard);
}

// std140 mirror of the `ObscuranceParams` block in obscurance.comp and obscurance_filter.comp.
struct Uniforms {
  float radius;                         // R, world units
  float bias;                           // absolute, world units (setting x R)
  float filterTolerance;                // absolute, world units (kFilterDepthTolerance x R)
  float guard;                          // kTransferGuard
  float rotation[16][4];                // cos, sin of each 4x4 phase's rotation, 0, 0
  uint32_t kernel[kMaxSamples / 4][4];  // tap i at [i / 4][i % 4] (packTap)
};
static_assert(sizeof(Uniforms) == 16 + 16 * 16 + kMaxSamples * 4, "std140 layout");

inline Uniforms makeUniforms(double radius, double bias, Membership m, int samples,
                             bool interleave) {
  Uniforms u{};
  const int n = std::clamp(samples, 1, kMaxSamples);
  u.radius = float(radius);
  u.bias = float(bias * radius);
  u.filterTolerance = float(kFilterDepthTolerance * radius);
  u.guard = kTransferGuard;
  for (int e = 0; e < 16; ++e) {
    const double a = rotationAngle(e & 3, e >> 2, interleave);
    u.rotation[e][0] = float(std::cos(a));
    u.rotation[e][1] = float(std::sin(a));
  }
  const std::vector<Tap> taps = sampleSet(m, n);
  for (int i = 0; i < n; ++i) u.kernel[i / 4][i % 4] = packTap(taps[size_t(i)]);
  return u;
}

}  // namespace gi::obscurance
