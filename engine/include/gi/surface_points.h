// Point representation of the scene's surfaces for imperfect shadow maps (seed 002, §3.1):
// points placed once, uniformly by area, each stored as (mesh instance, triangle,
// barycentrics) so that the engine's "surface_points" compute pass can turn them into
// world-space positions and normals every frame from the *deformed* vertices: the points
// follow skinned, morphed and moving meshes without being re-sampled.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

// One sample: triangle `triangle` of mesh `mesh` drawn by node `node`; the point is
// v0 + b.x (v1 - v0) + b.y (v2 - v0), i.e. vertex weights (1 - b.x - b.y, b.x, b.y).
struct SurfacePoint {
  uint32_t node = 0, mesh = 0, triangle = 0;
  glm::vec2 barycentric{0.0f};
};

struct SurfacePointSet {
  std::vector<SurfacePoint> points;
  double totalArea = 0.0;  // world-space area of all sampled surfaces at the sampling pose
  uint64_t seed = 0;
};

// A point on the posed surface (what the GPU pass writes, and its CPU reference).
struct SurfacePointSample {
  glm::vec3 position{0.0f};            // world space
  float area = 0.0f;                   // surface area the point stands for: totalArea / point count
  glm::vec3 normal{0.0f, 1.0f, 0.0f};  // world space, unit length
  float material = 0.0f;               // material index
};

// World-space triangle areas of the mesh drawn by `node` at the scene's current pose
// (skinned and morphed meshes deformed on the CPU as the GPU does). Degenerate or non-finite
// triangles get area 0 and are never sampled.
std::vector<double> posedTriangleAreas(const Scene& scene, int node, int mesh);

// Places `count` points uniformly by area over every mesh instance of `scene` at its current
// pose: a triangle with probability proportional to its world-space area (binary search in
// the cumulative areas), then uniform barycentrics (b = (sqrt(r1) (1 - r2), sqrt(r1) r2)).
// Deterministic for a seed on every platform (own generator, no std distributions). A scene
// without area gives an empty set.
SurfacePointSet sampleSurfacePoints(const Scene& scene, uint32_t count, uint64_t seed = 1);

// The vertices of `mesh` as drawn by `node` at the scene's current pose, in the node's space
// (morph targets and skinning applied; rigid meshes unchanged).
std::vector<Vertex> posedVertices(const Scene& scene, int node, int mesh);

// CPU reference of the GPU pass: the points on the scene's current pose. Normals are the
// interpolated vertex normals (face normal where they cancel), transformed by the node's
// normal matrix.
std::vector<SurfacePointSample> evaluateSurfacePoints(const Scene& scene,
                                                      const SurfacePointSet& set);

}  // namespace gi
