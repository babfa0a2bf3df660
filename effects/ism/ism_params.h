// Instant radiosity with imperfect shadow maps (Ritschel et al. 2008, seed 002): the parameter
// block the shaders read (mirror of IsmParams in ism_common.glsl), the limits of the settings,
// and CPU mirrors of the formulas the tests check (paraboloid mapping, the VPL singularity
// guard, the pull-push rules).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace gi::ism {

inline constexpr int kMaxVpls = 1024;  // the VPL table is a uniform buffer (64 KiB)
inline constexpr int kMaxBlock = 8;    // interleaving block k (k x k VPL subsets)
inline constexpr int kVplSlots = kMaxVpls + kMaxBlock * kMaxBlock;  // padded to whole blocks
inline constexpr int kMaxIsmResolution = 512;
inline constexpr int kMaxPullPushLevels = 6;  // ism_pull_push.comp: 64 x 64 blocks
inline constexpr int kMaxBounces = 3;
// Imperfect reflective shadow maps (ism_irsm.glsl): of each VPL's point subset, the first
// kIrsmPoints at most are shaded as its IRSM's entries (the next bounce's candidates).
inline constexpr uint32_t kIrsmPoints = 4096;
inline uint32_t irsmEntries(int pointsPerIsm) {
  return std::min(uint32_t(pointsPerIsm), kIrsmPoints);
}
// Environment VPLs (seed 002 §5, "Environment Maps"): at most this many directional VPLs
// sampled from the environment map, each with an orthographic ISM (their own uniform table).
inline constexpr int kMaxEnvVpls = 1024;
inline constexpr int kMaxSplatRadius = 2;
inline constexpr uint32_t kMaxPoints = 1u << 21;  // surface points asked of the engine
inline constexpr uint32_t kEmpty = 0xffffffffu;   // an ISM texel no point reached
// VPL singularity guard: 1 / d^2 becomes 1 / max(d^2, d_min^2) with d_min = kDistanceClamp
// x the scene's extent (the `distance_clamp` setting overrides the fraction). Without it a
// receiver next to a VPL gets unbounded irradiance (and 0/0 at d = 0).
inline constexpr float kDistanceClamp = 0.02f;
// Glossy receivers: the largest Phong exponent (VPLs resolve only broad lobes: "slightly
// glossy").
inline constexpr float kMaxPhongExponent = 128.0f;

// std140 mirror of IsmParams (ism_common.glsl); vec4 members only.
struct Uniforms {
  glm::vec4 rsm;        // width, height, vpl count, padded count (whole k x k blocks)
  glm::vec4 atlas;      // tile resolution, tiles per row, points per ISM, surface point count
  glm::vec4 bias;       // constant (world), slope (per unit distance), near, far (classic SMs)
  glm::vec4 pull;       // pull threshold, push threshold (world, level 0), levels, scene extent
  glm::vec4 gather;     // d_min^2, block k, k^2 (VPL subset weight), strength
  glm::vec4 blur;       // plane tolerance (relative depth), min normal cosine, splat scale, seed
  glm::vec4 envSphere;  // environment VPLs' orthographic maps: scene centre, bounding radius R
  glm::vec4 envVpls;    // environment VPLs: count, padded count, first tile, normal offset (texels)
  glm::vec4 nearField;  // range (world) of x: the "ao" darkening the environment VPLs' light, y:
                        // the earlier "indirect" the first bounce's far field is added to
  glm::vec4 envDepth;   // x: the orthographic maps' depth origin beyond envSphere's centre
};
static_assert(sizeof(Uniforms) == 10 * sizeof(glm::vec4));

// The environment VPLs' orthographic maps (seed 002 §5) over what the camera can see of the
// scene: the bounds of its frustum out to the scene's farthest corner, within the scene's
// bounds [lo, hi], not the scene's whole bounding sphere, so a texel shrinks where the view
// holds part of a large scene. `centre` and `radius` span the maps; `depth` (from the centre
// toward the sky) reaches past the scene's far side, so occluders outside the fitted region
// still shadow it. A frustum that misses the bounds falls back to the whole scene.
struct OrthoFit {
  glm::vec3 centre{0.0f};
  float radius = 1.0f, depth = 1.0f;
};
inline OrthoFit fitEnvironmentMaps(const glm::vec3& lo, const glm::vec3& hi,
                                   const glm::mat4& invViewProj, const glm::vec3& eye) {
  const glm::vec3 sceneCentre = 0.5f * (lo + hi);
  const float sceneRadius = std::max(0.5f * glm::length(hi - lo), 1e-6f);
  float far = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
    far = std::max(far, glm::length(corner - eye));
  }
  glm::vec3 fmin = eye, fmax = eye;
  for (int i = 0; i < 4; ++i) {  // the frustum's edges, out to the farthest corner
    const glm::vec4 h = invViewProj * glm::vec4((i & 1) ? 1.0f : -1.0f, (i & 2) ? 1.0f : -1.0f,
                                                1.0f, 1.0f);  // reverse-Z: 1 is the near plane
    const glm::vec3 p = glm::vec3(h) / h.w;
    const glm::vec3 d = p - eye;
    const float len = glm::length(d);
    if (!(len > 0.0f) || !std::isfinite(len)) return {sceneCentre, sceneRadius, sceneRadius};
    const glm::vec3 end = eye + d / len * far;
    fmin = glm::min(fmin, glm::min(p, end));
    fmax = glm::max(fmax, glm::max(p, end));
  }
  const glm::vec3 bmin = glm::max(fmin, lo), bmax = glm::min(fmax, hi);
  if (!(bmin.x <= bmax.x && bmin.y <= bmax.y && bmin.z <= bmax.z))
    return {sceneCentre, sceneRadius, sceneRadius};
  OrthoFit f;
  f.centre = 0.5f * (bmin + bmax);
  f.radius = std::max(0.5f * glm::length(bmax - bmin), 1e-6f);
  f.depth = glm::length(f.centre - sceneCentre) + sceneRadius;
  return f;
}

// The paraboloid basis of a VPL with normal n, the same as SceneView::paraboloid's view matrix
// (lookAlong: up +y, or +z when n is nearly vertical), so ISMs and classic maps share texels.
struct Basis {
  glm::vec3 s, u, f;
};
inline Basis basis(const glm::vec3& n) {
  const glm::vec3 up = std::abs(n.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  const glm::vec3 s = glm::normalize(glm::cross(n, up));
  return {s, glm::cross(s, n), n};
}
// Disk coordinates in [-1, 1]^2 of direction `dir` (unit) in the hemisphere around b.f;
// false behind it (cosine <= 0).
inline bool paraboloid(const Basis& b, const glm::vec3& dir, glm::vec2& p) {
  const float c = glm::dot(dir, b.f);
  if (!(c > 0.0f)) return false;
  p = glm::vec2(glm::dot(dir, b.s), glm::dot(dir, b.u)) / (1.0f + c);
  return true;
}

// Irradiance at a receiver (position x, normal n) from a VPL (position xv, normal nv, flux phi)
// without visibility: phi / pi cos(theta_v) cos(theta_r) / max(d^2, dMin^2). Zero behind either
// surface and for d = 0 (no direction); finite for every finite input.
inline glm::vec3 vplIrradiance(const glm::vec3& x, const glm::vec3& n, const glm::vec3& xv,
                               const glm::vec3& nv, const glm::vec3& phi, float dMin) {
  const glm::vec3 w = x - xv;
  const float d2 = glm::dot(w, w);
  if (!(d2 > 1e-20f)) return glm::vec3(0.0f);
  const glm::vec3 dir = w / std::sqrt(d2);
  const float cv = std::max(glm::dot(nv, dir), 0.0f), cr = std::max(-glm::dot(n, dir), 0.0f);
  return phi * (cv * cr / (3.14159265f * std::max(d2, dMin * dMin)));
}

// The sample point of environment VPL slot i of n (ism_env_vpl.comp; `phases` = k^2, the
// interleaving's phases, slot i = phase + j k^2): ((i + 0.5) / n, radical inverse of j +
// (phase + 0.5) / k^2 mod 1). Each phase's slots form a stratified set, and so do all slots.
inline glm::vec2 envSamplePoint(uint32_t i, uint32_t n, uint32_t phases) {
  uint32_t j = i / phases, bits = 0;
  for (int b = 0; b < 32; ++b) bits |= ((j >> b) & 1u) << (31 - b);
  const float second =
      float(bits) * 2.3283064365386963e-10f + (float(i % phases) + 0.5f) / float(phases);
  return {(float(i) + 0.5f) / float(n), second - std::floor(second)};
}

// Energy-normalised Phong lobe (n + 2) / (2 pi) cos^n(alpha) for light travelling along w
// (VPL -> receiver, any length) at a receiver with normal n seen from unit direction v; alpha
// between reflect(w, n) and v (mirror of ismPhongLobe in ism_glossy.glsl). At most
// (n + 2) / (2 pi); 0 for w = 0. The glossy radiance is f0 x lobe x vplIrradiance(...).
inline float phongLobe(const glm::vec3& w, const glm::vec3& n, const glm::vec3& v, float exponent) {
  const float len = glm::length(w);
  if (!(len > 1e-20f)) return 0.0f;
  const float c = std::clamp(glm::dot(glm::reflect(w / len, n), v), 0.0f, 1.0f);
  return (exponent + 2.0f) / (2.0f * 3.14159265f) * std::pow(c, exponent);
}

// Pull-push over one 2x2 block (seed 002 §3.2, after Marroquim et al. 2007). Depths are
// distances; infinity marks a hole. Pull: the mean of the valid children within `threshold` of
// the nearest one (points from a hidden surface behind are not mixed in), and whether those
// are at least half of the valid children (the coarse texel is mostly that surface). Push: a
// texel takes the coarse value when it is a hole, or when it lies more than `threshold` behind
// a majority coarse value (a hidden surface's sample seen through a gap in the near one).
// Behind a minority it stays: that is a silhouette, and replacing it would widen the occluder
// by up to 2^levels - 1 texels (on a courtyard's 64^2 orthographic sky maps, ~1.4 m).
struct PullPushTexel {
  float depth = std::numeric_limits<float>::infinity();
  bool majority = false;
};
inline PullPushTexel pullDepth(const float child[4], float threshold) {
  float nearest = std::numeric_limits<float>::infinity();
  for (int i = 0; i < 4; ++i) nearest = std::min(nearest, child[i]);
  if (!std::isfinite(nearest)) return {};
  float sum = 0.0f;
  int count = 0, valid = 0;
  for (int i = 0; i < 4; ++i) {
    valid += std::isfinite(child[i]) ? 1 : 0;
    if (child[i] <= nearest + threshold) {
      sum += child[i];
      ++count;
    }
  }
  return {sum / float(count), 2 * count >= valid};
}
inline PullPushTexel pushDepth(const PullPushTexel& fine, const PullPushTexel& coarse,
                               float threshold) {
  if (!std::isfinite(coarse.depth)) return fine;
  const bool replace =
      !std::isfinite(fine.depth) || (coarse.majority && fine.depth > coarse.depth + threshold);
  return replace ? coarse : fine;
}

}  // namespace gi::ism
