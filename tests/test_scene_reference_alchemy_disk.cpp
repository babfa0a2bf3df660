// The CPU reference's alchemy-disk quantity (gi-reference --quantity alchemy-disk): the
// screen-disk integral that the Alchemy estimator's sum converges to (reference.h,
// effects/alchemy/README.md). A plane gives A = 1 exactly (perspective and orthographic, with
// the plugin's default bias); on a 90-degree crease seen orthographically it reproduces the
// README's script-integrated table of I_disk; the sample mean is unbiased against a direct
// quadrature of the same integral; the bias, u and contrast act as stated; settings are checked.
// CPU only (no Vulkan).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/errors.h"
#include "gi/reference/reference.h"
#include "test_support.h"

namespace gi {
namespace {

namespace ref = gi::reference;
constexpr double kPi = 3.14159265358979323846;

// The parallelogram corner + s e1 + t e2 (s, t in [0, 1]), facing cross(e1, e2).
Mesh parallelogram(glm::vec3 corner, glm::vec3 e1, glm::vec3 e2) {
  Mesh m;
  m.name = "parallelogram";
  const glm::vec3 normal = glm::normalize(glm::cross(e1, e2));
  m.vertices = {{corner, normal, {0, 0}},
                {corner + e1, normal, {1, 0}},
                {corner + e1 + e2, normal, {1, 1}},
                {corner + e2, normal, {0, 1}}};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.boundsMin = glm::min(glm::min(corner, corner + e1 + e2), glm::min(corner + e1, corner + e2));
  m.boundsMax = glm::max(glm::max(corner, corner + e1 + e2), glm::max(corner + e1, corner + e2));
  return m;
}

Scene sceneOf(const std::vector<Mesh>& meshes) {
  Scene s;
  s.sourcePath = "test";
  s.materials.emplace_back();
  for (const Mesh& m : meshes) {
    s.meshes.push_back(m);
    s.nodes[s.addNode("mesh", glm::mat4(1.0f))].meshes = {int(s.meshes.size()) - 1};
  }
  s.updateWorldTransforms();
  return s;
}

// Floor y = 0 (x in [0, 4], facing +y) meeting the wall x = 0 (y in [0, 4], facing +x), both
// over z in [-2, 2]: far larger than r = 0.5 around the points tested.
Scene creaseScene() {
  return sceneOf({parallelogram({0, 0, 2}, {4, 0, 0}, {0, 0, -4}),
                  parallelogram({0, 0, -2}, {0, 4, 0}, {0, 0, 4})});
}

// A camera looking at `target` along `forward` from 3 units away; orthographic (half height
// 0.1) or perspective (50 degrees).
CameraView cameraAt(glm::vec3 target, glm::vec3 forward, bool orthographic, float aspect = 1.0f) {
  CameraView c;
  c.position = target - 3.0f * glm::normalize(forward);
  c.view = glm::lookAt(c.position, target, glm::vec3(0, 1, 0));
  c.znear = 0.01f;
  c.zfar = 20.0f;
  c.yfov = glm::radians(50.0f);
  c.proj = orthographic ? orthoReverseZ(-0.1f * aspect, 0.1f * aspect, -0.1f, 0.1f, c.znear, c.zfar)
                        : perspectiveReverseZ(c.yfov, aspect, c.znear, c.zfar);
  return c;
}

ref::Settings diskSettings(uint32_t spp, uint32_t w, uint32_t h) {
  ref::Settings s;
  s.quantity = ref::Quantity::AlchemyDisk;
  s.width = w;
  s.height = h;
  s.spp = spp;
  s.radius = 0.5f;
  s.threads = 2;
  return s;
}

TEST(ReferenceAlchemyDisk, PlaneGivesExactlyOne) {
  // Every tap lands on the plane: v.n is 0 up to float rounding of the hit points, which the
  // plugin's default bias (1e-4 x view depth) absorbs, so every sample is 0 and A is exactly 1.
  const Scene plane = sceneOf({parallelogram({-50, 0, 50}, {100, 0, 0}, {0, 0, -100})});
  for (bool ortho : {false, true})
    for (float elevation : {90.0f, 40.0f, 12.0f}) {
      const float e = glm::radians(elevation);
      ref::Settings s = diskSettings(64, 24, 18);
      s.alchemy.bias = 1e-4f;
      s.camera = cameraAt({0.3f, 0, -0.2f}, {0.01f, -std::sin(e), -std::cos(e)}, ortho, 24.f / 18);
      const ref::Result r = ref::render(plane, s);
      ASSERT_GT(r.geometryPixels, size_t(24 * 18 / 2));  // sky above the horizon is 1 too
      for (size_t i = 0; i < size_t(24 * 18); ++i) {
        ASSERT_EQ(r.value.pixels[i * 4], 1.0f) << "pixel " << i << " elevation " << elevation;
        ASSERT_EQ(r.stdError.pixels[i * 4], 0.0f);
      }
    }
}

// The README's table ("What the estimator's expectation really is"): I_disk for a floor point at
// distance d from the wall, orthographic view facing the wall at elevation e, r = 0.5,
// sigma = 1, epsilon = 1e-4, bias 0; script-integrated to about 1 % and printed to 2 decimals.
// Rendered at sigma = 0.1 (A = 1 - 0.1 I stays unclamped), one pixel through the point, 2^20
// samples: within 1 % + 0.005 (the table's rounding) + 4 standard errors.
TEST(ReferenceAlchemyDisk, CreaseReproducesTheReadmeTable) {
  struct Case {
    double d, elevation, table;
  };
  const Scene scene = creaseScene();
  for (const Case& c : {Case{0.05, 20, 2.48}, Case{0.1, 45, 1.24}, Case{0.2, 20, 0.87},
                        Case{0.05, 70, 1.17}, Case{0.3, 45, 0.28}}) {
    const float e = glm::radians(float(c.elevation));
    ref::Settings s = diskSettings(1u << 20, 1, 1);
    s.alchemy.sigma = 0.1f;
    s.camera = cameraAt({float(c.d), 0, 0}, {-std::cos(e), -std::sin(e), 0}, true);
    const ref::Result r = ref::render(scene, s);
    ASSERT_EQ(r.geometryPixels, 1u);
    ASSERT_NEAR(r.position.pixels[0], c.d, 1e-5) << "the pixel must see the floor point";
    const double I = (1.0 - r.value.pixels[0]) / 0.1, se = r.stdError.pixels[0] / 0.1;
    std::printf("crease d %.2f elevation %.0f: I_disk %.4f +- %.4f (README %.2f)\n", c.d,
                c.elevation, I, se, c.table);
    EXPECT_NEAR(I, c.table, 0.01 * c.table + 0.005 + 4 * se) << c.d << " " << c.elevation;
    EXPECT_LT(se, 0.005 * c.table) << "enough samples for the comparison to bite";
  }
}

// The same integral by quadrature, traced analytically: the crease point at distance d seen
// orthographically at elevation e (camera right = -z, up = (-sin e, cos e, 0)); taps on the disk
// hit the floor (y = 0, x >= 0) or the wall (x = 0, y >= 0) along the view direction.
double creaseDiskQuadrature(double d, double elevDeg, const ref::AlchemyParams& a, double r) {
  const double e = elevDeg * kPi / 180.0;
  const glm::dvec3 fwd(-std::cos(e), -std::sin(e), 0), up(-std::sin(e), std::cos(e), 0),
      right(0, 0, -1), c(d, 0, 0), n(0, 1, 0);
  const int nr = 600, na = 600;
  double sum = 0.0;
  for (int i = 0; i < nr; ++i)
    for (int j = 0; j < na; ++j) {
      const double rho = (i + 0.5) / nr * r, phi = (j + 0.5) / na * 2 * kPi;
      const glm::dvec3 x = c + rho * (std::cos(phi) * right + std::sin(phi) * up);
      // First hit of x + t fwd over all t (the line through x; the camera is far behind).
      double best = 1e30;
      glm::dvec3 p(0.0);
      const double tf = -x.y / fwd.y;  // floor
      if (x.x + tf * fwd.x >= 0) best = tf, p = x + tf * fwd;
      const double tw = -x.x / fwd.x;  // wall
      if (x.y + tw * fwd.y >= 0 && tw < best) best = tw, p = x + tw * fwd;
      if (best > 1e29) continue;
      const glm::dvec3 v = p - c;
      const double vv = dot(v, v);
      if (!(vv < r * r)) continue;
      const double z = 3.0;  // C's view depth (the camera is 3 units away)
      sum += std::max(0.0, dot(v, n) - a.bias * z) / (std::max(double(a.u) * a.u, vv) + a.epsilon);
    }
  return a.sigma / (kPi * r) * sum * (r / nr) * (2 * kPi / na);
}

TEST(ReferenceAlchemyDisk, UnbiasedAgainstQuadratureWithBiasUAndContrast) {
  // Bias and u change the integrand as documented (quadrature of the same integrand), and
  // contrast k maps the same mean through max(0, 1 - I)^k.
  ref::AlchemyParams plain;
  plain.sigma = 0.2f;
  ref::AlchemyParams biased = plain;
  biased.bias = 0.02f;  // 0.06 at view depth 3: removes the taps barely above the floor
  ref::AlchemyParams knee = plain;
  knee.u = 0.1f;
  knee.contrast = 2.0f;
  const Scene scene = creaseScene();
  for (const ref::AlchemyParams& a : {plain, biased, knee}) {
    const double d = 0.15, elev = 30;
    const float e = glm::radians(float(elev));
    ref::Settings s = diskSettings(1u << 18, 1, 1);
    s.alchemy = a;
    s.camera = cameraAt({float(d), 0, 0}, {-std::cos(e), -std::sin(e), 0}, true);
    const ref::Result r = ref::render(scene, s);
    const double expectedI = creaseDiskQuadrature(d, elev, a, 0.5);
    const double expectedA = std::pow(std::max(0.0, 1.0 - expectedI), double(a.contrast));
    std::printf("bias %g u %g k %g: A %.5f +- %.5f, quadrature %.5f\n", a.bias, a.u, a.contrast,
                r.value.pixels[0], r.stdError.pixels[0], expectedA);
    EXPECT_NEAR(r.value.pixels[0], expectedA, 4 * r.stdError.pixels[0] + 1e-3 * expectedI);
  }
  EXPECT_LT(creaseDiskQuadrature(0.15, 30, biased, 0.5),
            0.95 * creaseDiskQuadrature(0.15, 30, plain, 0.5));
  // The knee only matters for occluders nearer than u: at d = 0.15 the wall is beyond it.
  EXPECT_LT(creaseDiskQuadrature(0.05, 30, knee, 0.5),
            0.95 * creaseDiskQuadrature(0.05, 30, plain, 0.5));
}

TEST(ReferenceAlchemyDisk, SettingsAndNames) {
  EXPECT_EQ(ref::parseQuantity("alchemy-disk"), ref::Quantity::AlchemyDisk);
  EXPECT_STREQ(ref::quantityName(ref::Quantity::AlchemyDisk), "alchemy-disk");
  const Scene scene = creaseScene();
  auto expectUsage = [&](const ref::Settings& s) {
    try {
      ref::render(scene, s);
      ADD_FAILURE() << "expected a usage error";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage) << e.what();
    }
  };
  ref::Settings s = diskSettings(4, 8, 6);
  s.alchemy.bias = -1.0f;
  expectUsage(s);
  s = diskSettings(4, 8, 6);
  s.alchemy.epsilon = 0.0f;  // and u = 0: a tap on C itself would be 0 / 0
  expectUsage(s);
  s = diskSettings(4, 8, 6);
  s.quantity = ref::Quantity::AOSplit;
  s.camera = cameraAt({0.2f, 0, 0}, {-1, -1, 0}, true);
  expectUsage(s);  // the AO split measures along eye rays
  s.camera->zfar = s.camera->znear;
  s.quantity = ref::Quantity::AlchemyDisk;
  expectUsage(s);
  // Sky pixels are open, and the values stay finite with a camera inside the ball.
  s = diskSettings(16, 8, 6);
  s.camera = cameraAt({0.05f, 0.05f, 0}, {-1, -0.3f, 0}, false);
  s.camera->view =
      glm::lookAt(glm::vec3(0.1f, 0.1f, 0), glm::vec3(-1, 0.1f, 1), glm::vec3(0, 1, 0));
  const ref::Result r = ref::render(scene, s);
  for (float v : r.value.pixels) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f && v <= 1.0f);
}

}  // namespace
}  // namespace gi
