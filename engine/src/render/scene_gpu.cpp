#include "render/scene_gpu.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <tuple>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/animation.h"
#include "gi/errors.h"
#include "gi/gbuffer.h"
#include "gi/vk/common.h"

namespace gi {

using namespace gi::vk;

namespace {

// std140 mirror of DrawView in scene_view.glsl; one 256-byte slot per view (the largest
// minUniformBufferOffsetAlignment Vulkan allows).
struct DrawViewUniforms {
  glm::mat4 view, proj;
  glm::vec4 params, lightPosType, lightDirRange, lightRadiance, lightCone, viewport;
};
constexpr VkDeviceSize kViewSlotBytes = 256;

// Push constants of one draw (gbuffer.vert, scene_depth.vert, scene_rsm.vert): what every
// vertex of the draw needs, read once for all lanes instead of from the instance buffer per
// vertex (llvmpipe loads a non-uniform buffer index once per lane). std430: the mat3 is three
// vec4 columns. The depth shader declares only `model`.
struct DrawPush {
  glm::mat4 model;
  glm::vec4 normalMatrix[3];
  uint32_t instance;
};
static_assert(sizeof(DrawPush) == 116 && sizeof(DrawPush) <= 128, "guaranteed push range");
struct DepthPush {  // scene_depth.vert's: the model matrix alone
  glm::mat4 model;
};

// material.glsl's uniform block, one 256-byte slot per material (the largest offset alignment
// Vulkan allows), bound with the material's descriptor set.
struct MaterialUniforms {
  glm::vec4 baseColor, emission, params;
};
constexpr VkDeviceSize kMaterialSlotBytes = 256;
constexpr size_t kViewSlotsPerChunk = 256;
static_assert(sizeof(DrawViewUniforms) <= kViewSlotBytes);
static_assert(kDrawViewStride == kViewSlotBytes);

Image makeTexture(Context& ctx, VkFormat format, uint32_t w, uint32_t h, const void* pixels,
                  size_t bytes) {
  ImageDesc desc;
  desc.format = format;
  desc.width = w;
  desc.height = h;
  desc.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  Image img(ctx, desc);
  uploadImage(ctx, img, pixels, bytes);
  return img;
}

}  // namespace

// ---- views --------------------------------------------------------------------------------

SceneView SceneView::fromCamera(const CameraView& camera) {
  SceneView v;
  v.view = camera.view;
  v.proj = camera.proj;
  v.znear = camera.znear;
  v.zfar = camera.zfar;
  return v;
}

SceneView SceneView::perspective(const glm::vec3& eye, const glm::vec3& forward, float yfov,
                                 float aspect, float znear, float zfar) {
  const glm::vec3 f = safeNormalize(forward, glm::vec3(0, 0, -1));
  SceneView v;
  v.view = lookAlong(eye, f);
  v.proj = perspectiveReverseZ(yfov, aspect, znear, zfar);
  v.znear = znear;
  v.zfar = zfar;
  return v;
}

SceneView SceneView::orthographic(const glm::vec3& eye, const glm::vec3& forward, float halfWidth,
                                  float halfHeight, float znear, float zfar) {
  const glm::vec3 f = safeNormalize(forward, glm::vec3(0, 0, -1));
  SceneView v;
  v.projection = Projection::Orthographic;
  v.view = lookAlong(eye, f);
  v.proj = orthoReverseZ(-halfWidth, halfWidth, -halfHeight, halfHeight, znear, zfar);
  v.znear = znear;
  v.zfar = zfar;
  return v;
}

SceneView SceneView::paraboloid(const glm::vec3& center, const glm::vec3& axis, float znear,
                                float zfar) {
  const glm::vec3 f = safeNormalize(axis, glm::vec3(0, -1, 0));
  SceneView v;
  v.projection = Projection::Paraboloid;
  v.view = lookAlong(center, f);
  v.znear = znear;
  v.zfar = zfar;
  return v;
}

std::array<SceneView, 6> SceneView::cube(const glm::vec3& center, float znear, float zfar) {
  const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::array<SceneView, 6> faces;
  for (int i = 0; i < 6; ++i)
    faces[i] = perspective(center, axes[i], glm::radians(90.0f), 1.0f, znear, zfar);
  return faces;
}

std::vector<VkFormat> sceneColorFormats(SceneOutputs outputs) {
  switch (outputs) {
    case SceneOutputs::Depth:
      return {};
    case SceneOutputs::GBuffer:
      return {gbuffer::kPackedFormat, gbuffer::kMotionFormat};
    case SceneOutputs::ReflectiveShadowMap:
      // Flux in 32-bit floats: a texel of a large map carries a tiny share of the light's
      // power, which half floats would round to subnormals.
      return {VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT,
              VK_FORMAT_R32G32B32A32_SFLOAT};
  }
  return {};
}

// ---- upload -------------------------------------------------------------------------------

SceneGpu::SceneGpu(Context& ctx, const Scene& scene) : ctx_(ctx), scene_(scene) {
  upload();
  updateDeformations();  // joint matrices of the scene as loaded
  createPipelines();
}

SceneGpu::~SceneGpu() = default;

void SceneGpu::upload() {
  // Loaders guarantee a material; a scene built in code might not have one.
  materials_ = scene_.materials;
  if (materials_.empty()) materials_.emplace_back();
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  struct Range {
    uint32_t firstIndex, indexCount;
    int32_t vertexOffset;
  };
  std::vector<Range> ranges;
  for (const Mesh& m : scene_.meshes) {
    ranges.push_back(
        {uint32_t(indices.size()), uint32_t(m.indices.size()), int32_t(vertices.size())});
    vertices.insert(vertices.end(), m.vertices.begin(), m.vertices.end());
    indices.insert(indices.end(), m.indices.begin(), m.indices.end());
  }

  pose_.nodes = scene_.nodes;
  pose_.roots = scene_.roots;
  pose_.skins = scene_.skins;
  pose_.animations = scene_.animations;
  pose_.cameras = scene_.cameras;
  pose_.activeCameraNode = scene_.activeCameraNode;
  // Materials that draw alike share one index (and one descriptor bind per pass): e.g. a JSON
  // scene's primitives each bring a material of their own, often the same one.
  std::vector<uint32_t> canonical(materials_.size());
  {
    std::map<std::tuple<std::array<float, 10>, int>, uint32_t> seen;
    for (uint32_t i = 0; i < materials_.size(); ++i) {
      const Material& m = materials_[i];
      const std::array<float, 10> v = {
          m.baseColor.r, m.baseColor.g, m.baseColor.b, m.baseColor.a, m.emission.r,
          m.emission.g,  m.emission.b,  m.roughness,   m.metallic,    m.doubleSided ? 1.0f : 0.0f};
      const bool finite = std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
      canonical[i] = finite ? seen.try_emplace({v, m.baseColorTexture}, i).first->second : i;
    }
  }
  std::vector<Vertex> rest;
  std::vector<glm::uvec4> jointIndices;
  std::vector<glm::vec4> jointWeights;
  uint32_t jointTotal = 0;
  for (size_t n = 0; n < scene_.nodes.size(); ++n) {
    const Node& node = scene_.nodes[n];
    for (int m : node.meshes) {
      const Mesh& mesh = scene_.meshes[m];
      if (mesh.indices.empty()) continue;
      const bool skinned =
          mesh.skinned() && node.skin >= 0 && size_t(node.skin) < scene_.skins.size();
      const bool morphed = !mesh.morphTargets.empty();
      int32_t vertexOffset = ranges[m].vertexOffset;
      if (skinned || morphed) {
        // A private copy of the vertices, deformed in place every frame.
        Deformed d;
        d.node = int(n);
        d.mesh = m;
        d.count = uint32_t(mesh.vertices.size());
        d.srcFirst = uint32_t(rest.size());
        d.dstFirst = uint32_t(vertices.size());
        d.jointFirst = jointTotal;
        d.jointCount = skinned ? uint32_t(scene_.skins[node.skin].joints.size()) : 0;
        jointTotal += d.jointCount;
        rest.insert(rest.end(), mesh.vertices.begin(), mesh.vertices.end());
        for (size_t v = 0; v < mesh.vertices.size(); ++v) {
          jointIndices.push_back(skinned ? mesh.joints[v] : glm::uvec4(0));
          jointWeights.push_back(skinned ? mesh.weights[v] : glm::vec4(0.0f));
        }
        vertices.insert(vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
        vertexOffset = int32_t(d.dstFirst);
        deformed_.push_back(std::move(d));
      }
      GpuInstance inst;
      inst.model = inst.prevModel = node.world;
      inst.normalMatrix = glm::mat4(cofactor3(node.world));
      const uint32_t materialIndex =
          canonical[std::min<uint32_t>(mesh.material, uint32_t(materials_.size() - 1))];
      inst.material = glm::uvec4(materialIndex, uint32_t(vertexOffset), 0, 0);
      instanceRefs_.push_back({int(n), m, uint32_t(instances_.size()), ranges[m].firstIndex});
      draws_.push_back({ranges[m].firstIndex, ranges[m].indexCount, vertexOffset,
                        uint32_t(instances_.size()), materialIndex});
      instances_.push_back(inst);
      instanceNodes_.push_back(int(n));
      dynamic_.push_back(skinned || morphed ? 1 : 0);
    }
  }
  // Keep buffers non-empty so descriptors stay valid for an empty scene.
  if (vertices.empty()) vertices.emplace_back();
  if (indices.empty()) indices.push_back(0);
  vertexBuffer_ =
      createDeviceBuffer(ctx_, vertices.data(), vertices.size() * sizeof(Vertex),
                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                             VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  indexBuffer_ =
      createDeviceBuffer(ctx_, indices.data(), indices.size() * sizeof(uint32_t),
                         VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (!deformed_.empty()) {
    // Rest vertices and joint matrices change on the CPU (morphs, poses): host-visible.
    restBuffer_ =
        Buffer(ctx_, rest.size() * sizeof(Vertex), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    restBuffer_.write(rest.data(), rest.size() * sizeof(Vertex));
    jointIndexBuffer_ =
        createDeviceBuffer(ctx_, jointIndices.data(), jointIndices.size() * sizeof(glm::uvec4),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    jointWeightBuffer_ =
        createDeviceBuffer(ctx_, jointWeights.data(), jointWeights.size() * sizeof(glm::vec4),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    jointBuffer_ = Buffer(ctx_, std::max<size_t>(jointTotal, 1) * sizeof(glm::mat4),
                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  }
  // Grouped by material so each material's descriptor set is bound once.
  std::stable_sort(
      draws_.begin(), draws_.end(),
      [](const SceneDrawItem& a, const SceneDrawItem& b) { return a.material < b.material; });
  std::vector<GpuInstance> uploaded = instances_;
  if (uploaded.empty()) uploaded.emplace_back();  // keep the buffer non-empty
  // Host-visible: animated nodes rewrite their model matrices every frame.
  instanceBuffer_ =
      Buffer(ctx_, uploaded.size() * sizeof(GpuInstance), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  instanceBuffer_.write(uploaded.data(), uploaded.size() * sizeof(GpuInstance));
  instancesDirty_ = false;

  std::vector<GpuMaterial> materials;
  for (const Material& m : materials_) {
    const int tex = m.baseColorTexture >= 0 && m.baseColorTexture < int(scene_.textures.size())
                        ? m.baseColorTexture
                        : -1;
    materials.push_back({m.baseColor, glm::vec4(m.emission, 0.0f),
                         glm::vec4(m.roughness, m.metallic, float(tex), m.doubleSided)});
  }
  materialBuffer_ =
      createDeviceBuffer(ctx_, materials.data(), materials.size() * sizeof(GpuMaterial),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<uint8_t> slots(materials.size() * kMaterialSlotBytes, 0);
  for (size_t i = 0; i < materials.size(); ++i) {
    const GpuMaterial& m = materials[i];
    const MaterialUniforms u{
        m.baseColor, glm::vec4(glm::vec3(m.emission), 1.0f),
        glm::vec4(std::clamp(m.params.x, 0.0f, 1.0f), std::clamp(m.params.y, 0.0f, 1.0f),
                  m.params.z >= 0.0f ? 1.0f : 0.0f, m.params.w)};
    std::memcpy(&slots[i * kMaterialSlotBytes], &u, sizeof u);
  }
  materialUniforms_ =
      createDeviceBuffer(ctx_, slots.data(), slots.size(), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);

  const uint8_t white[4] = {255, 255, 255, 255};
  for (const Texture& t : scene_.textures) {
    const bool valid =
        t.width > 0 && t.height > 0 && t.rgba8.size() == size_t(t.width) * t.height * 4;
    textures_.push_back(valid ? makeTexture(ctx_, VK_FORMAT_R8G8B8A8_SRGB, t.width, t.height,
                                            t.rgba8.data(), t.rgba8.size())
                              : makeTexture(ctx_, VK_FORMAT_R8G8B8A8_SRGB, 1, 1, white, 4));
  }
  // Bound for materials without a texture (the binding must always be valid).
  whiteTexture_ = makeTexture(ctx_, VK_FORMAT_R8G8B8A8_SRGB, 1, 1, white, 4);
  linearRepeat_ = Sampler(ctx_, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT);
}

void SceneGpu::createPipelines() {
  // Descriptor layouts come from the shaders; the per-draw push constants are checked against
  // DrawPush (the depth shaders take only its model matrix: DepthPush).
  const CppBlock drawPush = GI_CPP_BLOCK(DrawPush, model, normalMatrix, instance);
  const CppBlock depthPush = GI_CPP_BLOCK(DepthPush, model);
  const std::vector<VkVertexInputAttributeDescription> fullVertex = {
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
      {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
      {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}};
  GraphicsDesc g;
  g.name = "scene: gbuffer.vert + gbuffer.frag";
  g.vertex = loadSpirv("gbuffer.vert");
  g.fragment = loadSpirv("gbuffer.frag");
  g.blocks.pushConstants = drawPush;
  g.vertexLayout.stride = sizeof(Vertex);
  g.vertexLayout.attributes = fullVertex;
  g.colorFormats = sceneColorFormats(SceneOutputs::GBuffer);
  g.depthFormat = kSceneDepthFormat;
  gbufferPipeline_ = Pipeline::graphics(ctx_, g);

  GraphicsDesc d;
  d.name = "scene: scene_depth.vert + scene_depth.frag";
  d.vertex = loadSpirv("scene_depth.vert");
  d.fragment = loadSpirv("scene_depth.frag");
  d.blocks.pushConstants = depthPush;
  d.vertexLayout.stride = sizeof(Vertex);
  d.vertexLayout.attributes = {fullVertex[0]};
  d.depthFormat = kSceneDepthFormat;
  depthPipeline_ = Pipeline::graphics(ctx_, d);

  // Depth peeling: the depth draw whose fragments not behind the previous layer are discarded.
  GraphicsDesc peel = d;
  peel.name = "scene: scene_depth.vert + scene_depth_peel.frag";
  peel.fragment = loadSpirv("scene_depth_peel.frag");
  peelPipeline_ = Pipeline::graphics(ctx_, peel);
  nearestClamp_ = Sampler(ctx_, VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);

  GraphicsDesc r = g;
  r.name = "scene: scene_rsm.vert + scene_rsm.frag";
  r.vertex = loadSpirv("scene_rsm.vert");
  r.fragment = loadSpirv("scene_rsm.frag");
  r.colorFormats = sceneColorFormats(SceneOutputs::ReflectiveShadowMap);
  rsmPipeline_ = Pipeline::graphics(ctx_, r);
}

// ---- pose ---------------------------------------------------------------------------------

uint64_t SceneGpu::triangleCount() const {
  uint64_t n = 0;
  for (const SceneDrawItem& d : draws_) n += d.indexCount / 3;
  return n;
}

void SceneGpu::setTime(double seconds) {
  pose_.animate(seconds);
  for (size_t i = 0; i < instanceNodes_.size(); ++i) {
    GpuInstance& inst = instances_[i];
    const glm::mat4& world = pose_.nodes[instanceNodes_[i]].world;
    if (inst.model != world) {
      ++poseVersion_;
      if (!dynamic_[i]) {
        dynamic_[i] = 1;
        ++staticVersion_;
      }
    }
    inst.model = world;
    inst.normalMatrix = glm::mat4(cofactor3(world));
  }
  instancesDirty_ = true;
  updateDeformations();
}

// The previous model matrix is the one the last rendered frame used (none before the first
// frame: no motion), like the camera's previous view-projection in the renderer.
void SceneGpu::beginFrame() {
  counts_ = {};
  const bool first = rendered_.size() != instances_.size();
  for (size_t i = 0; i < instances_.size(); ++i) {
    const glm::mat4 prev = first ? instances_[i].model : rendered_[i];
    if (prev != instances_[i].prevModel) {
      instances_[i].prevModel = prev;
      instancesDirty_ = true;
    }
  }
  if (instancesDirty_ && !instances_.empty())
    instanceBuffer_.write(instances_.data(), instances_.size() * sizeof(GpuInstance));
  instancesDirty_ = false;
  rendered_.resize(instances_.size());
  for (size_t i = 0; i < instances_.size(); ++i) rendered_[i] = instances_[i].model;
  viewSlotsUsed_ = 0;
}

void SceneGpu::updateDeformations() {
  for (Deformed& d : deformed_) {
    const Mesh& mesh = scene_.meshes[d.mesh];
    if (d.jointCount > 0) {
      std::vector<glm::mat4> joints = jointMatrices(pose_, d.node);
      if (joints != d.lastJoints) {
        jointBuffer_.write(joints.data(), joints.size() * sizeof(glm::mat4),
                           size_t(d.jointFirst) * sizeof(glm::mat4));
        d.lastJoints = std::move(joints);
        d.dirty = true;
        ++poseVersion_;
      }
    }
    if (!mesh.morphTargets.empty()) {
      const std::vector<float>& weights = pose_.nodes[d.node].morphWeights;
      if (weights != d.lastWeights || d.lastWeights.empty()) {
        const std::vector<Vertex> morphed = morphVertices(mesh, weights);
        restBuffer_.write(morphed.data(), morphed.size() * sizeof(Vertex),
                          size_t(d.srcFirst) * sizeof(Vertex));
        d.lastWeights = weights;
        d.dirty = true;
        ++poseVersion_;
      }
    }
  }
}

// Per-axis min and max of a morph target's position deltas (cached: targets never change).
const std::pair<glm::vec3, glm::vec3>& SceneGpu::morphDeltaBounds(int mesh, size_t target) const {
  auto& cached = morphBounds_[mesh];
  if (cached.empty())
    for (const MorphTarget& t : scene_.meshes[mesh].morphTargets) {
      glm::vec3 lo(0.0f), hi(0.0f);
      for (const glm::vec3& d : t.positionDeltas)
        if (std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z)) {
          lo = glm::min(lo, d);
          hi = glm::max(hi, d);
        }
      cached.emplace_back(lo, hi);
    }
  return cached[target];
}

// World box of an instance: its mesh box (widened by its morph targets at the current weights)
// under its node's transform, and for a skinned instance also under every joint's skinning
// transform (a skinned vertex is a weighted mean of those transforms of itself, or stays in its
// bind pose when its weights vanish). Non-finite corners are left out.
SceneGpu::Box SceneGpu::instanceBox(size_t node, int m) const {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi = -lo;
  auto addBox = [&](const glm::vec3& bmin, const glm::vec3& bmax, const glm::mat4& t) {
    for (int i = 0; i < 8; ++i) {
      const glm::vec3 c(i & 1 ? bmax.x : bmin.x, i & 2 ? bmax.y : bmin.y, i & 4 ? bmax.z : bmin.z);
      const glm::vec3 w = glm::vec3(t * glm::vec4(c, 1.0f));
      if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) continue;
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
  };
  const Mesh& mesh = scene_.meshes[m];
  glm::vec3 bmin = mesh.boundsMin, bmax = mesh.boundsMax;
  const std::vector<float>& weights = pose_.nodes[node].morphWeights;
  for (size_t t = 0; t < mesh.morphTargets.size() && t < weights.size(); ++t) {
    // Per-axis worst case of w * delta over the target's vertices, added target by target.
    const float w = std::isfinite(weights[t]) ? weights[t] : 0.0f;
    const auto& [dmin, dmax] = morphDeltaBounds(m, t);
    bmin += glm::min(glm::vec3(0.0f), glm::min(w * dmin, w * dmax));
    bmax += glm::max(glm::vec3(0.0f), glm::max(w * dmin, w * dmax));
  }
  const glm::mat4& world = pose_.nodes[node].world;
  addBox(bmin, bmax, world);
  // The joint matrices updateDeformations() computed for this instance.
  const auto d = std::find_if(deformed_.begin(), deformed_.end(), [&](const Deformed& e) {
    return e.node == int(node) && e.mesh == m;
  });
  if (d != deformed_.end())
    for (const glm::mat4& j : d->lastJoints) addBox(bmin, bmax, world * j);
  return {lo, hi};
}

// World bounds of the posed geometry: the union of the instances' boxes.
void SceneGpu::bounds(glm::vec3& lo, glm::vec3& hi) const {
  lo = glm::vec3(std::numeric_limits<float>::max());
  hi = -lo;
  for (size_t n = 0; n < pose_.nodes.size(); ++n)
    for (int m : pose_.nodes[n].meshes) {
      const Box b = instanceBox(n, m);
      lo = glm::min(lo, b.first);
      hi = glm::max(hi, b.second);
    }
  if (lo.x > hi.x) {  // no geometry: a unit box keeps shadow fits finite
    lo = glm::vec3(-1.0f);
    hi = glm::vec3(1.0f);
  }
}

const std::vector<SceneGpu::Box>& SceneGpu::instanceBoxes() {
  if (boxesVersion_ != poseVersion_ || instanceBoxes_.size() != instanceRefs_.size()) {
    instanceBoxes_.clear();
    for (const SurfacePointsPass::InstanceRef& r : instanceRefs_)
      instanceBoxes_.push_back(instanceBox(size_t(r.node), r.mesh));
    boxesVersion_ = poseVersion_;
  }
  return instanceBoxes_;
}

// Culling: the box is outside the view when its eight corners all lie beyond one plane of the
// clip volume (-w <= x, y <= w; reverse-Z: 0 <= z <= w). Conservative: a box that straddles
// planes without touching the frustum is still drawn; non-finite corners never cull.
bool SceneGpu::inView(const SceneDrawItem& d, const glm::mat4* worldToClip) {
  bool visible = true;
  if (culling_ && worldToClip && d.instance < instanceBoxes().size()) {
    const auto& [lo, hi] = instanceBoxes_[d.instance];
    if (lo.x <= hi.x) {
      int out[6] = {0, 0, 0, 0, 0, 0};
      for (int i = 0; i < 8; ++i) {
        const glm::vec4 c = *worldToClip * glm::vec4(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y,
                                                     i & 4 ? hi.z : lo.z, 1.0f);
        out[0] += c.x < -c.w;
        out[1] += c.x > c.w;
        out[2] += c.y < -c.w;
        out[3] += c.y > c.w;
        out[4] += c.z < 0.0f;
        out[5] += c.z > c.w;
      }
      for (int k : out) visible = visible && k < 8;
    }
  }
  ++(visible ? counts_.drawn : counts_.culled);
  return visible;
}

// ---- draws --------------------------------------------------------------------------------

void SceneGpu::declareRead(PassBuilder& builder, BufferUsage usage) const {
  if (vertices_.valid()) builder.read(vertices_, usage);
}

VkDescriptorBufferInfo SceneGpu::viewSlot(const SceneView& view, const LightInfo* light,
                                          VkExtent2D extent) {
  const size_t chunk = viewSlotsUsed_ / kViewSlotsPerChunk;
  if (chunk >= viewChunks_.size())
    viewChunks_.emplace_back(ctx_, kViewSlotBytes * kViewSlotsPerChunk,
                             VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
  const VkDeviceSize offset = (viewSlotsUsed_ % kViewSlotsPerChunk) * kViewSlotBytes;
  ++viewSlotsUsed_;
  DrawViewUniforms u{};
  u.view = view.view;
  u.proj = view.proj;
  u.params = glm::vec4(float(int(view.projection == Projection::Paraboloid     ? 2
                                 : view.projection == Projection::Orthographic ? 1
                                                                               : 0)),
                       view.znear, view.zfar, 0.0f);
  const VkRect2D vp = view.viewport.extent.width > 0 ? view.viewport : VkRect2D{{0, 0}, extent};
  u.viewport = glm::vec4(vp.offset.x, vp.offset.y, vp.extent.width, vp.extent.height);
  if (light) {
    const float type = light->type == LightType::Directional ? 0.0f
                       : light->type == LightType::Point     ? 1.0f
                                                             : 2.0f;
    u.lightPosType = glm::vec4(light->position, type);
    u.lightDirRange = glm::vec4(light->direction, light->range);
    u.lightRadiance = glm::vec4(light->radiance, 0.0f);
    // World area of one texel of an orthographic view: (2 / proj[0][0]) x (2 / proj[1][1]) /
    // texels.
    const float texelArea = view.projection == Projection::Orthographic
                                ? std::abs(4.0f / (view.proj[0][0] * view.proj[1][1])) /
                                      float(vp.extent.width * vp.extent.height)
                                : 0.0f;
    u.lightCone = glm::vec4(light->cosInner, light->cosOuter, texelArea, 0.0f);
  }
  viewChunks_[chunk].write(&u, sizeof u, offset);
  return {viewChunks_[chunk].handle(), offset, kViewSlotBytes};
}

void SceneGpu::beginRendering(PassContext& pc, const SceneTargets& t, size_t colorCount) {
  if (t.colors.size() != colorCount || t.depth == VK_NULL_HANDLE)
    throw Error(ErrorKind::Usage, "",
                "GpuScene draw: expected " + std::to_string(colorCount) +
                    " colour target(s) and a depth target, got " + std::to_string(t.colors.size()));
  std::vector<VkRenderingAttachmentInfo> colors(colorCount);
  for (size_t i = 0; i < colorCount; ++i) {
    colors[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    colors[i].imageView = t.colors[i];
    colors[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    colors[i].loadOp = t.clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    colors[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    colors[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
  }
  VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depth.imageView = t.depth;
  depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  depth.loadOp = t.clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
  depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  depth.clearValue.depthStencil = {0.0f, 0};  // reverse-Z: 0 is the far plane
  VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
  info.renderArea = {{0, 0}, t.extent};
  info.layerCount = 1;
  info.colorAttachmentCount = uint32_t(colorCount);
  info.pColorAttachments = colors.data();
  info.pDepthAttachment = &depth;
  vkCmdBeginRendering(pc.cmd(), &info);
}

void SceneGpu::bindGeometry(VkCommandBuffer cmd) {
  VkDeviceSize offset = 0;
  VkBuffer vb = vertexBuffer_.handle();
  vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
  vkCmdBindIndexBuffer(cmd, indexBuffer_.handle(), 0, VK_INDEX_TYPE_UINT32);
}

void SceneGpu::bindMaterial(PassContext& pc, const Pipeline& p, uint32_t material,
                            VkBuffer uniforms, VkDeviceSize offset, VkDeviceSize range) {
  const Material& m = materials_[material];
  const bool textured = m.baseColorTexture >= 0 && m.baseColorTexture < int(textures_.size());
  // The view's uniforms are "Frame" (the main view's FrameUniforms) or "View" (a DrawView);
  // the instances are read only by the G-buffer's vertex shader.
  const ShaderInterface& shader = p.shaderInterface();
  DescriptorWriter w(p);
  w.buffer(shader.find("Frame") ? "Frame" : "View", uniforms, offset, range)
      .buffer("MaterialBlock", materialUniforms_.handle(), material * kMaterialSlotBytes,
              sizeof(MaterialUniforms))
      .texture("baseColorTexture",
               textured ? textures_[m.baseColorTexture].view() : whiteTexture_.view(),
               linearRepeat_.handle());
  if (shader.find("Instances")) w.buffer("Instances", instanceBuffer_.handle());
  pc.descriptors().bind(pc.cmd(), p, w);
}

void SceneGpu::pushDraw(VkCommandBuffer cmd, const Pipeline& p, const SceneDrawItem& d,
                        bool modelOnly) const {
  const GpuInstance& inst = instances_[d.instance];
  DrawPush push;
  push.model = inst.model;
  for (int c = 0; c < 3; ++c) push.normalMatrix[c] = inst.normalMatrix[c];
  push.instance = d.instance;
  static_assert(offsetof(DrawPush, model) == offsetof(DepthPush, model));
  p.pushBytes(cmd, &push, modelOnly ? sizeof(DepthPush) : sizeof push);
}

void SceneGpu::drawGBuffer(PassContext& pc, const SceneTargets& t, VkBuffer viewUniforms,
                           const glm::mat4* cullWorldToClip) {
  VkCommandBuffer c = pc.cmd();
  beginRendering(pc, t, sceneColorFormats(SceneOutputs::GBuffer).size());
  VkViewport viewport{0, 0, float(t.extent.width), float(t.extent.height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, t.extent};
  vkCmdSetViewport(c, 0, 1, &viewport);
  vkCmdSetScissor(c, 0, 1, &scissor);
  if (!draws_.empty()) {
    bindGeometry(c);
    uint32_t boundMaterial = UINT32_MAX;
    for (const SceneDrawItem& d : draws_) {
      if (!inView(d, cullWorldToClip)) continue;
      if (d.material != boundMaterial) {
        bindMaterial(pc, gbufferPipeline_, d.material, viewUniforms, 0, VK_WHOLE_SIZE);
        boundMaterial = d.material;
      }
      pushDraw(c, gbufferPipeline_, d, false);
      vkCmdDrawIndexed(c, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
    }
  }
  vkCmdEndRendering(c);
}

// The view's region of the targets (all of them when its viewport is empty).
void SceneGpu::setViewport(VkCommandBuffer cmd, const SceneView& view, VkExtent2D extent) {
  const VkRect2D rect = view.viewport.extent.width > 0 ? view.viewport : VkRect2D{{0, 0}, extent};
  const VkViewport viewport{float(rect.offset.x),
                            float(rect.offset.y),
                            float(rect.extent.width),
                            float(rect.extent.height),
                            0.0f,
                            1.0f};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &rect);
}

void SceneGpu::drawDepth(PassContext& pc, const SceneTargets& t, std::span<const SceneView> views) {
  drawDepth(pc, t, views, Subset::All);
}

// An instance turns dynamic only when its matrix changes, which also bumps poseVersion_.
const std::vector<SceneGpu::Box>& SceneGpu::dynamicBoxes() {
  if (dynamicBoxesVersion_ != poseVersion_) {
    const std::vector<Box>& all = instanceBoxes();
    dynamicBoxes_.clear();
    for (size_t i = 0; i < all.size() && i < dynamic_.size(); ++i)
      if (dynamic_[i]) dynamicBoxes_.push_back(all[i]);
    dynamicBoxesVersion_ = poseVersion_;
  }
  return dynamicBoxes_;
}

void SceneGpu::drawDepth(PassContext& pc, const SceneTargets& t, std::span<const SceneView> views,
                         Subset subset) {
  VkCommandBuffer c = pc.cmd();
  beginRendering(pc, t, 0);
  if (!draws_.empty()) bindGeometry(c);
  for (const SceneView& v : views) {
    const VkDescriptorBufferInfo slot = viewSlot(v, nullptr, t.extent);
    setViewport(c, v, t.extent);
    DescriptorWriter w(depthPipeline_);
    w.buffer("View", slot.buffer, slot.offset, slot.range);
    pc.descriptors().bind(c, depthPipeline_, w);
    const glm::mat4 clip = v.proj * v.view;
    const glm::mat4* cull = v.projection == Projection::Paraboloid ? nullptr : &clip;
    for (const SceneDrawItem& d : draws_) {
      if (subset != Subset::All && isDynamic(d.instance) != (subset == Subset::Dynamic)) continue;
      if (!inView(d, cull)) continue;
      pushDraw(c, depthPipeline_, d, true);
      vkCmdDrawIndexed(c, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
    }
  }
  vkCmdEndRendering(c);
}

void SceneGpu::drawDepthFromBuffer(PassContext& pc, const SceneTargets& t, VkBuffer views,
                                   std::span<const VkRect2D> viewports) {
  if (views == VK_NULL_HANDLE && !viewports.empty())
    throw Error(ErrorKind::Usage, "", "GpuScene::drawDepthFromBuffer: no view buffer");
  VkCommandBuffer c = pc.cmd();
  beginRendering(pc, t, 0);
  if (!draws_.empty()) bindGeometry(c);
  for (size_t i = 0; i < viewports.size(); ++i) {
    SceneView placed;
    placed.viewport = viewports[i];
    setViewport(c, placed, t.extent);
    DescriptorWriter w(depthPipeline_);
    w.buffer("View", views, VkDeviceSize(i) * kDrawViewStride, sizeof(DrawViewUniforms));
    pc.descriptors().bind(c, depthPipeline_, w);
    counts_.drawn += draws_.size();  // views computed on the GPU: nothing to cull here
    for (const SceneDrawItem& d : draws_) {
      pushDraw(c, depthPipeline_, d, true);
      vkCmdDrawIndexed(c, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
    }
  }
  vkCmdEndRendering(c);
}

void SceneGpu::drawDepthPeeled(PassContext& pc, const SceneTargets& t,
                               std::span<const SceneView> views, VkImageView previous) {
  if (previous == VK_NULL_HANDLE)
    throw Error(ErrorKind::Usage, "", "GpuScene::drawDepthPeeled: no previous depth layer");
  VkCommandBuffer c = pc.cmd();
  beginRendering(pc, t, 0);
  if (!draws_.empty()) bindGeometry(c);
  for (const SceneView& v : views) {
    const VkDescriptorBufferInfo slot = viewSlot(v, nullptr, t.extent);
    setViewport(c, v, t.extent);
    DescriptorWriter w(peelPipeline_);
    w.buffer("View", slot.buffer, slot.offset, slot.range)
        .texture("previousDepth", previous, nearestClamp_.handle());
    pc.descriptors().bind(c, peelPipeline_, w);
    const glm::mat4 clip = v.proj * v.view;
    const glm::mat4* cull = v.projection == Projection::Paraboloid ? nullptr : &clip;
    for (const SceneDrawItem& d : draws_) {
      if (!inView(d, cull)) continue;
      pushDraw(c, peelPipeline_, d, true);
      vkCmdDrawIndexed(c, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
    }
  }
  vkCmdEndRendering(c);
}

void SceneGpu::drawRsm(PassContext& pc, const SceneTargets& t, const SceneView& view,
                       const LightInfo& light) {
  VkCommandBuffer c = pc.cmd();
  beginRendering(pc, t, sceneColorFormats(SceneOutputs::ReflectiveShadowMap).size());
  const VkDescriptorBufferInfo slot = viewSlot(view, &light, t.extent);
  setViewport(c, view, t.extent);
  if (!draws_.empty()) {
    bindGeometry(c);
    uint32_t boundMaterial = UINT32_MAX;
    const glm::mat4 clip = view.proj * view.view;
    const glm::mat4* cull = view.projection == Projection::Paraboloid ? nullptr : &clip;
    for (const SceneDrawItem& d : draws_) {
      if (!inView(d, cull)) continue;
      if (d.material != boundMaterial) {
        bindMaterial(pc, rsmPipeline_, d.material, slot.buffer, slot.offset, slot.range);
        boundMaterial = d.material;
      }
      pushDraw(c, rsmPipeline_, d, false);
      vkCmdDrawIndexed(c, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
    }
  }
  vkCmdEndRendering(c);
}

}  // namespace gi
