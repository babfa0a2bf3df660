// processMesh: areas, dropped triangles, recomputed normals, welding and bounds.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "gi/scene_io.h"

namespace {

gi::Vertex vert(float x, float y, float z, glm::vec3 n = glm::vec3(0.0f)) {
  gi::Vertex v;
  v.position = {x, y, z};
  v.normal = n;
  return v;
}

// A 2 x 3 quad in the z = 1 plane, facing +z, as two triangles.
gi::Mesh quad(glm::vec3 normal = glm::vec3(0.0f)) {
  gi::Mesh m;
  m.vertices = {vert(0, 0, 1, normal), vert(2, 0, 1, normal), vert(2, 3, 1, normal),
                vert(0, 3, 1, normal)};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

void expectNear(glm::vec3 a, glm::vec3 b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

TEST(SceneMesh, QuadAreasAndBounds) {
  gi::Mesh m = quad();
  gi::MeshFixReport r = gi::processMesh(m);
  ASSERT_EQ(m.triangleAreas.size(), 2u);
  EXPECT_NEAR(m.triangleAreas[0], 3.0f, 1e-5f);
  EXPECT_NEAR(m.triangleAreas[1], 3.0f, 1e-5f);
  expectNear(m.boundsMin, {0, 0, 1});
  expectNear(m.boundsMax, {2, 3, 1});
  EXPECT_EQ(r.droppedDegenerateTriangles, 0u);
  EXPECT_EQ(r.droppedNonFiniteTriangles, 0u);
}

TEST(SceneMesh, ZeroNormalsBecomeFaceNormal) {
  gi::Mesh m = quad();
  gi::MeshFixReport r = gi::processMesh(m);
  EXPECT_EQ(r.recomputedNormals, 4u);
  for (const gi::Vertex& v : m.vertices) expectNear(v.normal, {0, 0, 1});
}

TEST(SceneMesh, NaNNormalsRecomputedValidOnesNormalised) {
  gi::Mesh m = quad(glm::vec3(0, 0, 5));
  m.vertices[1].normal = glm::vec3(std::numeric_limits<float>::quiet_NaN(), 0, 0);
  gi::MeshFixReport r = gi::processMesh(m);
  EXPECT_EQ(r.recomputedNormals, 1u);
  for (const gi::Vertex& v : m.vertices) expectNear(v.normal, {0, 0, 1});
}

TEST(SceneMesh, NaNVertexDropsItsTriangles) {
  gi::Mesh m = quad();
  m.vertices.push_back(vert(std::numeric_limits<float>::quiet_NaN(), 0, 0));
  m.indices.insert(m.indices.end(), {0, 1, 4});
  gi::MeshFixReport r = gi::processMesh(m);
  EXPECT_EQ(r.droppedNonFiniteTriangles, 1u);
  EXPECT_EQ(m.triangleCount(), 2u);
  EXPECT_EQ(m.triangleAreas.size(), 2u);
  EXPECT_EQ(m.vertices.size(), 4u);  // the NaN vertex is no longer referenced
  for (const gi::Vertex& v : m.vertices) EXPECT_TRUE(std::isfinite(v.position.x));
  expectNear(m.boundsMin, {0, 0, 1});
  expectNear(m.boundsMax, {2, 3, 1});
}

TEST(SceneMesh, DegenerateTrianglesDropped) {
  gi::Mesh m = quad();
  m.vertices.push_back(vert(1, 0, 1));  // on the edge 0-1: triangle 0,4,1 is collinear
  m.indices.insert(m.indices.end(), {0, 4, 1, 2, 2, 3, 0, 1, 99});
  gi::MeshFixReport r = gi::processMesh(m);
  EXPECT_EQ(r.droppedDegenerateTriangles, 3u);
  EXPECT_EQ(m.triangleCount(), 2u);
}

TEST(SceneMesh, OppositeFacesNeverGiveNaN) {
  // Two coincident triangles with opposite winding share vertices: the area-weighted sum is
  // zero, so the vertex falls back to a face normal.
  gi::Mesh m;
  m.vertices = {vert(0, 0, 0), vert(1, 0, 0), vert(0, 1, 0)};
  m.indices = {0, 1, 2, 0, 2, 1};
  gi::processMesh(m);
  for (const gi::Vertex& v : m.vertices) {
    EXPECT_TRUE(std::isfinite(v.normal.x) && std::isfinite(v.normal.y) &&
                std::isfinite(v.normal.z));
    EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-5f);
  }
}

TEST(SceneMesh, WeldMergesIdenticalVertices) {
  gi::Mesh m;
  // Two triangles of the quad with unshared corners (6 vertices, 2 duplicated pairs).
  m.vertices = {vert(0, 0, 0), vert(1, 0, 0), vert(1, 1, 0),
                vert(0, 0, 0), vert(1, 1, 0), vert(0, 1, 0)};
  m.indices = {0, 1, 2, 3, 4, 5};
  gi::MeshFixReport r = gi::processMesh(m, true);
  EXPECT_EQ(r.weldedVertices, 2u);
  EXPECT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.triangleCount(), 2u);
  EXPECT_NEAR(m.triangleAreas[0] + m.triangleAreas[1], 1.0f, 1e-5f);
}

TEST(SceneMesh, EmptyMeshIsFine) {
  gi::Mesh m;
  gi::MeshFixReport r = gi::processMesh(m, true);
  EXPECT_EQ(m.triangleCount(), 0u);
  EXPECT_TRUE(m.triangleAreas.empty());
  expectNear(m.boundsMin, {0, 0, 0});
  expectNear(m.boundsMax, {0, 0, 0});
  EXPECT_EQ(r.recomputedNormals, 0u);

  gi::Mesh onlyNaN;  // everything dropped ends empty as well
  onlyNaN.vertices = {vert(NAN, 0, 0), vert(1, 0, 0), vert(0, 1, 0)};
  onlyNaN.indices = {0, 1, 2};
  gi::processMesh(onlyNaN);
  EXPECT_EQ(onlyNaN.triangleCount(), 0u);
  EXPECT_TRUE(onlyNaN.vertices.empty());
}

TEST(SceneMesh, NonManifoldFacesStillProcessed) {
  // Three triangles sharing one edge (a non-manifold "book"): OpenMesh refuses the third one
  // on the shared topology, yet it must keep its area and normal.
  gi::Mesh m;
  m.vertices = {vert(0, 0, 0), vert(1, 0, 0), vert(0, 1, 0), vert(0, -1, 0), vert(0, 0, 1)};
  m.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  gi::processMesh(m);
  ASSERT_EQ(m.triangleAreas.size(), 3u);
  for (float a : m.triangleAreas) EXPECT_NEAR(a, 0.5f, 1e-5f);
  for (const gi::Vertex& v : m.vertices) EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-5f);
}

}  // namespace
