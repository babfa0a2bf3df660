#include "gi/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/errors.h"

namespace gi {

void Scene::updateWorldTransforms() {
  // Iterative walk from the roots; loaders guarantee the hierarchy is a forest.
  std::vector<int> stack(roots.rbegin(), roots.rend());
  for (int r : roots) nodes[r].world = nodes[r].local;
  while (!stack.empty()) {
    int n = stack.back();
    stack.pop_back();
    for (int c : nodes[n].children) {
      nodes[c].world = nodes[n].world * nodes[c].local;
      stack.push_back(c);
    }
  }
}

void Scene::worldBounds(glm::vec3& outMin, glm::vec3& outMax) const {
  outMin = glm::vec3(std::numeric_limits<float>::max());
  outMax = glm::vec3(-std::numeric_limits<float>::max());
  for (const Node& node : nodes) {
    for (int m : node.meshes) {
      const Mesh& mesh = meshes[m];
      for (int i = 0; i < 8; ++i) {
        glm::vec3 corner((i & 1) ? mesh.boundsMax.x : mesh.boundsMin.x,
                         (i & 2) ? mesh.boundsMax.y : mesh.boundsMin.y,
                         (i & 4) ? mesh.boundsMax.z : mesh.boundsMin.z);
        glm::vec3 w = glm::vec3(node.world * glm::vec4(corner, 1.0f));
        outMin = glm::min(outMin, w);
        outMax = glm::max(outMax, w);
      }
    }
  }
  if (outMin.x > outMax.x) {  // no geometry: a unit box keeps cameras finite
    outMin = glm::vec3(-1.0f);
    outMax = glm::vec3(1.0f);
  }
}

size_t Scene::triangleCount() const {
  size_t n = 0;
  for (const Mesh& m : meshes) n += m.triangleCount();
  return n;
}

int Scene::addNode(const std::string& name, const glm::mat4& local, int parent) {
  Node node;
  node.name = name;
  node.local = local;
  node.parent = parent;
  nodes.push_back(node);
  int index = static_cast<int>(nodes.size()) - 1;
  if (parent < 0)
    roots.push_back(index);
  else
    nodes[parent].children.push_back(index);
  return index;
}

glm::mat4 perspectiveReverseZ(float yfov, float aspect, float znear, float zfar) {
  // Standard Vulkan [0,1] projection with near and far swapped: depth 1 at near, 0 at far.
  const float f = 1.0f / std::tan(yfov * 0.5f);
  glm::mat4 p(0.0f);
  p[0][0] = f / aspect;
  p[1][1] = -f;  // Vulkan's y points down in clip space
  p[2][2] = znear / (zfar - znear);
  p[2][3] = -1.0f;
  p[3][2] = znear * zfar / (zfar - znear);
  return p;
}

glm::mat4 orthoReverseZ(float left, float right, float bottom, float top, float znear, float zfar) {
  glm::mat4 flip(1.0f);
  flip[2][2] = -1.0f;
  flip[3][2] = 1.0f;  // z' = w - z
  return flip * glm::orthoRH_ZO(left, right, bottom, top, znear, zfar);
}

glm::vec3 safeNormalize(const glm::vec3& v, const glm::vec3& fallback) {
  const float len = glm::length(v);
  return len > 1e-12f && std::isfinite(len) ? v / len : fallback;
}

glm::mat4 lookAlong(const glm::vec3& eye, const glm::vec3& forward) {
  const glm::vec3 up = std::abs(forward.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  return glm::lookAt(eye, eye + forward, up);
}

CameraView cameraFromNode(const Scene& scene, int nodeIndex, float aspect) {
  const Node& node = scene.nodes.at(nodeIndex);
  const Camera& cam = scene.cameras.at(node.camera);
  CameraView v;
  // Strip scale from the camera's world matrix: a view matrix must be rigid.
  glm::mat4 w = node.world;
  glm::vec3 x = glm::vec3(w[0]), y = glm::vec3(w[1]), z = glm::vec3(w[2]);
  auto safeNormalize = [](glm::vec3 a, glm::vec3 fallback) {
    float l = glm::length(a);
    return (l > 1e-20f && std::isfinite(l)) ? a / l : fallback;
  };
  x = safeNormalize(x, {1, 0, 0});
  y = safeNormalize(y, {0, 1, 0});
  z = safeNormalize(z, {0, 0, 1});
  glm::mat4 rigid(glm::vec4(x, 0), glm::vec4(y, 0), glm::vec4(z, 0), w[3]);
  v.view = glm::inverse(rigid);
  v.position = glm::vec3(w[3]);
  v.znear = std::max(cam.znear, 1e-6f);
  v.zfar = std::max(cam.zfar, v.znear * 2.0f);
  v.yfov = std::clamp(cam.yfov, 1e-3f, 3.1f);
  // The output's aspect wins over the file's: a glTF aspectRatio of 1 on a 4:3 image would
  // stretch the picture. The vertical field of view is kept.
  v.proj = perspectiveReverseZ(v.yfov, aspect, v.znear, v.zfar);
  return v;
}

CameraView cameraFramingBounds(const glm::vec3& bmin, const glm::vec3& bmax, float aspect) {
  CameraView v;
  glm::vec3 center = 0.5f * (bmin + bmax);
  // Any size a float holds frames the same (a 1e-3 floor framed tiny models as a speck).
  float radius = std::max(0.5f * glm::length(bmax - bmin), 1e-20f);
  v.yfov = glm::radians(45.0f);
  float fit = std::min(v.yfov, 2.0f * std::atan(std::tan(v.yfov * 0.5f) * aspect));
  float dist = radius / std::sin(fit * 0.5f);
  glm::vec3 dir = glm::normalize(glm::vec3(0.35f, 0.45f, 1.0f));
  v.position = center + dir * dist;
  v.view = glm::lookAt(v.position, center, glm::vec3(0, 1, 0));
  v.znear = std::max(dist - radius * 1.5f, dist * 1e-3f);
  v.zfar = dist + radius * 1.5f;
  v.proj = perspectiveReverseZ(v.yfov, aspect, v.znear, v.zfar);
  return v;
}

CameraView activeCamera(const Scene& scene, float aspect) {
  if (scene.activeCameraNode >= 0 && scene.nodes[scene.activeCameraNode].camera >= 0)
    return cameraFromNode(scene, scene.activeCameraNode, aspect);
  glm::vec3 bmin, bmax;
  scene.worldBounds(bmin, bmax);
  return cameraFramingBounds(bmin, bmax, aspect);
}

const char* errorKindName(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::FileNotFound:
      return "file not found";
    case ErrorKind::EmptyFile:
      return "empty file";
    case ErrorKind::Parse:
      return "parse error";
    case ErrorKind::Schema:
      return "schema error";
    case ErrorKind::IndexOutOfRange:
      return "index out of range";
    case ErrorKind::MissingResource:
      return "missing resource";
    case ErrorKind::NonFinite:
      return "non-finite data";
    case ErrorKind::Cycle:
      return "cyclic node hierarchy";
    case ErrorKind::InvalidData:
      return "invalid data";
    case ErrorKind::Unsupported:
      return "unsupported";
    case ErrorKind::Vulkan:
      return "vulkan error";
    case ErrorKind::Usage:
      return "usage error";
    case ErrorKind::ShaderInterface:
      return "shader interface mismatch";
    case ErrorKind::Output:
      return "output error";
  }
  return "error";
}

}  // namespace gi
