// Area-uniform surface points (see gi/surface_points.h).
#include "gi/surface_points.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "gi/animation.h"

namespace gi {
namespace {

// splitmix64: tiny, well-mixed and identical everywhere (std distributions are not).
struct SplitMix64 {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

bool drawsMesh(const Scene& scene, size_t node, int mesh) {
  return mesh >= 0 && size_t(mesh) < scene.meshes.size() && !scene.meshes[mesh].indices.empty() &&
         node < scene.nodes.size();
}

}  // namespace

std::vector<Vertex> posedVertices(const Scene& scene, int node, int meshIndex) {
  const Node& n = scene.nodes.at(size_t(node));
  const Mesh& mesh = scene.meshes.at(size_t(meshIndex));
  std::vector<Vertex> rest =
      mesh.morphTargets.empty() ? mesh.vertices : morphVertices(mesh, n.morphWeights);
  const bool skinned = mesh.skinned() && n.skin >= 0 && size_t(n.skin) < scene.skins.size();
  return skinned ? skinVertices(mesh, rest, jointMatrices(scene, node)) : rest;
}

std::vector<double> posedTriangleAreas(const Scene& scene, int node, int meshIndex) {
  const Mesh& mesh = scene.meshes.at(size_t(meshIndex));
  const std::vector<Vertex> verts = posedVertices(scene, node, meshIndex);
  const glm::dmat4 world(scene.nodes.at(size_t(node)).world);
  std::vector<double> areas(mesh.triangleCount(), 0.0);
  for (size_t t = 0; t < areas.size(); ++t) {
    const uint32_t i0 = mesh.indices[3 * t], i1 = mesh.indices[3 * t + 1],
                   i2 = mesh.indices[3 * t + 2];
    if (i0 >= verts.size() || i1 >= verts.size() || i2 >= verts.size()) continue;
    const glm::dvec3 a(world * glm::dvec4(glm::dvec3(verts[i0].position), 1.0));
    const glm::dvec3 b(world * glm::dvec4(glm::dvec3(verts[i1].position), 1.0));
    const glm::dvec3 c(world * glm::dvec4(glm::dvec3(verts[i2].position), 1.0));
    const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
    areas[t] = std::isfinite(area) ? area : 0.0;  // guard: non-finite triangles never drawn
  }
  return areas;
}

SurfacePointSet sampleSurfacePoints(const Scene& scene, uint32_t count, uint64_t seed) {
  SurfacePointSet set;
  set.seed = seed;
  struct Range {
    uint32_t node, mesh;
    size_t first;  // first entry in `cumulative`
  };
  std::vector<Range> ranges;
  std::vector<double> cumulative;  // running sum of triangle areas over all instances
  double total = 0.0;
  for (size_t n = 0; n < scene.nodes.size(); ++n)
    for (int m : scene.nodes[n].meshes) {
      if (!drawsMesh(scene, n, m)) continue;
      ranges.push_back({uint32_t(n), uint32_t(m), cumulative.size()});
      for (double a : posedTriangleAreas(scene, int(n), m)) cumulative.push_back(total += a);
    }
  set.totalArea = total;
  if (count == 0 || !(total > 0.0)) return set;

  SplitMix64 rng{seed};
  set.points.reserve(count);
  for (uint32_t i = 0; i < count; ++i) {
    // upper_bound skips zero-area triangles: their cumulative value equals the previous one.
    const double target = rng.uniform() * total;
    size_t tri =
        size_t(std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin());
    tri = std::min(tri, cumulative.size() - 1);
    const auto range = std::upper_bound(ranges.begin(), ranges.end(), tri,
                                        [](size_t t, const Range& r) { return t < r.first; }) -
                       1;
    const double s = std::sqrt(rng.uniform()), r2 = rng.uniform();
    SurfacePoint p;
    p.node = range->node;
    p.mesh = range->mesh;
    p.triangle = uint32_t(tri - range->first);
    p.barycentric = glm::vec2(float(s * (1.0 - r2)), float(s * r2));
    set.points.push_back(p);
  }
  return set;
}

std::vector<SurfacePointSample> evaluateSurfacePoints(const Scene& scene,
                                                      const SurfacePointSet& set) {
  std::vector<SurfacePointSample> out(set.points.size());
  if (set.points.empty()) return out;
  const float area = float(set.totalArea / double(set.points.size()));
  // Posed vertices once per instance (points of all instances are interleaved).
  std::map<std::pair<uint32_t, uint32_t>, std::vector<Vertex>> posed;
  const uint32_t lastMaterial = uint32_t(std::max<size_t>(scene.materials.size(), 1) - 1);
  for (size_t i = 0; i < set.points.size(); ++i) {
    const SurfacePoint& p = set.points[i];
    auto it = posed.find({p.node, p.mesh});
    if (it == posed.end())
      it = posed
               .emplace(std::make_pair(p.node, p.mesh),
                        posedVertices(scene, int(p.node), int(p.mesh)))
               .first;
    const std::vector<Vertex>& verts = it->second;
    const Mesh& mesh = scene.meshes[p.mesh];
    const glm::mat4& world = scene.nodes[p.node].world;
    const size_t base = size_t(p.triangle) * 3;
    const Vertex& v0 = verts[mesh.indices[base]];
    const Vertex& v1 = verts[mesh.indices[base + 1]];
    const Vertex& v2 = verts[mesh.indices[base + 2]];
    const float b1 = p.barycentric.x, b2 = p.barycentric.y, b0 = 1.0f - b1 - b2;
    const glm::vec3 local = b0 * v0.position + b1 * v1.position + b2 * v2.position;
    glm::vec3 n = b0 * v0.normal + b1 * v1.normal + b2 * v2.normal;
    // Guard: interpolated normals can cancel; fall back to the face normal, then to +y.
    if (!(glm::dot(n, n) > 1e-20f))
      n = glm::cross(v1.position - v0.position, v2.position - v0.position);
    n = cofactor3(world) * n;
    const float len2 = glm::dot(n, n);
    SurfacePointSample& s = out[i];
    s.position = glm::vec3(world * glm::vec4(local, 1.0f));
    s.normal = len2 > 1e-30f && std::isfinite(len2) ? n / std::sqrt(len2) : glm::vec3(0, 1, 0);
    s.area = area;
    s.material = float(std::min(mesh.material, lastMaterial));  // as the renderer clamps it
  }
  return out;
}

}  // namespace gi
