// Built-in primitives for the default scene and JSON scenes ("primitive": "plane" | "box" |
// "sphere"). Triangles are wound counter-clockwise seen from outside, matching the normals.
#include <cmath>

#include <glm/gtc/constants.hpp>

#include "gi/scene_io.h"
#include "scene_io_util.h"

namespace gi::detail {
namespace {

// Appends a triangle, swapping two corners when needed so that its winding agrees with
// `outward` (robust against getting a parametrisation's orientation wrong).
void addTriangle(Mesh& m, uint32_t a, uint32_t b, uint32_t c, const glm::vec3& outward) {
  glm::vec3 n = glm::cross(m.vertices[b].position - m.vertices[a].position,
                           m.vertices[c].position - m.vertices[a].position);
  if (glm::dot(n, outward) < 0.0f) std::swap(b, c);
  m.indices.insert(m.indices.end(), {a, b, c});
}

// A quad centred at `centre` spanning +-u and +-v with the given normal.
void addQuad(Mesh& m, const glm::vec3& centre, const glm::vec3& u, const glm::vec3& v,
             const glm::vec3& normal) {
  const uint32_t base = static_cast<uint32_t>(m.vertices.size());
  const glm::vec2 uvs[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  const glm::vec3 corners[4] = {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
  for (int i = 0; i < 4; ++i) m.vertices.push_back(Vertex{corners[i], normal, uvs[i]});
  addTriangle(m, base, base + 1, base + 2, normal);
  addTriangle(m, base, base + 2, base + 3, normal);
}

}  // namespace

Mesh makePlane(float sizeX, float sizeZ) {
  Mesh m;
  m.name = "plane";
  addQuad(m, glm::vec3(0.0f), glm::vec3(0.5f * sizeX, 0, 0), glm::vec3(0, 0, 0.5f * sizeZ),
          glm::vec3(0, 1, 0));
  processMesh(m);
  return m;
}

Mesh makeBox(const glm::vec3& size, int segments) {
  Mesh m;
  m.name = "box";
  const glm::vec3 h = 0.5f * size;
  const float s = float(segments);
  for (int axis = 0; axis < 3; ++axis) {
    for (float sign : {1.0f, -1.0f}) {
      glm::vec3 n(0.0f), u(0.0f), v(0.0f);
      n[axis] = sign;
      u[(axis + 1) % 3] = h[(axis + 1) % 3];
      v[(axis + 2) % 3] = h[(axis + 2) % 3];
      // segments x segments quads per face (12 segments^2 triangles in all).
      for (int i = 0; i < segments; ++i)
        for (int j = 0; j < segments; ++j)
          addQuad(m,
                  n * h + u * ((2.0f * float(i) + 1.0f) / s - 1.0f) +
                      v * ((2.0f * float(j) + 1.0f) / s - 1.0f),
                  u / s, v / s, n);
    }
  }
  processMesh(m);
  return m;
}

Mesh makeSphere(float radius, int segments, int rings) {
  Mesh m;
  m.name = "sphere";
  segments = std::max(segments, 3);
  rings = std::max(rings, 2);
  // (rings + 1) x (segments + 1) grid; the seam column is duplicated for the uv wrap.
  for (int r = 0; r <= rings; ++r) {
    const float theta = glm::pi<float>() * static_cast<float>(r) / static_cast<float>(rings);
    for (int s = 0; s <= segments; ++s) {
      const float phi = glm::two_pi<float>() * static_cast<float>(s) / static_cast<float>(segments);
      glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                  std::sin(theta) * std::sin(phi));
      m.vertices.push_back(Vertex{radius * n,
                                  n,
                                  {static_cast<float>(s) / static_cast<float>(segments),
                                   static_cast<float>(r) / static_cast<float>(rings)}});
    }
  }
  auto at = [&](int r, int s) { return static_cast<uint32_t>(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = at(r, s), b = at(r, s + 1), c = at(r + 1, s + 1), d = at(r + 1, s);
      const glm::vec3 out =
          m.vertices[a].normal + m.vertices[b].normal + m.vertices[c].normal + m.vertices[d].normal;
      if (r > 0) addTriangle(m, a, b, c, out);          // the top row's is degenerate (pole)
      if (r + 1 < rings) addTriangle(m, a, c, d, out);  // the bottom row's likewise
    }
  }
  processMesh(m);
  return m;
}

}  // namespace gi::detail
