// Area-uniform surface points (gi/surface_points.h) on the CPU: the sampler's density is
// uniform by area (chi-square over triangles and inside one triangle), deterministic for a
// seed, never picks zero-area triangles, and the evaluated points lie on the (posed) surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/animation.h"
#include "gi/scene_io.h"
#include "gi/surface_points.h"
#include "test_support.h"

namespace gi {
namespace {

// One mesh of `triangles` (world positions), drawn by one node with transform `world`.
Scene triangleScene(const std::vector<glm::vec3>& corners, const glm::mat4& world) {
  Scene s;
  Mesh m;
  for (const glm::vec3& p : corners) m.vertices.push_back({p, {0, 0, 1}, {0, 0}});
  for (uint32_t i = 0; i < corners.size(); ++i) m.indices.push_back(i);
  s.meshes.push_back(m);
  s.materials.emplace_back();
  const int node = s.addNode("mesh", world);
  s.nodes[node].meshes.push_back(0);
  s.updateWorldTransforms();
  return s;
}

// Upper-tail chi-square bound: mean k, sd sqrt(2k); 5 sd is far beyond any fixed-seed
// fluctuation of a correct sampler, and far below what a wrong density gives (tests below).
double chiSquareLimit(size_t bins) {
  const double k = double(bins - 1);
  return k + 5.0 * std::sqrt(2.0 * k);
}

double chiSquare(const std::vector<double>& observed, const std::vector<double>& expected) {
  double chi = 0.0;
  for (size_t i = 0; i < observed.size(); ++i)
    chi += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
  return chi;
}

// Distance from p to triangle abc (closest point, Ericson's Real-Time Collision Detection 5.1.5).
double pointTriangleDistance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double denom = 1.0 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

TEST(SurfacePoints, DensityIsUniformByAreaOverTriangles) {
  // Triangles whose areas span three orders of magnitude, under a non-uniform scale (areas
  // must be world-space ones), plus a degenerate triangle that must never be picked.
  std::vector<glm::vec3> corners;
  for (int i = 0; i < 40; ++i) {
    const float s = 0.05f + 0.05f * float(i * i);
    const glm::vec3 o(float(i) * 10.0f, 0, 0);
    corners.insert(corners.end(), {o, o + glm::vec3(s, 0, 0), o + glm::vec3(0, s, 0.3f * s)});
  }
  corners.insert(corners.end(), {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}});  // collinear: area 0
  const Scene scene = triangleScene(corners, glm::scale(glm::mat4(1.0f), {1.0f, 3.0f, 0.5f}));
  const std::vector<double> areas = posedTriangleAreas(scene, 0, 0);
  ASSERT_EQ(areas.size(), 41u);
  EXPECT_EQ(areas.back(), 0.0);
  const double total = std::accumulate(areas.begin(), areas.end(), 0.0);

  const uint32_t n = 200000;
  const SurfacePointSet set = sampleSurfacePoints(scene, n, 7);
  ASSERT_EQ(set.points.size(), n);
  EXPECT_NEAR(set.totalArea, total, 1e-9 * total);
  std::vector<double> observed(40, 0.0), expected(40);
  for (const SurfacePoint& p : set.points) {
    ASSERT_LT(p.triangle, 40u) << "the zero-area triangle was sampled";
    observed[p.triangle] += 1.0;
  }
  for (size_t t = 0; t < 40; ++t) expected[t] = n * areas[t] / total;
  EXPECT_LT(chiSquare(observed, expected), chiSquareLimit(40));

  // The test can fail: the same counts against a density uniform per triangle (not by area)
  // are rejected by orders of magnitude.
  std::vector<double> perTriangle(40, n / 40.0);
  EXPECT_GT(chiSquare(observed, perTriangle), 100.0 * chiSquareLimit(40));
}

TEST(SurfacePoints, BarycentricsAreUniformInsideATriangle) {
  // The midpoint subdivision splits a triangle into 4 of equal area: each gets a quarter of
  // the points. (Uniform u, v without the square root crowds the first corner and fails.)
  const Scene scene = triangleScene({{0, 0, 0}, {4, 0, 0}, {1, 3, 0}}, glm::mat4(1.0f));
  const uint32_t n = 100000;
  const SurfacePointSet set = sampleSurfacePoints(scene, n, 3);
  std::vector<double> observed(4, 0.0);
  for (const SurfacePoint& p : set.points) {
    const float b1 = p.barycentric.x, b2 = p.barycentric.y, b0 = 1.0f - b1 - b2;
    ASSERT_TRUE(b1 >= 0 && b2 >= 0 && b0 >= -1e-6f);
    const int sub = b0 > 0.5f ? 0 : b1 > 0.5f ? 1 : b2 > 0.5f ? 2 : 3;
    observed[sub] += 1.0;
  }
  EXPECT_LT(chiSquare(observed, std::vector<double>(4, n / 4.0)), chiSquareLimit(4));
  // Finer: each barycentric coordinate b of a uniform point has P(b > x) = (1 - x)^2; bin b1
  // into 10 bands.
  std::vector<double> bands(10, 0.0), expected(10);
  for (const SurfacePoint& p : set.points) bands[std::min(int(p.barycentric.x * 10.0f), 9)] += 1.0;
  for (int i = 0; i < 10; ++i)
    expected[i] = n * (std::pow(1.0 - 0.1 * i, 2.0) - std::pow(1.0 - 0.1 * (i + 1), 2.0));
  EXPECT_LT(chiSquare(bands, expected), chiSquareLimit(10));
}

TEST(SurfacePoints, DeterministicForASeedAndDifferentAcrossSeeds) {
  const Scene scene = makeDefaultScene();
  const SurfacePointSet a = sampleSurfacePoints(scene, 5000, 11);
  const SurfacePointSet b = sampleSurfacePoints(scene, 5000, 11);
  const SurfacePointSet c = sampleSurfacePoints(scene, 5000, 12);
  ASSERT_EQ(a.points.size(), b.points.size());
  size_t same = 0, sameOther = 0;
  for (size_t i = 0; i < a.points.size(); ++i) {
    same += a.points[i].triangle == b.points[i].triangle && a.points[i].node == b.points[i].node &&
            a.points[i].barycentric == b.points[i].barycentric;
    sameOther += a.points[i].barycentric == c.points[i].barycentric;
  }
  EXPECT_EQ(same, a.points.size());
  EXPECT_LT(sameOther, 10u);
}

TEST(SurfacePoints, EmptyOrAreaLessScenesGiveNoPoints) {
  EXPECT_TRUE(sampleSurfacePoints(Scene{}, 1000).points.empty());
  const Scene flat = triangleScene({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, glm::mat4(1.0f));
  const SurfacePointSet set = sampleSurfacePoints(flat, 1000);
  EXPECT_TRUE(set.points.empty());
  EXPECT_EQ(set.totalArea, 0.0);
  EXPECT_TRUE(evaluateSurfacePoints(flat, set).empty());
  // A zero-scale instance has no area either (and produces no NaN).
  const Scene squashed = triangleScene({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                       glm::scale(glm::mat4(1.0f), glm::vec3(0.0f)));
  EXPECT_TRUE(sampleSurfacePoints(squashed, 100).points.empty());
}

TEST(SurfacePoints, EvaluatedPointsLieOnTheirTrianglesWithUnitNormals) {
  const Scene scene = makeDefaultScene();
  const SurfacePointSet set = sampleSurfacePoints(scene, 20000, 5);
  const std::vector<SurfacePointSample> pts = evaluateSurfacePoints(scene, set);
  ASSERT_EQ(pts.size(), set.points.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    const SurfacePoint& p = set.points[i];
    const Mesh& mesh = scene.meshes[p.mesh];
    const glm::dmat4 w(scene.nodes[p.node].world);
    glm::dvec3 c[3];
    for (int k = 0; k < 3; ++k)
      c[k] = glm::dvec3(
          w *
          glm::dvec4(glm::dvec3(mesh.vertices[mesh.indices[3 * p.triangle + k]].position), 1.0));
    ASSERT_LT(pointTriangleDistance(glm::dvec3(pts[i].position), c[0], c[1], c[2]), 1e-5) << i;
    ASSERT_NEAR(glm::length(pts[i].normal), 1.0f, 1e-5f);
    ASSERT_NEAR(pts[i].area, set.totalArea / double(pts.size()), 1e-6);
  }
}

TEST(SurfacePoints, PointsFollowASkinnedMeshOnTheCpu) {
  Scene scene = loadGltf(test::assimpModel("glTF2/simple_skin/simple_skin.gltf"));
  const SurfacePointSet set = sampleSurfacePoints(scene, 4000, 9);
  ASSERT_EQ(set.points.size(), 4000u);
  glm::vec3 lo, hi;
  scene.worldBounds(lo, hi);
  const double size = glm::length(hi - lo);
  const std::vector<SurfacePointSample> rest = evaluateSurfacePoints(scene, set);
  double movedMost = 0.0;
  for (double t : {0.5, 1.25, 3.0}) {
    scene.animate(t);
    const std::vector<SurfacePointSample> pts = evaluateSurfacePoints(scene, set);
    double worst = 0.0, moved = 0.0;
    for (size_t i = 0; i < pts.size(); ++i) {
      const SurfacePoint& p = set.points[i];
      const Mesh& mesh = scene.meshes[p.mesh];
      // The skinned triangle straight from the skinning reference (not through posedVertices).
      const std::vector<Vertex> skinned =
          skinVertices(mesh, mesh.vertices, jointMatrices(scene, int(p.node)));
      const glm::dmat4 w(scene.nodes[p.node].world);
      glm::dvec3 c[3];
      for (int k = 0; k < 3; ++k)
        c[k] = glm::dvec3(
            w * glm::dvec4(glm::dvec3(skinned[mesh.indices[3 * p.triangle + k]].position), 1.0));
      worst = std::max(worst, pointTriangleDistance(glm::dvec3(pts[i].position), c[0], c[1], c[2]));
      moved = std::max(moved, double(glm::length(pts[i].position - rest[i].position)));
    }
    EXPECT_LT(worst, 1e-4 * size) << "time " << t;
    movedMost = std::max(movedMost, moved);
  }
  EXPECT_GT(movedMost, 0.05 * size) << "the skin never moved the points";
}

}  // namespace
}  // namespace gi
