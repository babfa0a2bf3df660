// Mesh sanitising shared by every loader: drop unusable triangles, repair normals, optionally
// weld duplicates, and derive the per-triangle areas and bounds the renderers rely on.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <unordered_map>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "gi/scene_io.h"

namespace gi {
namespace {

using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// A normal is usable when it is finite and not (close to) zero length.
bool usableNormal(const glm::vec3& n) {
  if (!finite(n)) return false;
  float len2 = glm::dot(n, n);
  return std::isfinite(len2) && len2 > 1e-12f;
}

// Twice the triangle's area relative to its longest edge squared, in double so that the test
// for "zero area" is not dominated by float rounding.
bool degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  glm::dvec3 e0 = glm::dvec3(b) - glm::dvec3(a), e1 = glm::dvec3(c) - glm::dvec3(a);
  glm::dvec3 e2 = glm::dvec3(c) - glm::dvec3(b);
  double cross = glm::length(glm::cross(e0, e1));
  double longest = std::max({glm::dot(e0, e0), glm::dot(e1, e1), glm::dot(e2, e2)});
  return !(cross > 1e-12 * longest) || !std::isfinite(cross);
}

// OpenMesh reports non-manifold faces on omerr; we handle those faces ourselves (see below),
// so silence it while building and restore the previous state afterwards.
class QuietOpenMesh {
 public:
  QuietOpenMesh() : wasEnabled_(::omerr().is_enabled()) { ::omerr().disable(); }
  ~QuietOpenMesh() {
    if (wasEnabled_) ::omerr().enable();
  }
  QuietOpenMesh(const QuietOpenMesh&) = delete;
  QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;

 private:
  bool wasEnabled_;
};

// Reorders a per-vertex array (skin data, morph deltas) like the vertices; `order` lists the
// kept old indices. Arrays not parallel to the vertices are left alone.
template <class T>
void keepOrdered(std::vector<T>& values, const std::vector<uint32_t>& order, size_t oldCount) {
  if (values.size() != oldCount) return;
  std::vector<T> kept;
  kept.reserve(order.size());
  for (uint32_t i : order) kept.push_back(values[i]);
  values = std::move(kept);
}

// Keeps only referenced vertices (in first-use order) and rewrites the indices.
void compactVertices(Mesh& mesh) {
  std::vector<uint32_t> remap(mesh.vertices.size(), UINT32_MAX);
  std::vector<uint32_t> order;
  order.reserve(mesh.vertices.size());
  for (uint32_t& idx : mesh.indices) {
    if (remap[idx] == UINT32_MAX) {
      remap[idx] = static_cast<uint32_t>(order.size());
      order.push_back(idx);
    }
    idx = remap[idx];
  }
  const size_t oldCount = mesh.vertices.size();
  keepOrdered(mesh.vertices, order, oldCount);
  keepOrdered(mesh.joints, order, oldCount);
  keepOrdered(mesh.weights, order, oldCount);
  for (MorphTarget& t : mesh.morphTargets) {
    keepOrdered(t.positionDeltas, order, oldCount);
    keepOrdered(t.normalDeltas, order, oldCount);
  }
}

// Merges vertices whose position, normal and uv are bit-identical; returns how many went.
size_t weldVertices(Mesh& mesh) {
  struct Key {
    float v[8];
    // Values are finite and -0 is folded into +0, so equal values have equal bits (hash).
    bool operator==(const Key& o) const { return std::equal(std::begin(v), std::end(v), o.v); }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      size_t h = 1469598103934665603ull;
      for (float f : k.v) {
        uint32_t bits;
        std::memcpy(&bits, &f, sizeof(bits));
        h = (h ^ bits) * 1099511628211ull;
      }
      return h;
    }
  };
  std::unordered_map<Key, uint32_t, KeyHash> seen;
  std::vector<uint32_t> remap(mesh.vertices.size());
  std::vector<Vertex> kept;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vertex& v = mesh.vertices[i];
    // +0.0f turns -0.0 into +0.0 so that the two zeros weld together.
    Key key{{v.position.x + 0.0f, v.position.y + 0.0f, v.position.z + 0.0f, v.normal.x + 0.0f,
             v.normal.y + 0.0f, v.normal.z + 0.0f, v.uv.x + 0.0f, v.uv.y + 0.0f}};
    auto [it, inserted] = seen.emplace(key, static_cast<uint32_t>(kept.size()));
    if (inserted) kept.push_back(v);
    remap[i] = it->second;
  }
  size_t removed = mesh.vertices.size() - kept.size();
  for (uint32_t& idx : mesh.indices) idx = remap[idx];
  mesh.vertices = std::move(kept);
  return removed;
}

}  // namespace

MeshFixReport processMesh(Mesh& mesh, bool weld) {
  MeshFixReport report;
  if (mesh.indices.size() % 3 != 0) {  // a partial trailing triangle cannot be drawn
    mesh.indices.resize(mesh.indices.size() - mesh.indices.size() % 3);
    ++report.droppedDegenerateTriangles;
  }

  // 1. Drop triangles that cannot be rendered: out-of-range or repeated indices, non-finite
  //    positions, zero area.
  std::vector<uint32_t> kept;
  kept.reserve(mesh.indices.size());
  const size_t vertexCount = mesh.vertices.size();
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
    if (i0 >= vertexCount || i1 >= vertexCount || i2 >= vertexCount || i0 == i1 || i1 == i2 ||
        i0 == i2) {
      ++report.droppedDegenerateTriangles;
      continue;
    }
    const glm::vec3 &a = mesh.vertices[i0].position, &b = mesh.vertices[i1].position,
                    &c = mesh.vertices[i2].position;
    if (!finite(a) || !finite(b) || !finite(c)) {
      ++report.droppedNonFiniteTriangles;
      continue;
    }
    if (degenerate(a, b, c)) {
      ++report.droppedDegenerateTriangles;
      continue;
    }
    kept.insert(kept.end(), {i0, i1, i2});
  }
  mesh.indices = std::move(kept);
  compactVertices(mesh);  // also removes the vertices only dropped triangles used

  // 2. Face normals and areas through OpenMesh. Faces OpenMesh refuses (non-manifold edges or
  //    vertices, common in scanned or hand-made data) get private copies of their corners so
  //    that every triangle still gets an OpenMesh face.
  const size_t triCount = mesh.triangleCount();
  OmMesh om;
  om.request_face_normals();
  std::vector<OmMesh::VertexHandle> handles;
  handles.reserve(mesh.vertices.size());
  for (const Vertex& v : mesh.vertices)
    handles.push_back(om.add_vertex(OmMesh::Point(v.position.x, v.position.y, v.position.z)));
  std::vector<OmMesh::FaceHandle> faces(triCount);
  {
    QuietOpenMesh quiet;
    for (size_t t = 0; t < triCount; ++t) {
      const uint32_t* idx = &mesh.indices[3 * t];
      OmMesh::FaceHandle fh = om.add_face(handles[idx[0]], handles[idx[1]], handles[idx[2]]);
      if (!fh.is_valid()) {
        OmMesh::VertexHandle copies[3];
        for (int k = 0; k < 3; ++k) {
          // Copy first: add_vertex may grow the point array that om.point() refers into.
          const OmMesh::Point p = om.point(handles[idx[k]]);
          copies[k] = om.add_vertex(p);
        }
        fh = om.add_face(copies[0], copies[1], copies[2]);
      }
      faces[t] = fh;
    }
  }
  om.update_face_normals();

  mesh.triangleAreas.assign(triCount, 0.0f);
  std::vector<glm::vec3> faceNormals(triCount);
  for (size_t t = 0; t < triCount; ++t) {
    if (faces[t].is_valid()) {
      const OmMesh::Normal& n = om.normal(faces[t]);
      faceNormals[t] = glm::vec3(n[0], n[1], n[2]);
      mesh.triangleAreas[t] = static_cast<float>(om.calc_face_area(faces[t]));
    } else {  // not expected (isolated copies always form a face), but never leave a gap
      const uint32_t* idx = &mesh.indices[3 * t];
      glm::vec3 c = glm::cross(mesh.vertices[idx[1]].position - mesh.vertices[idx[0]].position,
                               mesh.vertices[idx[2]].position - mesh.vertices[idx[0]].position);
      faceNormals[t] = glm::normalize(c);
      mesh.triangleAreas[t] = 0.5f * glm::length(c);
    }
  }

  // 3. Repair vertex normals: area-weighted average of the adjacent face normals for vertices
  //    whose normal is missing/zero/NaN; normalise the rest.
  std::vector<glm::vec3> accumulated(mesh.vertices.size(), glm::vec3(0.0f));
  std::vector<int> firstFace(mesh.vertices.size(), -1);
  for (size_t t = 0; t < triCount; ++t) {
    for (int k = 0; k < 3; ++k) {
      uint32_t v = mesh.indices[3 * t + k];
      accumulated[v] += faceNormals[t] * mesh.triangleAreas[t];
      if (firstFace[v] < 0) firstFace[v] = static_cast<int>(t);
    }
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    glm::vec3& n = mesh.vertices[v].normal;
    if (usableNormal(n)) {
      n = glm::normalize(n);
      continue;
    }
    ++report.recomputedNormals;
    if (usableNormal(accumulated[v]))
      n = glm::normalize(accumulated[v]);
    else if (firstFace[v] >= 0 && usableNormal(faceNormals[firstFace[v]]))
      n = glm::normalize(faceNormals[firstFace[v]]);  // adjacent faces cancel out
    else
      n = glm::vec3(0.0f, 1.0f, 0.0f);
  }
  for (Vertex& v : mesh.vertices)  // uvs only need to be finite
    if (!std::isfinite(v.uv.x) || !std::isfinite(v.uv.y)) v.uv = glm::vec2(0.0f);

  // Skinned and morphed vertices carry more than the key compares; never weld those.
  if (weld && mesh.joints.empty() && mesh.morphTargets.empty())
    report.weldedVertices = weldVertices(mesh);

  // 4. Bounds over the (all referenced) vertices; an empty mesh gets a zero box at the origin.
  if (mesh.vertices.empty()) {
    mesh.boundsMin = mesh.boundsMax = glm::vec3(0.0f);
  } else {
    mesh.boundsMin = glm::vec3(std::numeric_limits<float>::max());
    mesh.boundsMax = glm::vec3(-std::numeric_limits<float>::max());
    for (const Vertex& v : mesh.vertices) {
      mesh.boundsMin = glm::min(mesh.boundsMin, v.position);
      mesh.boundsMax = glm::max(mesh.boundsMax, v.position);
    }
  }
  return report;
}

}  // namespace gi
