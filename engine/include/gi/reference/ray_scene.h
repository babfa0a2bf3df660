// Ray queries against a gi::Scene for the CPU reference renderer: one Embree scene holding the
// world-space triangles of every mesh instance (each node's meshes under its world transform,
// exactly what the Vulkan renderer draws), with the surface data needed for shading. Embree
// stays behind this interface. Thread-safe for concurrent queries after construction.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi::reference {

struct SurfaceHit {
  float t = 0.0f;            // ray parameter (in units of the ray direction's length)
  glm::vec3 position{0.0f};  // world space, from barycentrics (not org + t * dir)
  glm::vec3 geometricNormal{0.0f, 1.0f, 0.0f};  // unit, facing the ray's origin
  glm::vec3 shadingNormal{0.0f, 1.0f, 0.0f};    // interpolated, unit, facing the ray's origin
  // The ray came from the side the interpolated normal points to as authored (before it was
  // turned to face the origin): the side a one-sided emitter lights (Material::doubleSided).
  bool frontFacing = true;
  glm::vec2 uv{0.0f};
  uint32_t material = 0;     // index into the scene's materials (clamped like the rasteriser)
  float offsetScale = 0.0f;  // scale of the surface's coordinates, for offsetting new rays
  int node = -1, mesh = -1;
  uint32_t triangle = 0;  // index of the triangle within its mesh
};

struct WorldTriangle {
  glm::vec3 p0{0.0f}, p1{0.0f}, p2{0.0f};  // world space, as intersected
  glm::vec3 n0{0.0f}, n1{0.0f}, n2{0.0f};  // the vertex normals (world, unit), as authored
  uint32_t material = 0;
};

class RayScene {
 public:
  // Builds the acceleration structure from the scene's current world transforms. Triangles
  // with non-finite world positions are skipped; zero-area ones can never be hit.
  explicit RayScene(const Scene& scene);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // Closest hit with t in (tnear, tfar); `dir` need not be unit length.
  bool intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar,
                 SurfaceHit& hit) const;
  // Any hit with t in (tnear, tfar).
  bool occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;

  // Origin for rays leaving `hit`: the hit position pushed along the geometric normal (which
  // faces the side the hit was seen from) by a scale-aware epsilon (see offsetDistance). New
  // rays start on the side the surface was reached from, so a direction below the geometric
  // tangent plane (possible around an interpolated normal) is blocked by the surface itself,
  // while rays above it cannot re-hit the triangle they start on.
  static glm::vec3 spawnOrigin(const SurfaceHit& hit);
  // The offset used by spawnOrigin: a fixed number of float ulps of the largest coordinate
  // involved (the hit position and its triangle's vertices), so it scales with the scene.
  static float offsetDistance(const SurfaceHit& hit);

  // The triangles (world space) whose material satisfies `keep`, e.g. the emitters.
  std::vector<WorldTriangle> triangles(const std::function<bool(uint32_t material)>& keep) const;

  size_t triangleCount() const;
  glm::vec3 boundsMin() const;
  glm::vec3 boundsMax() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi::reference
