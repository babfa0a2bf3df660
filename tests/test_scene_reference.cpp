// The CPU reference renderer against closed forms: AO / obscurance / Alchemy next to a wall
// and under a sphere resting on a plane, direct light from analytic lights and skies, one
// bounce in an infinite corner, primary-hit depth; determinism across seeds and thread counts;
// no NaN for degenerate input; the gi-reference command line. CPU only (no Vulkan).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/image_io.h"
#include "gi/reference/ray_scene.h"
#include "gi/reference/reference.h"
#include "gi/scene_io.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

namespace ref = gi::reference;
constexpr double kPi = 3.14159265358979323846;

// --- scene building -------------------------------------------------------------------------

// The parallelogram corner + s e1 + t e2 (s, t in [0, 1]) as an n x n grid of quads, facing
// cross(e1, e2).
Mesh parallelogram(glm::vec3 corner, glm::vec3 e1, glm::vec3 e2, int n = 1) {
  Mesh m;
  m.name = "parallelogram";
  const glm::vec3 normal = glm::normalize(glm::cross(e1, e2));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float s = float(i) / n, t = float(j) / n;
      m.vertices.push_back({corner + s * e1 + t * e2, normal, {s, t}});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
  m.boundsMin = glm::min(glm::min(corner, corner + e1 + e2), glm::min(corner + e1, corner + e2));
  m.boundsMax = glm::max(glm::max(corner, corner + e1 + e2), glm::max(corner + e1, corner + e2));
  return m;
}

// UV sphere (poles on the y axis, so the lowest vertex touches y = centre.y - radius).
Mesh sphere(glm::vec3 centre, float radius, int segments, int rings) {
  Mesh m;
  m.name = "sphere";
  for (int r = 0; r <= rings; ++r) {
    const float theta = float(kPi) * r / rings;
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2.0f * float(kPi) * s / segments;
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                        std::sin(theta) * std::sin(phi));
      m.vertices.push_back({centre + radius * n, n, {float(s) / segments, float(r) / rings}});
    }
  }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = r * (segments + 1) + s, b = a + segments + 1;
      if (r > 0) m.indices.insert(m.indices.end(), {a, a + 1, b});
      if (r < rings - 1) m.indices.insert(m.indices.end(), {a + 1, b + 1, b});
    }
  m.boundsMin = centre - glm::vec3(radius);
  m.boundsMax = centre + glm::vec3(radius);
  return m;
}

struct SceneBuilder {
  Scene s;
  SceneBuilder() { s.sourcePath = "test"; }
  int material(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    Material m;
    m.baseColor = glm::vec4(albedo, 1.0f);
    m.emission = emission;
    s.materials.push_back(m);
    return int(s.materials.size()) - 1;
  }
  void add(Mesh mesh, int material = 0, const glm::mat4& transform = glm::mat4(1.0f)) {
    if (s.materials.empty()) this->material(glm::vec3(0.8f));
    mesh.material = uint32_t(material);
    s.meshes.push_back(std::move(mesh));
    s.nodes[s.addNode("mesh", transform)].meshes = {int(s.meshes.size()) - 1};
  }
  void camera(glm::vec3 eye, glm::vec3 target, float yfovDeg = 50.0f, float znear = 0.01f,
              float zfar = 100.0f, glm::vec3 up = glm::vec3(0, 1, 0)) {
    Camera c;
    c.yfov = glm::radians(yfovDeg);
    c.znear = znear;
    c.zfar = zfar;
    s.cameras.push_back(c);
    s.activeCameraNode = s.addNode("camera", glm::inverse(glm::lookAt(eye, target, up)));
    s.nodes[s.activeCameraNode].camera = int(s.cameras.size()) - 1;
  }
  void light(LightType type, glm::mat4 transform, glm::vec3 color, float intensity) {
    Light l;
    l.type = type;
    l.color = color;
    l.intensity = intensity;
    s.lights.push_back(l);
    s.nodes[s.addNode("light", transform)].light = int(s.lights.size()) - 1;
  }
  void constantEnvironment(glm::vec3 color, float intensity) {
    s.environment.kind = Environment::Kind::Constant;
    s.environment.constantColor = color;
    s.environment.intensity = intensity;
  }
  Scene done() {
    if (s.materials.empty()) material(glm::vec3(0.8f));
    s.updateWorldTransforms();
    return s;
  }
};

// Floor y = 0 (x in [0, size]) meeting the wall x = 0 (y in [0, size]) along the z axis,
// both extending over z in [-size/2, size/2]; the wall faces +x, the floor +y.
void addCorner(SceneBuilder& b, float size, int floorMaterial = 0, int wallMaterial = 0) {
  b.add(parallelogram({0, 0, size / 2}, {size, 0, 0}, {0, 0, -size}), floorMaterial);
  b.add(parallelogram({0, 0, -size / 2}, {0, size, 0}, {0, 0, size}), wallMaterial);
}

struct PixelView {
  glm::vec3 position, value, stdError;
  bool geometry;
};
PixelView pixel(const ref::Result& r, size_t i) {
  auto v3 = [&](const ImageRGBA32F& img) {
    return glm::vec3(img.pixels[i * 4], img.pixels[i * 4 + 1], img.pixels[i * 4 + 2]);
  };
  return {v3(r.position), v3(r.value), v3(r.stdError), r.depth.pixels[i * 4 + 3] > 0.5f};
}

bool allFinite(const ImageRGBA32F& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}
bool allFinite(const ref::Result& r) {
  return allFinite(r.value) && allFinite(r.stdError) && allFinite(r.depth) && allFinite(r.normal) &&
         allFinite(r.position) && std::isfinite(r.meanStdError);
}

ref::Settings smallSettings(ref::Quantity q, uint32_t spp, uint32_t w = 48, uint32_t h = 36) {
  ref::Settings s;
  s.quantity = q;
  s.width = w;
  s.height = h;
  s.spp = spp;
  s.threads = 2;
  return s;
}

// --- closed forms ---------------------------------------------------------------------------
//
// A point on an infinite plane at distance d from an infinite perpendicular wall. By Malley's
// method a cosine-weighted direction is a uniform point (x, z) on the unit disk of the tangent
// plane lifted onto the hemisphere, so its component towards the wall, s = -x, has the density
// (2/pi) sqrt(1 - s^2) on [-1, 1] (the chord length of the disk). The ray reaches the wall at
// distance t = d / s when s > 0, and the other plane never occludes. Hence any cosine-weighted
// average of f(t(w)) over the directions that hit the wall within r is
//     (1/pi) int_{t < r} f(t) cos dw = int_{d/r}^{1} f(d/s) (2/pi) sqrt(1 - s^2) ds,
// and for f = 1 (the AO-occluded fraction) the circular segment beyond a = d/r:
//     F(a) = (acos(a) - a sqrt(1 - a^2)) / pi,   AO = 1 - F  (1 for d >= r, 1/2 at d -> 0).
double wallFraction(double d, double r) {
  const double a = d / r;
  if (a >= 1.0) return 0.0;
  return (std::acos(a) - a * std::sqrt(1.0 - a * a)) / kPi;
}

// int_{a}^{1} f(d/s) (2/pi) sqrt(1 - s^2) ds with s = sin(phi) (smooth integrand), Simpson.
template <class F>
double wallIntegral(double d, double r, const F& f) {
  const double a = d / r;
  if (a >= 1.0) return 0.0;
  const double lo = std::asin(a), hi = kPi / 2;
  const int n = 2000;
  const double h = (hi - lo) / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double phi = lo + i * h;
    const double s = std::max(std::sin(phi), 1e-300);
    const double c = std::cos(phi);
    const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    sum += w * f(d / s) * (2.0 / kPi) * c * c;
  }
  return sum * h / 3.0;
}

// Distance of a corner-scene hit to the other plane (floor point: x, wall point: y); negative
// when the pixel is on neither plane or closer than `margin` to the planes' far edges (where
// the finite planes stop looking infinite).
double distanceToOtherPlane(const glm::vec3& p, float size = 4.0f, float margin = 0.5f) {
  if (std::abs(p.z) > size / 2 - margin) return -1.0;
  if (std::abs(p.y) < 1e-5f && p.x > 1e-5f && p.x < size - margin) return p.x;
  if (std::abs(p.x) < 1e-5f && p.y > 1e-5f && p.y < size - margin) return p.y;
  return -1.0;
}

// Every pixel within 5 standard errors + `bias` of `expected`, and the mean residual within
// 4 standard errors of the mean (a bias check far tighter than the per-pixel one).
// A pixel whose samples happened to be all equal reports se = 0 (e.g. AO = 1 from n misses
// when the expectation is 0.98); `seBound(e)` gives the largest standard error samples of a
// known range can have at the expected value e (for samples in [0, 1]: sqrt(e (1 - e) / n)),
// and the per-pixel check uses the larger of the two.
using SeBound = std::function<double(double)>;
SeBound unitIntervalBound(uint32_t n) {
  return [n](double e) { return std::sqrt(std::max(e * (1 - e), 0.0) / n); };
}

template <class Expected>
void checkAgainst(const ref::Result& r, const Expected& expected, double bias, int minPixels,
                  const char* what, const SeBound& seBound = nullptr) {
  int checked = 0;
  double residual = 0.0, variance = 0.0;
  for (size_t i = 0; i < size_t(r.value.width) * r.value.height; ++i) {
    const PixelView p = pixel(r, i);
    if (!p.geometry) continue;
    const double e = expected(p.position);
    if (std::isnan(e)) continue;
    const double v = p.value.x, se = p.stdError.x;
    const double bound = seBound ? seBound(e) : 0.0;
    EXPECT_NEAR(v, e, 5.0 * std::max(se, bound) + bias)
        << what << " at " << p.position.x << "," << p.position.y << "," << p.position.z << " (se "
        << se << ")";
    residual += v - e;
    variance += se * se;
    ++checked;
  }
  EXPECT_GE(checked, minPixels) << what;
  if (checked > 0) {
    const double meanResidual = residual / checked, meanSe = std::sqrt(variance) / checked;
    EXPECT_LE(std::abs(meanResidual), 4.0 * meanSe + bias / 4) << what << ": mean residual";
  }
}

// A view of the corner showing floor and wall points from d = 0 to beyond r = 0.5.
Scene cornerScene() {
  SceneBuilder b;
  addCorner(b, 4.0f);
  b.camera({1.1f, 0.9f, 0.9f}, {0.2f, 0.15f, 0.0f}, 55.0f);
  return b.done();
}

// --- tests ----------------------------------------------------------------------------------

TEST(ReferenceAO, LargePlaneIsFullyOpenAtAnyScaleAndTessellation) {
  // Nothing but one plane: every direction is open, for AO, obscurance (and the Alchemy sum is
  // 0). Grazing camera rays, a finely tessellated plane and a plane far from the origin
  // exercise the self-intersection offset.
  struct Case {
    float half;
    int grid;
    glm::vec3 offset;
  };
  for (const Case& c :
       {Case{1e3f, 1, {0, 0, 0}}, Case{5.0f, 40, {0, 0, 0}}, Case{20.0f, 8, {3e3f, -2e3f, 1e3f}}}) {
    SceneBuilder b;
    b.add(parallelogram(c.offset + glm::vec3(-c.half, 0, c.half), {2 * c.half, 0, 0},
                        {0, 0, -2 * c.half}, c.grid));
    b.camera(c.offset + glm::vec3(0.3f, 0.8f, 2.0f), c.offset + glm::vec3(0, 0, -3.0f), 60.0f);
    const Scene scene = b.done();
    for (ref::Quantity q : {ref::Quantity::AO, ref::Quantity::Obscurance}) {
      ref::Settings s = smallSettings(q, 64);
      s.radius = 0.5f;
      const ref::Result r = ref::render(scene, s);
      ASSERT_GT(r.geometryPixels, 500u);
      for (size_t i = 0; i < size_t(s.width) * s.height; ++i) {
        ASSERT_EQ(r.value.pixels[i * 4], 1.0f) << "pixel " << i << " half-size " << c.half;
        ASSERT_EQ(r.stdError.pixels[i * 4], 0.0f);
      }
      EXPECT_EQ(r.meanStdError, 0.0);
    }
  }
}

TEST(ReferenceAO, CornerMatchesCircularSegment) {
  ref::Settings s = smallSettings(ref::Quantity::AO, 256, 64, 48);
  s.radius = 0.5f;
  const ref::Result r = ref::render(cornerScene(), s);
  ASSERT_TRUE(allFinite(r));
  EXPECT_EQ(r.spp, 256u);
  int nearCorner = 0;
  double varianceRatio = 0.0;
  int ratioCount = 0;
  checkAgainst(
      r,
      [&](glm::vec3 p) {
        const double d = distanceToOtherPlane(p);
        if (d < 0) return std::numeric_limits<double>::quiet_NaN();
        if (d < 0.05) ++nearCorner;
        return 1.0 - wallFraction(d, s.radius);
      },
      0.005, 1000, "AO", unitIntervalBound(r.spp));
  EXPECT_GT(nearCorner, 20) << "the view must include points close to the corner edge";
  // The reported standard error matches the binomial one of the exact value on average.
  for (size_t i = 0; i < size_t(s.width) * s.height; ++i) {
    const PixelView p = pixel(r, i);
    const double d = p.geometry ? distanceToOtherPlane(p.position) : -1.0;
    if (d < 0 || d > 0.45) continue;
    const double f = wallFraction(d, s.radius);
    if (f < 0.05) continue;
    varianceRatio += double(p.stdError.x) * p.stdError.x / (f * (1 - f) / r.spp);
    ++ratioCount;
  }
  ASSERT_GT(ratioCount, 200);
  EXPECT_NEAR(varianceRatio / ratioCount, 1.0, 0.1);
}

TEST(ReferenceAO, CornerLimitIsOneHalf) {
  // A point on the floor 1e-3 from the wall with r = 100: the wall covers half the cosine-
  // weighted hemisphere (F(1e-5) = 1/2 - 6e-6).
  SceneBuilder b;
  addCorner(b, 400.0f);
  b.camera({0.001f, 1.0f, 0.0f}, {0.001f, 0.0f, 0.0f}, 0.02f, 0.01f, 100.0f, glm::vec3(0, 0, -1));
  ref::Settings s = smallSettings(ref::Quantity::AO, 4096, 1, 1);
  s.radius = 100.0f;
  const ref::Result r = ref::render(b.done(), s);
  const PixelView p = pixel(r, 0);
  ASSERT_TRUE(p.geometry);
  EXPECT_NEAR(p.position.x, 0.001f, 1e-5f);
  EXPECT_NEAR(p.value.x, 1.0 - wallFraction(p.position.x, 100.0), 4.0 * p.stdError.x + 1e-3);
  EXPECT_NEAR(p.stdError.x, std::sqrt(0.25 / 4096), 1e-3);
}

TEST(ReferenceObscurance, CornerMatchesIntegralOfMembership) {
  for (ref::Membership m : {ref::Membership::Sqrt, ref::Membership::Linear,
                            ref::Membership::Smoothstep, ref::Membership::Step}) {
    ref::Settings s = smallSettings(ref::Quantity::Obscurance, 128);
    s.radius = 0.5f;
    s.membership = m;
    const ref::Result r = ref::render(cornerScene(), s);
    ASSERT_TRUE(allFinite(r));
    checkAgainst(
        r,
        [&](glm::vec3 p) {
          const double d = distanceToOtherPlane(p);
          if (d < 0) return std::numeric_limits<double>::quiet_NaN();
          // O = 1 - (1/pi) int (1 - mu(t)) cos over the wall directions within R.
          return 1.0 - wallIntegral(d, s.radius, [&](double t) {
                   return 1.0 - ref::membership(m, float(t), s.radius);
                 });
        },
        0.005, 500, ref::membershipName(m), unitIntervalBound(r.spp));
  }
}

TEST(ReferenceAlchemy, CornerMatchesFalloffIntegral) {
  // The integral the Alchemy estimator claims: A = max(0, 1 - I)^k,
  // I = (1/pi) int_{t < r} g(t) cos, g(t) = sigma t / (max(u^2, t^2) + epsilon).
  ref::AlchemyParams eq10;  // the paper's final estimator (u = 0), intensity scaled down
  eq10.sigma = 0.05f;
  ref::AlchemyParams eq7;  // the falloff u t / max(u, t)^2, u = 0.1 r
  eq7.sigma = eq7.u = 0.05f;
  eq7.epsilon = 0.0f;
  eq7.contrast = 2.0f;
  for (const ref::AlchemyParams& a : {eq10, eq7}) {
    ref::Settings s = smallSettings(ref::Quantity::Alchemy, 128);
    s.radius = 0.5f;
    s.alchemy = a;
    const ref::Result r = ref::render(cornerScene(), s);
    ASSERT_TRUE(allFinite(r));
    checkAgainst(
        r,
        [&](glm::vec3 p) {
          const double d = distanceToOtherPlane(p);
          // Near the edge the falloff's 1/t makes the sample variance (and the bias of the
          // nonlinear max(0, .)^k of a sample mean) large: checked from d = 0.02 on.
          if (d < 0.02) return std::numeric_limits<double>::quiet_NaN();
          const double I =
              wallIntegral(d, s.radius, [&](double t) { return ref::alchemyFalloff(a, float(t)); });
          return std::pow(std::max(0.0, 1.0 - I), double(a.contrast));
        },
        0.005, 500, "alchemy",
        [&](double A) {
          // Samples g in [0, gMax]: variance at most I (gMax - I), through dA/dI.
          double gMax = 0.0;
          for (double t = 1e-4; t < s.radius; t *= 1.01)
            gMax = std::max(gMax, double(ref::alchemyFalloff(a, float(t))));
          const double k = a.contrast, I = 1.0 - std::pow(A, 1.0 / k);
          return k * std::pow(1.0 - I, k - 1.0) * std::sqrt(std::max(I * (gMax - I), 0.0) / r.spp);
        });
  }
}

TEST(ReferenceAO, SphereOnPlaneMatchesProjectedSolidAngleAndIsDarkestAtContact) {
  // Unbounded radius: a point on the plane at distance D from the contact point of a sphere of
  // radius R sees the whole sphere above its horizon, with projected solid angle
  // pi sin^2(alpha) cos(beta), sin(alpha) = R / L, cos(beta) = R / L, L^2 = D^2 + R^2:
  // AO = 1 - R^3 / (D^2 + R^2)^(3/2) (0 at the contact point).
  const float R = 0.5f;
  SceneBuilder b;
  b.add(parallelogram({-20, 0, 20}, {40, 0, 0}, {0, 0, -40}));
  b.add(sphere({0, R, 0}, R, 128, 64));
  b.camera({2.2f, 0.45f, 0.9f}, {0.0f, 0.0f, 0.0f}, 50.0f);
  ref::Settings s = smallSettings(ref::Quantity::AO, 128, 64, 48);
  s.radius = 1e4f;
  const ref::Result r = ref::render(b.done(), s);
  ASSERT_TRUE(allFinite(r));
  // Tessellation: the inscribed polyhedron is up to R (1 - cos(pi/128)) = 1.5e-4 R smaller.
  checkAgainst(
      r,
      [&](glm::vec3 p) {
        if (std::abs(p.y) > 1e-5f) return std::numeric_limits<double>::quiet_NaN();
        const double D2 = double(p.x) * p.x + double(p.z) * p.z;
        return 1.0 - std::pow(R, 3) / std::pow(D2 + R * R, 1.5);
      },
      0.01, 1000, "sphere on plane", unitIntervalBound(r.spp));
  // Darkest at the contact: binned by distance, the mean AO increases away from it.
  double sum[4] = {0, 0, 0, 0};
  int count[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < size_t(s.width) * s.height; ++i) {
    const PixelView p = pixel(r, i);
    if (!p.geometry || std::abs(p.position.y) > 1e-5f) continue;
    const float D = glm::length(glm::vec2(p.position.x, p.position.z));
    const int bin = D < 0.4f ? 0 : D < 0.7f ? 1 : D < 1.2f ? 2 : 3;
    sum[bin] += p.value.x;
    ++count[bin];
  }
  for (int i = 0; i < 4; ++i) ASSERT_GT(count[i], 5) << "bin " << i;
  for (int i = 0; i < 3; ++i) EXPECT_LT(sum[i] / count[i], sum[i + 1] / count[i + 1]);
}

// The lighting pass's BRDF for a punctual light on a dielectric (lights.glsl): rho / pi plus
// f0 = 0.04 times the normalised Blinn-Phong lobe (s + 8) / (8 pi) (n.h)^s, s = 2 / r^4 - 2.
glm::vec3 lightingBrdf(glm::vec3 rho, float roughness, glm::vec3 n, glm::vec3 l, glm::vec3 v) {
  const float s =
      std::clamp(2.0f / std::pow(std::max(roughness, 0.03f), 4.0f) - 2.0f, 1.0f, 4096.0f);
  const glm::vec3 h = glm::normalize(l + v);
  const float lobe = (s + 8.0f) / (8.0f * float(kPi)) * std::pow(std::max(glm::dot(n, h), 0.0f), s);
  return rho / float(kPi) + glm::vec3(0.04f * lobe);
}

TEST(ReferenceDirect, AnalyticLightsAndEnvironmentsOnAPlane) {
  const glm::vec3 albedo(0.5f, 0.6f, 0.7f);
  // Directional light (lux) tilted 30 degrees + constant environment (Lambert only): exact, no
  // variance.
  {
    SceneBuilder b;
    b.add(parallelogram({-50, 0, 50}, {100, 0, 0}, {0, 0, -100}), b.material(albedo));
    b.camera({0, 2, 3}, {0, 0, 0});
    const glm::mat4 sun = glm::rotate(glm::mat4(1.0f), glm::radians(-60.0f), glm::vec3(1, 0, 0));
    b.light(LightType::Directional, sun, glm::vec3(1.0f, 0.9f, 0.8f), 3.0f);
    b.constantEnvironment(glm::vec3(0.2f, 0.3f, 0.4f), 2.0f);
    const Scene scene = b.done();
    const glm::vec3 l = -glm::normalize(glm::vec3(sun * glm::vec4(0, 0, -1, 0)));
    const float roughness = scene.materials[0].roughness;
    const ref::Result r = ref::render(scene, smallSettings(ref::Quantity::Direct, 16));
    for (size_t i = 0; i < size_t(r.value.width) * r.value.height; ++i) {
      const PixelView p = pixel(r, i);
      if (!p.geometry) continue;
      const glm::vec3 v = glm::normalize(glm::vec3(0, 2, 3) - p.position);
      const glm::vec3 expected = lightingBrdf(albedo, roughness, {0, 1, 0}, l, v) *
                                     glm::vec3(1.0f, 0.9f, 0.8f) * 3.0f * l.y +
                                 albedo * glm::vec3(0.2f, 0.3f, 0.4f) * 2.0f;
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(p.value[c], expected[c], 1e-5f);
      ASSERT_EQ(p.stdError.x, 0.0f);
    }
  }
  // Point light (candela) at height h: f_r I cos / d^2; an occluding square between it
  // and the plane casts an exact shadow.
  {
    const glm::vec3 lightPos(0.3f, 1.5f, -0.2f);
    SceneBuilder b;
    b.add(parallelogram({-50, 0, 50}, {100, 0, 0}, {0, 0, -100}), b.material(albedo));
    b.add(parallelogram({-0.2f, 0.75f, 0.2f}, {0.4f, 0, 0}, {0, 0, -0.4f}), 0);
    b.camera({0, 2.5f, 3}, {0, 0, 0});
    b.light(LightType::Point, glm::translate(glm::mat4(1.0f), lightPos), glm::vec3(1.0f), 5.0f);
    b.constantEnvironment(glm::vec3(0.0f), 0.0f);
    const Scene scene = b.done();
    const float roughness = scene.materials[0].roughness;
    const ref::Result r = ref::render(scene, smallSettings(ref::Quantity::Direct, 4, 64, 48));
    int lit = 0, shadowed = 0;
    for (size_t i = 0; i < size_t(r.value.width) * r.value.height; ++i) {
      const PixelView p = pixel(r, i);
      if (!p.geometry || std::abs(p.position.y) > 1e-5f) continue;  // floor only
      // Where the segment to the light crosses y = 0.75 (the occluder's plane).
      const glm::vec3 toLight = lightPos - p.position;
      const glm::vec3 cross = p.position + toLight * (0.75f / toLight.y);
      const float margin = std::max(std::abs(cross.x), std::abs(cross.z)) - 0.2f;
      if (std::abs(margin) < 0.01f) continue;  // penumbra-free, but skip the pixel-exact edge
      const float d2 = glm::dot(toLight, toLight);
      const glm::vec3 l = toLight / std::sqrt(d2);
      const glm::vec3 v = glm::normalize(glm::vec3(0, 2.5f, 3) - p.position);
      const glm::vec3 expected =
          margin < 0 ? glm::vec3(0.0f)
                     : lightingBrdf(albedo, roughness, {0, 1, 0}, l, v) * 5.0f * l.y / d2;
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(p.value[c], expected[c], 1e-5f + 1e-5f * expected[c]);
      (margin < 0 ? shadowed : lit)++;
    }
    EXPECT_GT(lit, 500);
    EXPECT_GT(shadowed, 50);
  }
  // The procedural sky on an open plane facing up: (rho/pi) int L cos over the upper
  // hemisphere, with cos distributed as 2y dy, is rho (h + (z - h) int_0^1 sqrt(y) 2y dy)
  // = rho (h + 0.8 (z - h)).
  {
    SceneBuilder b;
    b.add(parallelogram({-50, 0, 50}, {100, 0, 0}, {0, 0, -100}), b.material(albedo));
    b.camera({0, 2, 3}, {0, 0, 0});
    Scene scene = b.done();
    scene.environment.intensity = 1.5f;
    const Environment& e = scene.environment;
    const glm::vec3 expected =
        albedo * e.intensity * (e.horizonColor + 0.8f * (e.zenithColor - e.horizonColor));
    const ref::Result r = ref::render(scene, smallSettings(ref::Quantity::Direct, 256, 16, 12));
    int checked = 0;
    for (size_t i = 0; i < size_t(r.value.width) * r.value.height; ++i) {
      const PixelView p = pixel(r, i);
      if (!p.geometry) {
        // Sky pixels hold the environment radiance (like the rasteriser's lit target).
        EXPECT_GT(p.value.z, 0.0f);
        continue;
      }
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(p.value[c], expected[c], 5.0f * p.stdError[c] + 2e-3f);
      ++checked;
    }
    EXPECT_GT(checked, 50);
  }
}

// A map that is dim (0.05) but for a small sun (1000, 2x2 texels of 64 x 32: 0.027 sr, 97% of
// the map's power) over an open plane: the environment is sampled by cosine and by the map's
// importance, combined by multiple importance sampling (Shading::environmentLight). The mean
// matches (rho / pi) int L cos (midpoint rule on a fine grid) within 2%, and the pixels'
// spread at 64 spp is below 0.6 of the mean (measured 0.41; 1.3 with cosine samples alone,
// which find the sun in 0.6% of the samples).
TEST(ReferenceDirect, SmallSunInAMapIsFoundByImportanceSampling) {
  const glm::vec3 albedo(0.5f);
  SceneBuilder b;
  b.add(parallelogram({-50, 0, 50}, {100, 0, 0}, {0, 0, -100}), b.material(albedo));
  b.camera({0, 2, 3}, {0, 0, 0});
  Scene scene = b.done();
  Environment& e = scene.environment;
  e.kind = Environment::Kind::Map;
  e.intensity = 1.0f;
  e.mapWidth = 64;
  e.mapHeight = 32;
  e.mapRGB.assign(64 * 32 * 3, 0.05f);
  for (int y : {7, 8})
    for (int x : {63, 0})
      for (int c = 0; c < 3; ++c) e.mapRGB[(size_t(y) * 64 + x) * 3 + c] = 1000.0f;
  const double exact = 0.5 * test::upperHemisphereIrradianceOverPi(e, false);
  const ref::Result r = ref::render(scene, smallSettings(ref::Quantity::Direct, 64));
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (size_t i = 0; i < size_t(r.value.width) * r.value.height; ++i) {
    const PixelView p = pixel(r, i);
    if (!p.geometry) continue;
    ASSERT_TRUE(std::isfinite(p.value.x));
    sum += p.value.x;
    sum2 += double(p.value.x) * p.value.x;
    ++n;
  }
  ASSERT_GT(n, 500);
  const double mean = sum / n, spread = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  std::printf("mean %.4f (exact %.4f), spread of the pixels %.4f\n", mean, exact, spread);
  EXPECT_NEAR(mean, exact, 0.02 * exact);
  EXPECT_LT(spread, 0.6 * mean);
}

TEST(ReferenceDirect, SpotConeAndRangeFollowTheRasteriser) {
  // Spot light straight down: inside the inner cone full intensity, outside the outer cone
  // nothing; the range window clamp(1 - (d^2/range^2)^2, 0, 1).
  SceneBuilder b;
  b.add(parallelogram({-50, 0, 50}, {100, 0, 0}, {0, 0, -100}), b.material(glm::vec3(1.0f)));
  b.camera({0, 1.5f, 0.01f}, {0, 0, 0}, 90.0f);
  const glm::mat4 spot = glm::translate(glm::mat4(1.0f), glm::vec3(0, 1, 0)) *
                         glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), glm::vec3(1, 0, 0));
  b.light(LightType::Spot, spot, glm::vec3(1.0f), 2.0f);
  b.constantEnvironment(glm::vec3(0.0f), 0.0f);
  Scene scene = b.done();
  scene.lights[0].innerConeAngle = glm::radians(20.0f);
  scene.lights[0].outerConeAngle = glm::radians(30.0f);
  scene.lights[0].range = 1.3f;
  const ref::Result r = ref::render(scene, smallSettings(ref::Quantity::Direct, 1, 64, 64));
  int inner = 0, outer = 0;
  for (size_t i = 0; i < size_t(r.value.width) * r.value.height; ++i) {
    const PixelView p = pixel(r, i);
    if (!p.geometry) continue;
    const float rho = glm::length(glm::vec2(p.position.x, p.position.z));
    const float angle = std::atan(rho);  // light at height 1
    const float d2 = rho * rho + 1.0f;
    if (angle < glm::radians(19.5f)) {
      const float window = std::clamp(1.0f - std::pow(d2 / (1.3f * 1.3f), 2.0f), 0.0f, 1.0f);
      const glm::vec3 l = glm::normalize(-p.position + glm::vec3(0, 1, 0));
      const glm::vec3 v = glm::normalize(glm::vec3(0, 1.5f, 0.01f) - p.position);
      const float expected =
          lightingBrdf(glm::vec3(1.0f), scene.materials[0].roughness, {0, 1, 0}, l, v).x * 2.0f /
          d2 * std::cos(angle) * window;
      EXPECT_NEAR(p.value.x, expected, 1e-5f);
      ++inner;
    } else if (angle > glm::radians(30.5f)) {
      EXPECT_EQ(p.value.x, 0.0f);
      ++outer;
    }
  }
  EXPECT_GT(inner, 100);
  EXPECT_GT(outer, 100);
}

TEST(ReferenceIndirect, InfiniteCornerUnderConstantSkyHasClosedForm) {
  // Floor and wall of albedo a under a constant environment L (r unbounded, planes large):
  // a floor point sees the wall over half of its cosine-weighted hemisphere at any d > 0, and
  // every wall point sees the floor over half of its own. Direct = a L / 2; the bounce adds
  // a * (1/2) * (a L / 2). So direct+indirect = a L / 2 + a^2 L / 4, independent of d.
  const float a = 0.6f, L = 1.5f;
  SceneBuilder b;
  const int grey = b.material(glm::vec3(a));
  addCorner(b, 2000.0f, grey, grey);
  b.camera({1.1f, 0.9f, 0.9f}, {0.2f, 0.15f, 0.0f}, 55.0f);
  b.constantEnvironment(glm::vec3(1.0f), L);
  const Scene scene = b.done();
  auto expected = [&](double direct, double indirect) {
    return [=](glm::vec3 p) {
      return distanceToOtherPlane(p) < 0 ? std::numeric_limits<double>::quiet_NaN()
                                         : direct + indirect;
    };
  };
  ref::Settings s = smallSettings(ref::Quantity::Direct, 64, 32, 24);
  checkAgainst(ref::render(scene, s), expected(a * L / 2, 0), 0.005, 300, "direct");
  s.quantity = ref::Quantity::DirectIndirect;
  checkAgainst(ref::render(scene, s), expected(a * L / 2, a * a * L / 4), 0.005, 300,
               "direct+indirect");
  // k bounces: every point's outgoing radiance is a L / 2 + (a / 2) x the other plane's after
  // k - 1 bounces, so direct+indirect = a L / 2 (1 + a/2 + ... + (a/2)^k).
  for (uint32_t k : {2u, 3u}) {
    s.bounces = k;
    double sum = 0.0;
    for (uint32_t i = 1; i <= k; ++i) sum += std::pow(a / 2.0, double(i));
    checkAgainst(ref::render(scene, s), expected(a * L / 2, a * L / 2 * sum), 0.005, 300,
                 k == 2 ? "2 bounces" : "3 bounces");
  }
}

TEST(ReferenceIndirect, BouncesOutsideOneToEightAreRefused) {
  SceneBuilder b;
  addCorner(b, 10.0f, b.material(glm::vec3(0.5f)), b.material(glm::vec3(0.5f)));
  b.camera({1.1f, 0.9f, 0.9f}, {0.2f, 0.15f, 0.0f}, 55.0f);
  const Scene scene = b.done();
  ref::Settings s = smallSettings(ref::Quantity::DirectIndirect, 1, 4, 4);
  for (uint32_t k : {0u, ref::kMaxBounces + 1}) {
    s.bounces = k;
    EXPECT_THROW(ref::render(scene, s), Error) << k;
  }
}

TEST(ReferenceIndirect, EmissiveSurfacesLightOnlyTheBounce) {
  // A black emissive wall Le next to a floor of albedo a, no environment: direct = 0 (emitters
  // are not lights there), direct+indirect = a Le / 2 on the floor, Le on the wall itself.
  const float a = 0.5f, Le = 3.0f;
  SceneBuilder b;
  const int floorMat = b.material(glm::vec3(a));
  const int wallMat = b.material(glm::vec3(0.0f), glm::vec3(Le));
  addCorner(b, 2000.0f, floorMat, wallMat);
  b.camera({1.1f, 0.9f, 0.9f}, {0.2f, 0.15f, 0.0f}, 55.0f);
  b.constantEnvironment(glm::vec3(0.0f), 0.0f);
  const Scene scene = b.done();
  auto onFloor = [](glm::vec3 p) { return std::abs(p.y) < 1e-5f && p.x > 1e-5f; };
  ref::Settings s = smallSettings(ref::Quantity::Direct, 16, 32, 24);
  checkAgainst(
      ref::render(scene, s), [&](glm::vec3 p) { return onFloor(p) ? 0.0 : Le; }, 1e-6, 300,
      "direct");
  s.quantity = ref::Quantity::DirectIndirect;
  s.spp = 256;
  checkAgainst(
      ref::render(scene, s), [&](glm::vec3 p) { return onFloor(p) ? a * Le / 2 : Le; }, 0.005, 300,
      "direct+indirect");
  // Emitters seen but lighting nothing: the floor is dark, the wall keeps its radiance, at any
  // number of bounces.
  s.emitterLight = false;
  for (uint32_t k : {1u, 3u}) {
    s.bounces = k;
    checkAgainst(
        ref::render(scene, s), [&](glm::vec3 p) { return onFloor(p) ? 0.0 : Le; }, 1e-6, 300,
        "direct+indirect without emitter light");
  }
}

// Form factor from a differential area to a parallel rectangle at height h with one corner
// straight above it, extents X h and Y h (signed: odd in X and in Y).
double cornerFormFactor(double X, double Y) {
  const double a = std::sqrt(1 + X * X), b = std::sqrt(1 + Y * Y);
  return (X / a * std::atan(Y / a) + Y / b * std::atan(X / b)) / (2 * kPi);
}

TEST(ReferenceIndirect, SmallEmitterIsSampledDirectly) {
  // A small emissive square (side 0.3, Le, albedo 0) at height 1 facing the floor (albedo a):
  // the floor's radiance is a Le F, F the form factor to the rectangle. Cosine sampling alone
  // would hit it in ~3% of the directions (relative error ~0.7 at 64 samples); sampling the
  // emitter makes the estimate nearly exact.
  const float a = 0.5f, Le = 20.0f, half = 0.15f;
  SceneBuilder b;
  b.add(parallelogram({-5, 0, 5}, {10, 0, 0}, {0, 0, -10}), b.material(glm::vec3(a)));
  b.add(parallelogram({-half, 1, -half}, {2 * half, 0, 0}, {0, 0, 2 * half}),
        b.material(glm::vec3(0.0f), glm::vec3(Le)));
  b.camera({0, 0.6f, 2.0f}, {0, 0, -0.3f}, 60.0f);
  b.constantEnvironment(glm::vec3(0.0f), 0.0f);
  ref::Settings s = smallSettings(ref::Quantity::DirectIndirect, 64, 32, 24);
  const ref::Result r = ref::render(b.done(), s);
  double relativeError = 0.0;
  int floor = 0;
  checkAgainst(
      r,
      [&](glm::vec3 p) {
        if (std::abs(p.y) > 1e-5f || std::abs(p.x) > 4 || std::abs(p.z) > 4)
          return std::numeric_limits<double>::quiet_NaN();
        const double X0 = (-half - p.x), X1 = (half - p.x), Y0 = (-half - p.z), Y1 = (half - p.z);
        const double F = cornerFormFactor(X1, Y1) - cornerFormFactor(X0, Y1) -
                         cornerFormFactor(X1, Y0) + cornerFormFactor(X0, Y0);
        return a * Le * F;
      },
      0.002, 300, "small emitter");
  for (size_t i = 0; i < size_t(s.width) * s.height; ++i) {
    const PixelView p = pixel(r, i);
    if (!p.geometry || std::abs(p.position.y) > 1e-5f || p.value.x < 0.05f) continue;
    relativeError += p.stdError.x / p.value.x;
    ++floor;
  }
  ASSERT_GT(floor, 100);
  EXPECT_LT(relativeError / floor, 0.05) << "the emitter must be importance sampled";
}

TEST(ReferenceDepth, PrimaryHitsFollowTheVulkanConventions) {
  // A plane facing the camera at distance 5 (as in test_render_gbuffer): view z = -5, NDC depth
  // = proj applied to it, normal (0, 0, 1) in view space, sky marked 0.
  SceneBuilder b;
  b.add(parallelogram({-1, -1, -5}, {2, 0, 0}, {0, 2, 0}));
  b.camera({0, 0, 0}, {0, 0, -1}, 60.0f, 0.1f, 100.0f);
  const Scene scene = b.done();
  ref::Settings s = smallSettings(ref::Quantity::Depth, 1, 160, 120);
  const ref::Result r = ref::render(scene, s);
  ASSERT_TRUE(allFinite(r));
  const CameraView cam = activeCamera(scene, 160.0f / 120.0f);
  const glm::vec4 clip = cam.proj * glm::vec4(0, 0, -5, 1);
  int plane = 0;
  for (size_t i = 0; i < 160 * 120; ++i) {
    const float* d = &r.depth.pixels[i * 4];
    const float* n = &r.normal.pixels[i * 4];
    if (d[3] == 0.0f) {
      EXPECT_EQ(d[0], 0.0f);
      EXPECT_EQ(d[2], 0.0f);
      EXPECT_EQ(n[3], 0.0f);
      continue;
    }
    ++plane;
    EXPECT_EQ(d[2], 1.0f);  // the sky mask
    EXPECT_NEAR(d[1], -5.0f, 5e-6f);
    EXPECT_NEAR(d[0], clip.z / clip.w, 1e-7f);
    EXPECT_NEAR(n[2], 1.0f, 1e-6f);
    // The value image of the depth quantity is the depth image.
    EXPECT_EQ(r.value.pixels[i * 4], d[0]);
  }
  // The plane's projected size, as in test_render_gbuffer: within a pixel row/column.
  const double expected = std::pow(1.0 / (5.0 * std::tan(glm::radians(30.0))), 2) * 120.0 / 160.0;
  EXPECT_NEAR(plane / (160.0 * 120.0), expected, 0.01);
  // Pixel centres: the pixel left of the image centre sees x = -(0.5 / 80) * aspect * tan(30) * 5.
  const size_t centreLeft = 60 * 160 + 79;
  const float expectedX = -0.5f / 80.0f * (160.0f / 120.0f) * std::tan(glm::radians(30.0f)) * 5;
  EXPECT_NEAR(r.position.pixels[centreLeft * 4], expectedX, 1e-5f);
  // Row 60 is just below the centre: y grows downwards in the image, upwards in the world.
  EXPECT_NEAR(r.position.pixels[centreLeft * 4 + 1],
              -0.5f / 60.0f * std::tan(glm::radians(30.0f)) * 5, 1e-5f);
}

TEST(ReferenceDeterminism, SameSeedAnyThreadCountGivesTheSameImage) {
  const Scene scene = loadScene("default");
  for (ref::Quantity q :
       {ref::Quantity::AO, ref::Quantity::DirectIndirect, ref::Quantity::AlchemyDisk}) {
    ref::Settings s = smallSettings(q, 8, 40, 30);
    s.seed = 7;
    s.threads = 1;
    const ref::Result a = ref::render(scene, s);
    s.threads = 3;
    const ref::Result b = ref::render(scene, s);
    const ref::Result c = ref::render(scene, s);
    s.seed = 8;
    const ref::Result d = ref::render(scene, s);
    EXPECT_EQ(a.value.pixels, b.value.pixels) << ref::quantityName(q);
    EXPECT_EQ(a.stdError.pixels, b.stdError.pixels);
    EXPECT_EQ(b.value.pixels, c.value.pixels);
    EXPECT_NE(a.value.pixels, d.value.pixels) << "a different seed must give other samples";
    EXPECT_TRUE(allFinite(a));
  }
}

TEST(ReferenceProgressive, StopsAtTheNoiseTarget) {
  const Scene scene = loadScene("default");
  ref::Settings s = smallSettings(ref::Quantity::AO, 1024, 32, 24);
  s.noiseTarget = 0.05;
  std::vector<ref::Progress> passes;
  s.progress = [&](const ref::Progress& p) { passes.push_back(p); };
  const ref::Result r = ref::render(scene, s);
  EXPECT_LT(r.spp, 1024u);
  EXPECT_LE(r.meanStdError, 0.05);
  ASSERT_GE(passes.size(), 2u);
  EXPECT_GT(passes[passes.size() - 2].meanStdError, 0.05) << "stopped at the first pass below";
  EXPECT_EQ(passes.back().spp, r.spp);
  // The error shrinks like 1/sqrt(n).
  EXPECT_NEAR(passes.front().meanStdError * std::sqrt(passes.front().spp / double(r.spp)),
              r.meanStdError, 0.2 * r.meanStdError);
  // The same render up to that count without a target gives the same image.
  ref::Settings fixed = s;
  fixed.noiseTarget = 0.0;
  fixed.spp = r.spp;
  fixed.progress = nullptr;
  EXPECT_EQ(ref::render(scene, fixed).value.pixels, r.value.pixels);
}

TEST(ReferenceRobustness, DegenerateInputGivesNoNan) {
  const std::vector<ref::Quantity> all = {
      ref::Quantity::AO,     ref::Quantity::Obscurance,     ref::Quantity::Alchemy,
      ref::Quantity::Direct, ref::Quantity::DirectIndirect, ref::Quantity::Depth,
      ref::Quantity::Normal, ref::Quantity::AlchemyDisk};
  auto renderAll = [&](const Scene& scene, const char* what) {
    for (ref::Quantity q : all) {
      ref::Settings s = smallSettings(q, 4, 24, 18);
      const ref::Result r = ref::render(scene, s);
      EXPECT_TRUE(allFinite(r)) << what << ", " << ref::quantityName(q);
    }
  };
  // Empty scene: all sky (AO 1, environment radiance, depth 0).
  {
    Scene empty;
    empty.updateWorldTransforms();
    for (ref::Quantity q : all) {
      const ref::Result r = ref::render(empty, smallSettings(q, 4, 24, 18));
      EXPECT_TRUE(allFinite(r));
      EXPECT_EQ(r.geometryPixels, 0u);
      for (size_t i = 0; i < 24 * 18; ++i) {
        EXPECT_EQ(r.depth.pixels[i * 4], 0.0f);
        EXPECT_EQ(r.value.pixels[i * 4 + 3], 0.0f);
        if (q == ref::Quantity::AO) {
          EXPECT_EQ(r.value.pixels[i * 4], 1.0f);
        }
      }
    }
  }
  // Camera inside a closed box and inside a sphere: everything is geometry, all finite.
  {
    SceneBuilder b;
    const float h = 1.0f;
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {-1.0f, 1.0f}) {
        glm::vec3 n(0.0f), u(0.0f), v(0.0f);
        n[axis] = sign * h;
        u[(axis + 1) % 3] = 2 * h;
        v[(axis + 2) % 3] = 2 * h;
        b.add(parallelogram(n - 0.5f * u - 0.5f * v, u, v));
      }
    b.add(sphere({0.2f, 0.1f, 0.0f}, 0.3f, 16, 8));
    b.camera({0.2f, 0.1f, 0.0f}, {0, 0, -1}, 90.0f);  // at the sphere's centre
    b.light(LightType::Point, glm::mat4(1.0f), glm::vec3(1.0f), 1.0f);
    const Scene scene = b.done();
    renderAll(scene, "camera inside geometry");
    EXPECT_EQ(ref::render(scene, smallSettings(ref::Quantity::AO, 4, 24, 18)).geometryPixels,
              24u * 18u);
  }
  // Zero vertex normals, a zero-area triangle, a NaN vertex, a node scaled to zero, a light on
  // the surface, out-of-range material and texture indices.
  {
    SceneBuilder b;
    Mesh m = parallelogram({-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, 2);
    for (Vertex& v : m.vertices) v.normal = glm::vec3(0.0f);
    m.indices.insert(m.indices.end(), {0, 0, 1});  // zero area
    m.vertices.push_back({glm::vec3(std::numeric_limits<float>::quiet_NaN()), {0, 1, 0}, {}});
    m.indices.insert(m.indices.end(), {0, 1, uint32_t(m.vertices.size() - 1)});
    b.add(m);
    b.add(parallelogram({-1, 0.5f, 1}, {2, 0, 0}, {0, 0, -2}), 0,
          glm::scale(glm::mat4(1.0f), glm::vec3(1, 0, 1)));
    Mesh bad = parallelogram({-1, 1, 1}, {2, 0, 0}, {0, 0, -2});
    b.add(bad, 7);
    b.light(LightType::Point, glm::mat4(1.0f), glm::vec3(1.0f), 1.0f);
    b.camera({0.5f, 2, 2}, {0, 0, 0});
    Scene scene = b.done();
    scene.materials[0].baseColorTexture = 3;
    renderAll(scene, "degenerate geometry");
  }
}

TEST(ReferenceSettings, InvalidSettingsAreUsageErrors) {
  const Scene scene = loadScene("default");
  auto expectUsage = [&](ref::Settings s) {
    try {
      ref::render(scene, s);
      ADD_FAILURE() << "expected a usage error";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage) << e.what();
    }
  };
  ref::Settings s = smallSettings(ref::Quantity::AO, 4);
  s.radius = 0.0f;
  expectUsage(s);
  s = smallSettings(ref::Quantity::AO, 0);
  expectUsage(s);
  s = smallSettings(ref::Quantity::AO, 4, 0, 10);
  expectUsage(s);
  s = smallSettings(ref::Quantity::Alchemy, 4);
  s.alchemy.contrast = 0.0f;
  expectUsage(s);
  s = smallSettings(ref::Quantity::Alchemy, 4);
  s.alchemy.epsilon = 0.0f;  // with u = 0: an unbounded falloff (standard error 6.6e9 before)
  expectUsage(s);
  EXPECT_THROW(ref::parseQuantity("bent"), Error);
  EXPECT_EQ(ref::parseQuantity("direct+indirect"), ref::Quantity::DirectIndirect);
  EXPECT_EQ(ref::parseMembership("sqrt"), ref::Membership::Sqrt);
}

// --- command line ---------------------------------------------------------------------------

std::string cli(const std::string& args) {
  return test::binPath("gi-reference") + " --quiet " + args;
}

TEST(ReferenceCli, WritesEstimateErrorPreviewAndReportsTheRun) {
  const std::string dir = test::makeTempDir("reference-cli");
  auto r =
      test::runCommand(cli("--scene default --quantity ao --radius 0.5 --spp 8 --width 40 "
                           "--height 30 --seed 3 --threads 2 --out '" +
                           dir + "/ao.pfm' --png '" + dir + "/ao.png' --gbuffer '" + dir + "/g'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("8 samples per pixel"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("mean standard error"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("time "), std::string::npos) << r.output;
  const ImageRGBA32F ao = readPfm(dir + "/ao.pfm");
  EXPECT_EQ(ao.width, 40);
  EXPECT_EQ(ao.height, 30);
  for (const char* f : {"/ao.stderr.pfm", "/g_depth.pfm", "/g_normal.pfm", "/g_position.pfm"})
    EXPECT_TRUE(allFinite(readPfm(dir + f))) << f;
  EXPECT_EQ(readPng(dir + "/ao.png").width, 40);
  // The library with the same settings gives the same image (PFM keeps floats exactly).
  ref::Settings s = smallSettings(ref::Quantity::AO, 8, 40, 30);
  s.seed = 3;
  const ref::Result lib = ref::render(loadScene("default"), s);
  for (size_t i = 0; i < 40 * 30; ++i) ASSERT_EQ(ao.pixels[i * 4], lib.value.pixels[i * 4]);
}

TEST(ReferenceCli, BadInputFailsWithOneLineAndNoOutput) {
  const std::string dir = test::makeTempDir("reference-cli-bad");
  struct Case {
    std::string args, mention;
    int exitCode;
  };
  const std::string out = " --out '" + dir + "/x.pfm' --png '" + dir + "/x.png'";
  for (const Case& c :
       std::vector<Case>{{"--scene '" + dir + "/missing.json'" + out, "missing.json", 1},
                         {"--scene default --quantity bent" + out, "bent", 2},
                         {"--scene default --radius -1" + out, "--radius", 2},
                         {"--scene default --radius 0" + out,
                          "--radius: expects a number in (0, 1e9], got '0'", 2},
                         {"--scene default --spp 1.5" + out, "is not an integer", 2},
                         {"--scene default --width 0x20" + out, "is hexadecimal", 2},
                         {"--scene default --quantity alchemy --alchemy-epsilon 0" + out,
                          "epsilon must be > 0 when u = 0", 2},
                         {"--scene default --out /sys/gi-test.pfm", "cannot write in", 1},
                         {"--scene default --out /sys/gi-nodir/x.pfm", "cannot write in", 1},
                         {"--scene default --out '" + dir + "/x.png'", "x.png", 2},
                         {"--scene default", "--out", 2}}) {
    auto r = test::runCommand(cli(c.args));
    EXPECT_EQ(r.exitCode, c.exitCode) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find("gi-reference: error"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.mention), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_TRUE(std::filesystem::is_empty(dir)) << c.args << " left files behind";
  }
}

}  // namespace
}  // namespace gi
