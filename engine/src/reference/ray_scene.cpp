#include "gi/reference/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "gi/animation.h"
#include "gi/errors.h"

namespace gi::reference {

namespace {

// Offset of spawned rays: 2^-19 of the coordinate scale, i.e. about 16 float ulps. Embree's
// intersection error grows with the distance between the ray origin and the triangle's
// vertices, the hit position's error with its own magnitude; the scale covers both. (The
// closed-form tests still pass at 2^-23, one ulp, and fail without an offset.)
constexpr float kOffsetRelative = 1.0f / 524288.0f;

float maxAbs(const glm::vec3& v) {
  return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::vec3 safeNormalize(const glm::vec3& v, const glm::vec3& fallback) {
  const float len2 = glm::dot(v, v);
  return (len2 > 1e-30f && std::isfinite(len2)) ? v / std::sqrt(len2) : fallback;
}

// Cofactor of the upper 3x3 signed by the determinant (the rasteriser's normal matrix):
// transforms normals like the inverse transpose and stays finite for singular matrices.
glm::mat3 normalMatrix(const glm::mat4& m) {
  const glm::vec3 a(m[0]), b(m[1]), c(m[2]);
  glm::mat3 cof(glm::cross(b, c), glm::cross(c, a), glm::cross(a, b));
  if (glm::dot(a, glm::cross(b, c)) < 0.0f) cof = -cof;
  return cof;
}

void embreeError(void* /*user*/, RTCError code, const char* message) {
  // Errors raised during construction are turned into exceptions by the caller via
  // rtcGetDeviceError; this callback only keeps Embree from printing to stderr.
  (void)code;
  (void)message;
}

}  // namespace

// One mesh instance: world-space vertex data (positions padded by one element for Embree's
// 16-byte loads) and its triangles.
struct Instance {
  std::vector<glm::vec3> positions;  // world space, size = vertex count + 1 (padding)
  std::vector<glm::vec3> normals;    // world space, unit
  std::vector<glm::vec2> uvs;
  std::vector<uint32_t> indices;      // kept triangles only
  std::vector<uint32_t> triangleIds;  // index of each kept triangle in the source mesh
  uint32_t material = 0;
  int node = -1, mesh = -1;
};

struct RayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  // Indexed by Embree geometry ID; heap-allocated so the buffers Embree shares never move.
  std::vector<std::unique_ptr<Instance>> instances;
  size_t triangles = 0;
  glm::vec3 bmin{0.0f}, bmax{0.0f};

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  void check(const char* what) const {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE)
      throw Error(
          ErrorKind::InvalidData, "",
          std::string("embree: ") + what + " failed (error " + std::to_string(int(e)) + ")");
  }

  void fillHit(const RTCRayHit& rh, const glm::vec3& org, SurfaceHit& hit) const {
    const Instance& inst = *instances[rh.hit.geomID];
    const uint32_t* tri = &inst.indices[size_t(rh.hit.primID) * 3];
    const glm::vec3 &p0 = inst.positions[tri[0]], &p1 = inst.positions[tri[1]],
                    &p2 = inst.positions[tri[2]];
    const float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
    hit.t = rh.ray.tfar;
    hit.position = w * p0 + u * p1 + v * p2;
    const glm::vec3 toOrigin = org - hit.position;
    glm::vec3 ng = safeNormalize(glm::cross(p1 - p0, p2 - p0),
                                 safeNormalize(glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z),
                                               glm::vec3(0.0f, 1.0f, 0.0f)));
    if (glm::dot(ng, toOrigin) < 0.0f) ng = -ng;
    glm::vec3 ns = safeNormalize(
        w * inst.normals[tri[0]] + u * inst.normals[tri[1]] + v * inst.normals[tri[2]], ng);
    hit.frontFacing = glm::dot(ns, toOrigin) >= 0.0f;
    if (!hit.frontFacing) ns = -ns;
    hit.geometricNormal = ng;
    hit.shadingNormal = ns;
    hit.uv = w * inst.uvs[tri[0]] + u * inst.uvs[tri[1]] + v * inst.uvs[tri[2]];
    hit.material = inst.material;
    hit.node = inst.node;
    hit.mesh = inst.mesh;
    hit.triangle = inst.triangleIds[rh.hit.primID];
    hit.offsetScale = std::max({maxAbs(hit.position), maxAbs(p0 - hit.position),
                                maxAbs(p1 - hit.position), maxAbs(p2 - hit.position)});
  }
};

RayScene::RayScene(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.device = rtcNewDevice(nullptr);
  if (!m.device)
    throw Error(ErrorKind::InvalidData, "",
                "embree: cannot create a device (error " +
                    std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  rtcSetDeviceErrorFunction(m.device, embreeError, nullptr);
  m.scene = rtcNewScene(m.device);
  rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_HIGH);
  m.bmin = glm::vec3(std::numeric_limits<float>::max());
  m.bmax = glm::vec3(-std::numeric_limits<float>::max());

  const uint32_t materialCount = uint32_t(std::max<size_t>(scene.materials.size(), 1));
  for (size_t n = 0; n < scene.nodes.size(); ++n) {
    const Node& node = scene.nodes[n];
    for (int meshIndex : node.meshes) {
      if (meshIndex < 0 || size_t(meshIndex) >= scene.meshes.size()) continue;
      const Mesh& mesh = scene.meshes[meshIndex];
      if (mesh.indices.size() < 3 || mesh.vertices.empty()) continue;
      auto owned = std::make_unique<Instance>();
      Instance& inst = *owned;
      inst.node = int(n);
      inst.mesh = meshIndex;
      inst.material = std::min(mesh.material, materialCount - 1);
      // The pose the rasteriser draws: morph targets at the node's current weights, then
      // skinning by the node's skin (gi/animation.h, the CPU twin of the skinning pass).
      std::vector<Vertex> posed;
      const bool morphed = !mesh.morphTargets.empty();
      const bool skinned =
          mesh.skinned() && node.skin >= 0 && size_t(node.skin) < scene.skins.size();
      if (morphed) posed = morphVertices(mesh, node.morphWeights);
      if (skinned)
        posed = skinVertices(mesh, morphed ? posed : mesh.vertices, jointMatrices(scene, int(n)));
      const std::vector<Vertex>& vertices = (morphed || skinned) ? posed : mesh.vertices;
      const glm::mat3 nm = normalMatrix(node.world);
      inst.positions.reserve(vertices.size() + 1);
      for (const Vertex& v : vertices) {
        inst.positions.push_back(glm::vec3(node.world * glm::vec4(v.position, 1.0f)));
        inst.normals.push_back(safeNormalize(nm * v.normal, glm::vec3(0.0f)));
        inst.uvs.push_back(v.uv);
      }
      const size_t vertexCount = vertices.size();
      for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        if (a >= vertexCount || b >= vertexCount || c >= vertexCount) continue;
        if (!finite(inst.positions[a]) || !finite(inst.positions[b]) || !finite(inst.positions[c]))
          continue;
        inst.indices.insert(inst.indices.end(), {a, b, c});
        inst.triangleIds.push_back(uint32_t(t / 3));
        for (uint32_t i : {a, b, c}) {
          m.bmin = glm::min(m.bmin, inst.positions[i]);
          m.bmax = glm::max(m.bmax, inst.positions[i]);
        }
      }
      if (inst.indices.empty()) continue;
      inst.positions.emplace_back(0.0f);  // padding: Embree reads vertices with 16-byte loads

      RTCGeometry geom = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                 inst.positions.data(), 0, sizeof(glm::vec3), vertexCount);
      rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                 inst.indices.data(), 0, 3 * sizeof(uint32_t),
                                 inst.indices.size() / 3);
      rtcCommitGeometry(geom);
      const unsigned id = rtcAttachGeometry(m.scene, geom);
      rtcReleaseGeometry(geom);
      m.check("adding a mesh");
      if (id != m.instances.size())
        throw Error(ErrorKind::InvalidData, "", "embree: unexpected geometry id");
      m.triangles += inst.indices.size() / 3;
      m.instances.push_back(std::move(owned));
    }
  }
  rtcCommitScene(m.scene);
  m.check("building the scene");
  if (m.triangles == 0) m.bmin = m.bmax = glm::vec3(0.0f);
}

RayScene::~RayScene() = default;

bool RayScene::intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar,
                         SurfaceHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = org.x;
  rh.ray.org_y = org.y;
  rh.ray.org_z = org.z;
  rh.ray.dir_x = dir.x;
  rh.ray.dir_y = dir.y;
  rh.ray.dir_z = dir.z;
  rh.ray.tnear = std::max(tnear, 0.0f);
  rh.ray.tfar = std::max(tfar, rh.ray.tnear);
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xffffffffu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  impl_->fillHit(rh, org, hit);
  return true;
}

bool RayScene::occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = org.x;
  ray.org_y = org.y;
  ray.org_z = org.z;
  ray.dir_x = dir.x;
  ray.dir_y = dir.y;
  ray.dir_z = dir.z;
  ray.tnear = std::max(tnear, 0.0f);
  ray.tfar = std::max(tfar, ray.tnear);
  ray.time = 0.0f;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &context, &ray);
  // Embree sets tfar to -inf when something was hit.
  return !(ray.tfar >= 0.0f);
}

float RayScene::offsetDistance(const SurfaceHit& hit) {
  return std::max(hit.offsetScale, 1e-30f) * kOffsetRelative;
}

glm::vec3 RayScene::spawnOrigin(const SurfaceHit& hit) {
  return hit.position + offsetDistance(hit) * hit.geometricNormal;
}

std::vector<WorldTriangle> RayScene::triangles(
    const std::function<bool(uint32_t material)>& keep) const {
  std::vector<WorldTriangle> out;
  for (const auto& inst : impl_->instances) {
    if (!keep(inst->material)) continue;
    for (size_t t = 0; t + 2 < inst->indices.size(); t += 3) {
      const uint32_t a = inst->indices[t], b = inst->indices[t + 1], c = inst->indices[t + 2];
      out.push_back({inst->positions[a], inst->positions[b], inst->positions[c], inst->normals[a],
                     inst->normals[b], inst->normals[c], inst->material});
    }
  }
  return out;
}

size_t RayScene::triangleCount() const {
  return impl_->triangles;
}
glm::vec3 RayScene::boundsMin() const {
  return impl_->bmin;
}
glm::vec3 RayScene::boundsMax() const {
  return impl_->bmax;
}

}  // namespace gi::reference
