// Random numbers and sampling for the CPU reference renderer: a counter-seeded PCG32 (one
// stream per pixel and sample index, so results do not depend on the thread count), cosine-
// weighted hemisphere directions, the fuzzy membership functions of obscurance (seed 001) and
// the Alchemy falloff (seed 003).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace gi::reference {

constexpr float kPi = 3.14159265358979323846f;

inline uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// PCG32 (O'Neill, XSH-RR). Rng::forSample gives the stream of one pixel's sample: the same
// (seed, pixel, sample) always yields the same numbers, whichever thread draws them.
class Rng {
 public:
  Rng(uint64_t state, uint64_t stream) : inc_((stream << 1u) | 1u) {
    nextU32();
    state_ += state;
    nextU32();
  }
  static Rng forSample(uint64_t seed, uint64_t pixel, uint64_t sample) {
    const uint64_t h = splitmix64(splitmix64(splitmix64(seed) ^ pixel) ^ (sample * 0x2545f491ULL));
    return Rng(h, splitmix64(h ^ 0x5851f42d4c957f2dULL));
  }
  uint32_t nextU32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1) with 24 random bits (never 1).
  float uniform() { return float(nextU32() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_ = 0;
  uint64_t inc_;
};

// Orthonormal basis around a unit normal (Duff et al. 2017, branchless).
struct Basis {
  glm::vec3 t, b, n;
  explicit Basis(const glm::vec3& normal) : n(normal) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
  }
  glm::vec3 toWorld(const glm::vec3& local) const {
    return local.x * t + local.y * b + local.z * n;
  }
};

// Cosine-weighted direction on the hemisphere around +z (pdf cos(theta) / pi): a uniform point
// on the unit disk lifted onto the hemisphere (Malley's method).
inline glm::vec3 cosineHemisphere(float u1, float u2) {
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  return glm::vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1)));
}

// Fuzzy membership mu(d) of obscurance (seed 001 eq. 5): how strongly a direction whose first
// hit is at distance d counts as open. All are 0 at d = 0, increasing, and 1 (or -> 1) for
// d >= R; a ray that hits nothing counts 1.
enum class Membership {
  Sqrt,        // sqrt(d / R) clamped to 1 (Mendez et al., the paper's example)
  Linear,      // d / R clamped to 1
  Smoothstep,  // 3x^2 - 2x^3 with x = d / R clamped to 1
  Step,        // 0 below R, 1 beyond: obscurance reduces to ambient occlusion of radius R
  Exponential  // 1 - exp(-d / R): the participating-medium analogy (never reaches 1; rays are
               // traced without a distance limit)
};

inline float membership(Membership m, float d, float R) {
  if (!(R > 0.0f)) return 1.0f;
  const float x = std::max(d, 0.0f) / R;
  switch (m) {
    case Membership::Sqrt:
      return x >= 1.0f ? 1.0f : std::sqrt(x);
    case Membership::Linear:
      return std::min(x, 1.0f);
    case Membership::Smoothstep: {
      const float c = std::min(x, 1.0f);
      return c * c * (3.0f - 2.0f * c);
    }
    case Membership::Step:
      return x >= 1.0f ? 1.0f : 0.0f;
    case Membership::Exponential:
      return 1.0f - std::exp(-x);
  }
  return 1.0f;
}

// Parameters of the Alchemy obscurance (seed 003). The falloff applied to an occluder at
// distance t < radius is  g(t) = sigma * t / (max(u^2, t^2) + epsilon):
//  - u = 0 (default): exactly the per-sample weight of the paper's final estimator (eq. 10),
//    sigma * (v.n) / (v.v + epsilon) = g(t) * cos(theta) with v = t * w;
//  - sigma = u, epsilon = 0: the paper's falloff g(t) = u t / max(u, t)^2 of eqs. 7-9.
// Obscurance A = max(0, 1 - I)^k with I = (1/pi) * integral over the hemisphere of
// H(radius - t(w)) g(t(w)) cos(theta) dw (see reference.h for the derivation).
struct AlchemyParams {
  float sigma = 1.0f;     // intensity scale (the paper's sigma; it carries the length unit of u)
  float u = 0.0f;         // falloff knee; 0: the eq. 10 form
  float epsilon = 1e-4f;  // the paper's epsilon (squared length)
  float contrast = 1.0f;  // the paper's k
  float bias = 0.0f;      // beta: numerator max(0, v.n - beta z); alchemy-disk only
};

inline float alchemyFalloff(const AlchemyParams& p, float t) {
  const float t2 = t * t;
  const float denom = std::max(p.u * p.u, t2) + p.epsilon;
  return denom > 0.0f ? p.sigma * t / denom : 0.0f;
}

}  // namespace gi::reference
