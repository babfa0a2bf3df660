#include "gi/renderer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/animation.h"
#include "gi/effect.h"
#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/graph/frame_graph.h"
#include "gi/vk/common.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "gpu_types.h"
#include "light_setup.h"
#include "surface_points_pass.h"

namespace gi {

using namespace gi::vk;
namespace res = gi::resources;

namespace {

// Normal matrix: the cofactor of the model's 3x3 (gi::cofactor3), finite for singular ones.
glm::mat4 normalMatrixOf(const glm::mat4& m) {
  return glm::mat4(cofactor3(m));
}

// The shared vertex buffer as the graph sees it once deformed meshes are written into it.
constexpr const char* kVertices = "vertices";

uint32_t groups(uint32_t n) {
  return (n + 7) / 8;
}

TextureDesc outputRelative(VkFormat format) {
  return TextureDesc{format};
}

}  // namespace

struct Renderer::Impl : EffectContext {
  Context& ctx;
  RenderSettings settings;
  const Scene& scene;
  const EffectRegistry* registry;
  CameraView cameraView;

  // Scene data on the GPU.
  Buffer vertexBuffer, indexBuffer, materialBuffer, instanceBuffer, lightBuffer, frameBuffer;
  struct Draw {
    uint32_t firstIndex, indexCount;
    int32_t vertexOffset;
    uint32_t instance, material;
  };
  std::vector<Draw> draws;
  // Animation: the renderer's own copy of the node hierarchy, posed by setTime().
  Scene pose;
  std::vector<int> instanceNodes;  // node of each gpu::Instance
  std::vector<gpu::Instance> instances;
  bool instancesDirty = true;
  // Deformed (skinned and/or morphed) mesh instances: each owns a copy of its mesh's vertices
  // in vertexBuffer, rewritten by the "skinning" pass from its rest vertices.
  struct Deformed {
    int node = 0, mesh = 0;
    uint32_t srcFirst = 0, dstFirst = 0, count = 0, jointFirst = 0, jointCount = 0;
    std::vector<glm::mat4> lastJoints;
    std::vector<float> lastWeights;
    bool dirty = true;
  };
  std::vector<Deformed> deformed;
  Buffer restBuffer, jointIndexBuffer, jointWeightBuffer, jointBuffer;
  Pipeline skinningPipeline;
  uint32_t skinnedThisFrame = 0;
  // Point representation: created when settings or an effect ask for points.
  uint32_t pointsRequested = 0;
  std::vector<SurfacePointsPass::InstanceRef> instanceRefs;
  std::unique_ptr<SurfacePointsPass> surfacePoints;
  std::vector<Material> sceneMaterials;
  std::vector<Image> textures;
  Image whiteTexture, neutralAO, output;
  Sampler linearRepeat, linearClamp, nearestClamp;
  uint32_t lightCount = 0;
  LightSetup lightSetup;
  std::map<int, std::vector<std::pair<glm::vec3, glm::vec3>>> morphBounds;  // morphDeltaBounds
  glm::mat4 prevViewProj{1.0f};  // the camera of the previous frame (motion vectors)
  uint64_t framesRendered = 0;
  // Shadows: one map per shadowed light (slot), rendered as one or six views.
  std::vector<ShadowMap> shadowMaps;
  Buffer shadowViewBuffer;
  Pipeline shadowPipeline;
  bool shadowPipelineReady = false;  // createPipelines() ran: later shadow maps create it too
  Image environmentMap;

  Pipeline gbufferPipeline, lightingPipeline, tonemapPipeline, floorPipeline;
  SH9 irradiance{};
  struct ActiveEffect {
    std::unique_ptr<Effect> effect;
    EffectInfo info;
    SettingValues settings;
  };
  std::vector<ActiveEffect> effects;

  FrameGraph graph;
  TextureHandle outputHandle;
  bool graphDirty = true, recompiledByLastChange = false;
  double compileMs = 0.0;
  DescriptorArena descriptors;
  GpuTimer timer;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  std::vector<PassTiming> timings;

  Impl(Context& c, const Scene& s, const RenderSettings& rs, const EffectRegistry* reg)
      : ctx(c),
        settings(rs),
        scene(s),
        registry(reg),
        pointsRequested(rs.surfacePoints),
        graph(c, {rs.width, rs.height}),
        descriptors(c),
        timer(c) {
    if (settings.width == 0 || settings.height == 0 || settings.width > 16384 ||
        settings.height > 16384)
      throw Error(ErrorKind::Usage, "", "image size must be between 1x1 and 16384x16384");
    if (settings.shadowMapSize < 16 || settings.shadowMapSize > 8192)
      throw Error(ErrorKind::Usage, "", "shadow map size must be between 16 and 8192");
    cameraView = activeCamera(scene, float(settings.width) / float(settings.height));
    uploadScene();
    updateDeformations();  // joint matrices of the scene as loaded
    updateLights();        // after the joints: the shadow fit bounds skinned meshes by them
    createPipelines();
    for (const EffectConfig& e : settings.effects) {
      if (!registry)
        throw Error(ErrorKind::Usage, "",
                    "effect '" + e.name + "' requested but no registry given");
      ActiveEffect a{registry->create(e.name), registry->info(e.name), e.settings};
      a.effect->prepare(*this, a.settings);
      effects.push_back(std::move(a));
    }
    updateSurfacePoints();
    buildGraph();
    // Raw handles last: nothing after them may throw (~Impl does not run if the ctor throws).
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = ctx.commandPool();
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(ctx.device(), &alloc, &cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    if (VkResult r = vkCreateFence(ctx.device(), &fenceInfo, nullptr, &fence); r != VK_SUCCESS) {
      vkFreeCommandBuffers(ctx.device(), ctx.commandPool(), 1, &cmd);
      check(r, "vkCreateFence");
    }
  }

  ~Impl() override {
    vkDeviceWaitIdle(ctx.device());
    graph.reset();
    effects.clear();
    vkDestroyFence(ctx.device(), fence, nullptr);
    vkFreeCommandBuffers(ctx.device(), ctx.commandPool(), 1, &cmd);
  }

  // EffectContext
  vk::Context& vulkan() override { return ctx; }
  VkBuffer frameUniforms() override { return frameBuffer.handle(); }
  VkSampler nearestSampler() override { return nearestClamp.handle(); }
  VkSampler linearSampler() override { return linearClamp.handle(); }
  VkExtent2D outputExtent() override { return {settings.width, settings.height}; }
  void requestSurfacePoints(uint32_t count) override {
    pointsRequested = std::max(pointsRequested, count);
  }

  // (Re)samples the points when more are asked for than exist (at the scene as loaded).
  void updateSurfacePoints() {
    if (pointsRequested == 0 || (surfacePoints && surfacePoints->count() >= pointsRequested))
      return;
    surfacePoints.reset();
    surfacePoints = std::make_unique<SurfacePointsPass>(ctx, scene, pointsRequested,
                                                        settings.surfacePointSeed, instanceRefs);
  }

  Image makeTexture(VkFormat format, uint32_t w, uint32_t h, const void* pixels, size_t bytes) {
    ImageDesc desc;
    desc.format = format;
    desc.width = w;
    desc.height = h;
    desc.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    Image img(ctx, desc);
    uploadImage(ctx, img, pixels, bytes);
    return img;
  }

  void uploadScene() {
    // Loaders guarantee a material; a scene built in code might not have one.
    sceneMaterials = scene.materials;
    if (sceneMaterials.empty()) sceneMaterials.emplace_back();
    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices;
    struct Range {
      uint32_t firstIndex, indexCount;
      int32_t vertexOffset;
    };
    std::vector<Range> ranges;
    for (const Mesh& m : scene.meshes) {
      ranges.push_back(
          {uint32_t(indices.size()), uint32_t(m.indices.size()), int32_t(vertices.size())});
      vertices.insert(vertices.end(), m.vertices.begin(), m.vertices.end());
      indices.insert(indices.end(), m.indices.begin(), m.indices.end());
    }

    pose.nodes = scene.nodes;
    pose.roots = scene.roots;
    pose.skins = scene.skins;
    pose.animations = scene.animations;
    std::vector<Vertex> rest;
    std::vector<glm::uvec4> jointIndices;
    std::vector<glm::vec4> jointWeights;
    uint32_t jointTotal = 0;
    for (size_t n = 0; n < scene.nodes.size(); ++n) {
      const Node& node = scene.nodes[n];
      for (int m : node.meshes) {
        const Mesh& mesh = scene.meshes[m];
        if (mesh.indices.empty()) continue;
        const bool skinned =
            mesh.skinned() && node.skin >= 0 && size_t(node.skin) < scene.skins.size();
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
          d.jointCount = skinned ? uint32_t(scene.skins[node.skin].joints.size()) : 0;
          jointTotal += d.jointCount;
          rest.insert(rest.end(), mesh.vertices.begin(), mesh.vertices.end());
          for (size_t v = 0; v < mesh.vertices.size(); ++v) {
            jointIndices.push_back(skinned ? mesh.joints[v] : glm::uvec4(0));
            jointWeights.push_back(skinned ? mesh.weights[v] : glm::vec4(0.0f));
          }
          vertices.insert(vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
          vertexOffset = int32_t(d.dstFirst);
          deformed.push_back(std::move(d));
        }
        gpu::Instance inst;
        inst.model = inst.prevModel = node.world;
        inst.normalMatrix = normalMatrixOf(node.world);
        const uint32_t materialIndex =
            std::min<uint32_t>(mesh.material, uint32_t(sceneMaterials.size() - 1));
        inst.material = glm::uvec4(materialIndex, uint32_t(vertexOffset), 0, 0);
        instanceRefs.push_back({int(n), m, uint32_t(instances.size()), ranges[m].firstIndex});
        draws.push_back({ranges[m].firstIndex, ranges[m].indexCount, vertexOffset,
                         uint32_t(instances.size()), materialIndex});
        instances.push_back(inst);
        instanceNodes.push_back(int(n));
      }
    }
    vertexBuffer =
        createDeviceBuffer(ctx, vertices.data(), vertices.size() * sizeof(Vertex),
                           VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    indexBuffer =
        createDeviceBuffer(ctx, indices.data(), indices.size() * sizeof(uint32_t),
                           VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (!deformed.empty()) {
      // Rest vertices and joint matrices change on the CPU (morphs, poses): host-visible.
      restBuffer =
          Buffer(ctx, rest.size() * sizeof(Vertex), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
      restBuffer.write(rest.data(), rest.size() * sizeof(Vertex));
      jointIndexBuffer =
          createDeviceBuffer(ctx, jointIndices.data(), jointIndices.size() * sizeof(glm::uvec4),
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
      jointWeightBuffer =
          createDeviceBuffer(ctx, jointWeights.data(), jointWeights.size() * sizeof(glm::vec4),
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
      jointBuffer = Buffer(ctx, std::max<size_t>(jointTotal, 1) * sizeof(glm::mat4),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    }
    // Grouped by material so each material's descriptor set is bound once.
    std::stable_sort(draws.begin(), draws.end(),
                     [](const Draw& a, const Draw& b) { return a.material < b.material; });
    if (instances.empty()) instances.emplace_back();  // keep the buffer non-empty
    // Host-visible: animated nodes rewrite their model matrices every frame.
    instanceBuffer = Buffer(ctx, instances.size() * sizeof(gpu::Instance),
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    instanceBuffer.write(instances.data(), instances.size() * sizeof(gpu::Instance));

    std::vector<gpu::Material> materials;
    for (const Material& m : sceneMaterials) {
      int tex = m.baseColorTexture >= 0 && m.baseColorTexture < int(scene.textures.size())
                    ? m.baseColorTexture
                    : -1;
      materials.push_back({m.baseColor, glm::vec4(m.emission, 0.0f),
                           glm::vec4(m.roughness, m.metallic, float(tex), 0.0f)});
    }
    materialBuffer =
        createDeviceBuffer(ctx, materials.data(), materials.size() * sizeof(gpu::Material),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    const uint8_t white[4] = {255, 255, 255, 255};
    for (const Texture& t : scene.textures) {
      bool valid = t.width > 0 && t.height > 0 && t.rgba8.size() == size_t(t.width) * t.height * 4;
      textures.push_back(valid ? makeTexture(VK_FORMAT_R8G8B8A8_SRGB, t.width, t.height,
                                             t.rgba8.data(), t.rgba8.size())
                               : makeTexture(VK_FORMAT_R8G8B8A8_SRGB, 1, 1, white, 4));
    }
    // Bound for materials without a texture (the binding must always be valid).
    whiteTexture = makeTexture(VK_FORMAT_R8G8B8A8_SRGB, 1, 1, white, 4);
    // The neutral AO (1 everywhere) that lighting samples when no effect produces AO.
    neutralAO = makeTexture(VK_FORMAT_R8G8B8A8_UNORM, 1, 1, white, 4);
    linearRepeat = Sampler(ctx, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT);
    linearClamp = Sampler(ctx, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
    nearestClamp = Sampler(ctx, VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);

    pose.cameras = scene.cameras;
    pose.activeCameraNode = scene.activeCameraNode;
    prevViewProj = cameraView.proj * cameraView.view;
    const Environment& env = scene.environment;
    irradiance = irradianceSH(env);
    if (env.kind == Environment::Kind::Map && env.mapWidth > 0 && env.mapHeight > 0 &&
        env.mapRGB.size() == size_t(env.mapWidth) * env.mapHeight * 3) {
      std::vector<float> rgba(size_t(env.mapWidth) * env.mapHeight * 4, 1.0f);
      for (size_t i = 0; i < size_t(env.mapWidth) * env.mapHeight; ++i)
        for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = env.mapRGB[i * 3 + c];
      environmentMap = makeTexture(VK_FORMAT_R32G32B32A32_SFLOAT, uint32_t(env.mapWidth),
                                   uint32_t(env.mapHeight), rgba.data(), rgba.size() * 4);
    }
    frameBuffer = Buffer(ctx, sizeof(gpu::FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);

    ImageDesc od;
    od.format = VK_FORMAT_R8G8B8A8_UNORM;
    od.width = settings.width;
    od.height = settings.height;
    od.usage =
        VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    output = Image(ctx, od);
  }

  // Depth-only pipeline of the shadow passes (created once the first shadow map exists).
  void createShadowPipeline() {
    if (shadowMaps.empty() || shadowPipeline.handle() != VK_NULL_HANDLE) return;
    const auto ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    GraphicsDesc sd;
    sd.vertex = loadSpirv("shadow.vert");
    sd.fragment = loadSpirv("shadow.frag");
    sd.bindings = {{0, ssbo}};
    sd.pushConstantBytes = sizeof(glm::mat4) + sizeof(uint32_t);
    sd.vertexLayout.stride = sizeof(Vertex);
    sd.vertexLayout.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)}};
    sd.depthFormat = VK_FORMAT_D32_SFLOAT;  // reverse-Z like the G-buffer (compare >=)
    shadowPipeline = Pipeline::graphics(ctx, sd);
  }

  // Per-axis min and max of a morph target's position deltas (cached: targets never change).
  const std::pair<glm::vec3, glm::vec3>& morphDeltaBounds(int mesh, size_t target) {
    auto& cached = morphBounds[mesh];
    if (cached.empty())
      for (const MorphTarget& t : scene.meshes[mesh].morphTargets) {
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

  // World bounds of the posed geometry (after updateDeformations): each instance's mesh box
  // (widened by its morph targets at the current weights) under its node's transform, and for
  // a skinned instance also under every joint's skinning transform (a skinned vertex is a weighted
  // mean of those transforms of itself, or stays in its bind pose when its weights vanish).
  void posedBounds(glm::vec3& lo, glm::vec3& hi) {
    lo = glm::vec3(std::numeric_limits<float>::max());
    hi = -lo;
    auto addBox = [&](const glm::vec3& bmin, const glm::vec3& bmax, const glm::mat4& m) {
      for (int i = 0; i < 8; ++i) {
        const glm::vec3 c(i & 1 ? bmax.x : bmin.x, i & 2 ? bmax.y : bmin.y,
                          i & 4 ? bmax.z : bmin.z);
        const glm::vec3 w = glm::vec3(m * glm::vec4(c, 1.0f));
        if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) continue;
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
    };
    for (size_t n = 0; n < pose.nodes.size(); ++n)
      for (int m : pose.nodes[n].meshes) {
        const Mesh& mesh = scene.meshes[m];
        glm::vec3 bmin = mesh.boundsMin, bmax = mesh.boundsMax;
        const std::vector<float>& weights = pose.nodes[n].morphWeights;
        for (size_t t = 0; t < mesh.morphTargets.size() && t < weights.size(); ++t) {
          // Per-axis worst case of w * delta over the target's vertices, added target by target.
          const float w = std::isfinite(weights[t]) ? weights[t] : 0.0f;
          const auto& [dmin, dmax] = morphDeltaBounds(m, t);
          bmin += glm::min(glm::vec3(0.0f), glm::min(w * dmin, w * dmax));
          bmax += glm::max(glm::vec3(0.0f), glm::max(w * dmin, w * dmax));
        }
        const glm::mat4& world = pose.nodes[n].world;
        addBox(bmin, bmax, world);
        // The joint matrices updateDeformations() just computed for this instance.
        const auto d = std::find_if(deformed.begin(), deformed.end(), [&](const Deformed& e) {
          return e.node == int(n) && e.mesh == m;
        });
        if (d != deformed.end())
          for (const glm::mat4& j : d->lastJoints) addBox(bmin, bmax, world * j);
      }
    if (lo.x > hi.x) {  // no geometry: a unit box keeps the shadow fit finite
      lo = glm::vec3(-1.0f);
      hi = glm::vec3(1.0f);
    }
  }

  // Plans the lights and shadow views of the current pose and camera and uploads them. When a
  // light starts or stops casting into the scene the layout changes and the graph is rebuilt.
  void updateLights() {
    glm::vec3 lo, hi;
    posedBounds(lo, hi);
    LightSetup next = planLights(scene, pose.nodes, cameraView, lo, hi, settings.shadowMapSize);
    if (!lightBuffer || !next.sameLayout(lightSetup)) {
      lightBuffer = Buffer(ctx, std::max<size_t>(next.lights.size(), 1) * sizeof(gpu::Light),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
      shadowViewBuffer =
          Buffer(ctx, std::max<size_t>(next.views.size(), 1) * sizeof(gpu::ShadowView),
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
      graphDirty = true;
    }
    if (!next.lights.empty())
      lightBuffer.write(next.lights.data(), next.lights.size() * sizeof(gpu::Light));
    if (!next.views.empty())
      shadowViewBuffer.write(next.views.data(), next.views.size() * sizeof(gpu::ShadowView));
    lightCount = uint32_t(next.lights.size());
    shadowMaps = next.maps;
    lightSetup = std::move(next);
    if (shadowPipelineReady) createShadowPipeline();
  }

  void createPipelines() {
    ctx.requireWorkgroup(256, 1, "skinning / surface points");  // local_size_x 256
    const auto ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
               tex = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
               img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    GraphicsDesc g;
    g.vertex = loadSpirv("gbuffer.vert");
    g.fragment = loadSpirv("gbuffer.frag");
    g.bindings = {{0, ubo}, {1, ssbo}, {2, ssbo}, {3, tex}};
    g.pushConstantBytes = sizeof(uint32_t);
    g.vertexLayout.stride = sizeof(Vertex);
    g.vertexLayout.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                 {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
                                 {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}};
    g.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8G8B8A8_SRGB,
                      VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16G16B16A16_SFLOAT,
                      VK_FORMAT_R16G16_SFLOAT};
    g.depthFormat = VK_FORMAT_D32_SFLOAT;
    gbufferPipeline = Pipeline::graphics(ctx, g);
    lightingPipeline = Pipeline::compute(ctx, loadSpirv("lighting.comp"),
                                         {{0, ubo},
                                          {1, tex},
                                          {2, tex},
                                          {3, tex},
                                          {4, tex},
                                          {5, tex},
                                          {6, ssbo},
                                          {7, img},
                                          {8, tex},
                                          {9, tex},
                                          {10, tex},
                                          {11, tex},
                                          {12, tex},
                                          {13, ssbo},
                                          {14, tex}});
    shadowPipelineReady = true;
    createShadowPipeline();
    tonemapPipeline =
        Pipeline::compute(ctx, loadSpirv("tonemap.comp"), {{0, ubo}, {1, tex}, {2, img}});
    floorPipeline = Pipeline::compute(ctx, loadSpirv("floor.comp"), {{0, ubo}, {1, tex}, {2, img}});
    if (!deformed.empty())
      skinningPipeline =
          Pipeline::compute(ctx, loadSpirv("skinning.comp"),
                            {{0, ssbo}, {1, ssbo}, {2, ssbo}, {3, ssbo}, {4, ssbo}}, 5 * 4);
  }

  // ---- animation --------------------------------------------------------------------------

  // Poses the nodes at `time`: instance matrices (previous ones kept for motion vectors), joint
  // matrices and morphed rest vertices; instances whose deformation changed are marked for
  // re-skinning.
  void setTime(double time) {
    pose.animate(time);
    for (size_t i = 0; i < instanceNodes.size(); ++i) {
      gpu::Instance& inst = instances[i];
      const glm::mat4& world = pose.nodes[instanceNodes[i]].world;
      inst.prevModel = inst.model;
      inst.model = world;
      inst.normalMatrix = normalMatrixOf(world);
    }
    instancesDirty = true;
    updateDeformations();
    // Animated cameras and lights: the camera of the last frame feeds the motion vectors.
    prevViewProj = cameraView.proj * cameraView.view;
    if (scene.activeCameraNode >= 0)
      cameraView = activeCamera(pose, float(settings.width) / float(settings.height));
    if (framesRendered == 0) {
      // No frame was seen before this pose: nothing moved (no motion from the load pose).
      prevViewProj = cameraView.proj * cameraView.view;
      for (gpu::Instance& inst : instances) inst.prevModel = inst.model;
    }
    updateLights();
  }

  void updateDeformations() {
    for (Deformed& d : deformed) {
      const Mesh& mesh = scene.meshes[d.mesh];
      if (d.jointCount > 0) {
        std::vector<glm::mat4> joints = jointMatrices(pose, d.node);
        if (joints != d.lastJoints) {
          jointBuffer.write(joints.data(), joints.size() * sizeof(glm::mat4),
                            size_t(d.jointFirst) * sizeof(glm::mat4));
          d.lastJoints = std::move(joints);
          d.dirty = true;
        }
      }
      if (!mesh.morphTargets.empty()) {
        const std::vector<float>& weights = pose.nodes[d.node].morphWeights;
        if (weights != d.lastWeights || d.lastWeights.empty()) {
          const std::vector<Vertex> morphed = morphVertices(mesh, weights);
          restBuffer.write(morphed.data(), morphed.size() * sizeof(Vertex),
                           size_t(d.srcFirst) * sizeof(Vertex));
          d.lastWeights = weights;
          d.dirty = true;
        }
      }
    }
  }

  // The "skinning" pass: rewrites the vertex-buffer regions of deformed instances whose joint
  // matrices or morph weights changed. Returns the vertex buffer's new version for readers.
  BufferHandle addSkinningPass(BufferHandle vertices) {
    auto io = std::make_shared<BufferHandle>();
    graph.addPass(
        "skinning", [&](PassBuilder& b) { *io = b.write(vertices, BufferUsage::StorageWrite); },
        [this](PassContext& pc) {
          DescriptorWriter w;
          w.buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, restBuffer.handle())
              .buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, jointIndexBuffer.handle())
              .buffer(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, jointWeightBuffer.handle())
              .buffer(3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, jointBuffer.handle())
              .buffer(4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, vertexBuffer.handle());
          bind(pc.cmd(), skinningPipeline, w);
          skinnedThisFrame = 0;
          for (Deformed& d : deformed) {
            if (!d.dirty) continue;
            const uint32_t push[5] = {d.srcFirst, d.dstFirst, d.count, d.jointFirst, d.jointCount};
            vkCmdPushConstants(pc.cmd(), skinningPipeline.layout(), VK_SHADER_STAGE_ALL, 0,
                               sizeof(push), push);
            vkCmdDispatch(pc.cmd(), (d.count + 255) / 256, 1, 1);  // local_size_x 256
            d.dirty = false;
            skinnedThisFrame += d.count;
          }
        });
    return *io;
  }

  // ---- the frame graph ------------------------------------------------------------------

  void buildGraph() {
    const auto start = std::chrono::steady_clock::now();
    graph.reset();
    Blackboard& bb = graph.blackboard();
    TextureDesc outDesc{VK_FORMAT_R8G8B8A8_UNORM};
    // GENERAL at the end of every frame: presenters and read-back expect it.
    outputHandle = graph.importTexture(res::kOutput, output.handle(), output.view(), outDesc,
                                       VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    BufferHandle vertices;
    if (!deformed.empty()) {
      vertices = graph.importBuffer(kVertices, vertexBuffer.handle(), vertexBuffer.size());
      vertices = addSkinningPass(vertices);
      bb.put(kVertices, vertices);
    }
    addGBufferPass(bb);
    if (surfacePoints)
      surfacePoints->addPasses(
          graph, vertices,
          {vertexBuffer.handle(), indexBuffer.handle(), instanceBuffer.handle(),
           frameBuffer.handle(), nearestClamp.handle()});
    addShadowPasses(bb);
    addEffects(EffectStage::BeforeLighting);
    addLightingPass(bb);
    addEffects(EffectStage::AfterLighting);
    addTonemapPass(bb);
    addFloorPass(bb);
    if (!bb.has(settings.view)) {
      std::string names;
      for (const std::string& n : bb.names()) names += (names.empty() ? "" : ", ") + n;
      throw Error(ErrorKind::Usage, "",
                  "unknown view '" + settings.view + "' (available: " + names + ")");
    }
    graph.markOutput(bb.texture(settings.view));
    if (settings.floorPass) graph.markOutput(bb.texture(res::kFloor));
    graph.compile();
    graphDirty = false;
    compileMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }

  void addEffects(EffectStage stage) {
    for (ActiveEffect& a : effects)
      if (a.info.stage == stage) a.effect->addPasses(graph, *this, a.settings);
  }

  void bind(VkCommandBuffer c, const Pipeline& p, DescriptorWriter& writer) {
    descriptors.bind(c, p, writer);
  }

  void addGBufferPass(Blackboard& bb) {
    struct Targets {
      TextureHandle depth, normal, albedo, material, emission, motion;
    };
    auto t = std::make_shared<Targets>();
    graph.addPass(
        "gbuffer",
        [&](PassBuilder& b) {
          if (BufferHandle v = bb.buffer(kVertices); v.valid()) b.read(v, BufferUsage::Vertex);
          t->depth = b.write(b.create(res::kDepth, outputRelative(VK_FORMAT_D32_SFLOAT)),
                             TextureUsage::DepthAttachment);
          t->normal = b.write(b.create(res::kNormal, outputRelative(VK_FORMAT_R16G16B16A16_SFLOAT)),
                              TextureUsage::ColorAttachment);
          t->albedo = b.write(b.create(res::kAlbedo, outputRelative(VK_FORMAT_R8G8B8A8_SRGB)),
                              TextureUsage::ColorAttachment);
          t->material = b.write(b.create(res::kMaterial, outputRelative(VK_FORMAT_R8G8B8A8_UNORM)),
                                TextureUsage::ColorAttachment);
          t->emission =
              b.write(b.create(res::kEmission, outputRelative(VK_FORMAT_R16G16B16A16_SFLOAT)),
                      TextureUsage::ColorAttachment);
          t->motion = b.write(b.create(res::kMotion, outputRelative(VK_FORMAT_R16G16_SFLOAT)),
                              TextureUsage::ColorAttachment);
        },
        [this, t](PassContext& pc) { recordGBuffer(pc, *t); });
    bb.put(res::kDepth, t->depth);
    bb.put(res::kNormal, t->normal);
    bb.put(res::kAlbedo, t->albedo);
    bb.put(res::kMaterial, t->material);
    bb.put(res::kEmission, t->emission);
    bb.put(res::kMotion, t->motion);
  }

  template <class Targets>
  void recordGBuffer(PassContext& pc, const Targets& t) {
    VkCommandBuffer c = pc.cmd();
    std::array<TextureHandle, 5> colors = {t.normal, t.albedo, t.material, t.emission, t.motion};
    std::array<VkRenderingAttachmentInfo, 5> attachments{};
    for (size_t i = 0; i < colors.size(); ++i) {
      attachments[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
      attachments[i].imageView = pc.view(colors[i]);
      attachments[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      attachments[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      attachments[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
    }
    VkRenderingAttachmentInfo depthAttachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depthAttachment.imageView = pc.view(t.depth);
    depthAttachment.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depthAttachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depthAttachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depthAttachment.clearValue.depthStencil = {0.0f, 0};  // reverse-Z: 0 is the far plane
    VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
    info.renderArea = {{0, 0}, {settings.width, settings.height}};
    info.layerCount = 1;
    info.colorAttachmentCount = uint32_t(attachments.size());
    info.pColorAttachments = attachments.data();
    info.pDepthAttachment = &depthAttachment;
    vkCmdBeginRendering(c, &info);
    vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferPipeline.handle());
    VkViewport viewport{0, 0, float(settings.width), float(settings.height), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, {settings.width, settings.height}};
    vkCmdSetViewport(c, 0, 1, &viewport);
    vkCmdSetScissor(c, 0, 1, &scissor);
    if (!draws.empty()) {
      VkDeviceSize offset = 0;
      VkBuffer vb = vertexBuffer.handle();
      vkCmdBindVertexBuffers(c, 0, 1, &vb, &offset);
      vkCmdBindIndexBuffer(c, indexBuffer.handle(), 0, VK_INDEX_TYPE_UINT32);
      uint32_t boundMaterial = UINT32_MAX;
      for (const Draw& d : draws) {
        if (d.material != boundMaterial) {
          bindMaterialSet(c, d.material);
          boundMaterial = d.material;
        }
        vkCmdPushConstants(c, gbufferPipeline.layout(), VK_SHADER_STAGE_ALL, 0, sizeof(uint32_t),
                           &d.instance);
        vkCmdDrawIndexed(c, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
      }
    }
    vkCmdEndRendering(c);
  }

  void bindMaterialSet(VkCommandBuffer c, uint32_t materialIndex) {
    const Material& m = sceneMaterials[materialIndex];
    const bool textured = m.baseColorTexture >= 0 && m.baseColorTexture < int(textures.size());
    VkDescriptorSet set = descriptors.allocate(gbufferPipeline.setLayout());
    DescriptorWriter()
        .buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
        .buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, instanceBuffer.handle())
        .buffer(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, materialBuffer.handle())
        .sampled(3, textured ? textures[m.baseColorTexture].view() : whiteTexture.view(),
                 linearRepeat.handle())
        .update(ctx.device(), set);
    vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferPipeline.layout(), 0, 1,
                            &set, 0, nullptr);
  }

  // One "shadow_<light index>" pass per shadowed light, writing "shadow_map_<slot>" (D32,
  // reverse-Z, cleared to 0 = nothing). Only lighting reads them: culled along with it.
  void addShadowPasses(Blackboard& bb) {
    for (uint32_t slot = 0; slot < shadowMaps.size(); ++slot) {
      const ShadowMap& map = shadowMaps[slot];
      TextureDesc desc{VK_FORMAT_D32_SFLOAT};
      desc.sizeClass = SizeClass::Absolute;
      desc.width = map.width;
      desc.height = map.height;
      auto io = std::make_shared<TextureHandle>();
      const std::string name = "shadow_map_" + std::to_string(slot);
      graph.addPass(
          "shadow_" + std::to_string(map.light),
          [&](PassBuilder& b) {
            if (BufferHandle v = bb.buffer(kVertices); v.valid()) b.read(v, BufferUsage::Vertex);
            *io = b.write(b.create(name, desc), TextureUsage::DepthAttachment);
          },
          [this, io, slot](PassContext& pc) { recordShadowMap(pc, *io, shadowMaps[slot]); });
      bb.put(name, *io);
    }
  }

  void recordShadowMap(PassContext& pc, TextureHandle target, const ShadowMap& map) {
    VkCommandBuffer c = pc.cmd();
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = pc.view(target);
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = {0.0f, 0};  // reverse-Z far plane: no occluder
    VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
    info.renderArea = {{0, 0}, {map.width, map.height}};
    info.layerCount = 1;
    info.pDepthAttachment = &depth;
    vkCmdBeginRendering(c, &info);
    DescriptorWriter w;
    w.buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, instanceBuffer.handle());
    bind(c, shadowPipeline, w);
    if (!draws.empty()) {
      VkDeviceSize offset = 0;
      VkBuffer vb = vertexBuffer.handle();
      vkCmdBindVertexBuffers(c, 0, 1, &vb, &offset);
      vkCmdBindIndexBuffer(c, indexBuffer.handle(), 0, VK_INDEX_TYPE_UINT32);
    }
    for (const ShadowMap::View& v : map.views) {
      VkViewport viewport{float(v.rect.offset.x),
                          float(v.rect.offset.y),
                          float(v.rect.extent.width),
                          float(v.rect.extent.height),
                          0.0f,
                          1.0f};
      vkCmdSetViewport(c, 0, 1, &viewport);
      vkCmdSetScissor(c, 0, 1, &v.rect);
      struct {
        glm::mat4 viewProj;
        uint32_t instance;
      } push{v.viewProj, 0};
      for (const Draw& d : draws) {
        push.instance = d.instance;
        vkCmdPushConstants(c, shadowPipeline.layout(), VK_SHADER_STAGE_ALL, 0,
                           sizeof(glm::mat4) + sizeof(uint32_t), &push);
        vkCmdDrawIndexed(c, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
      }
    }
    vkCmdEndRendering(c);
  }

  void addLightingPass(Blackboard& bb) {
    struct Io {
      TextureHandle depth, normal, albedo, material, emission, ao, lit;
      std::vector<TextureHandle> shadows;
    };
    auto io = std::make_shared<Io>();
    // Optional input: AO from whichever effect published it, else the neutral white texture.
    TextureHandle ao = bb.texture(res::kAO);
    if (!ao.valid())
      ao =
          graph.importTexture("ao_neutral", neutralAO.handle(), neutralAO.view(),
                              {VK_FORMAT_R8G8B8A8_UNORM}, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    graph.addPass(
        "lighting",
        [&](PassBuilder& b) {
          io->depth = b.read(bb.texture(res::kDepth));
          io->normal = b.read(bb.texture(res::kNormal));
          io->albedo = b.read(bb.texture(res::kAlbedo));
          io->material = b.read(bb.texture(res::kMaterial));
          io->emission = b.read(bb.texture(res::kEmission));
          io->ao = b.read(ao);
          for (uint32_t slot = 0; slot < shadowMaps.size(); ++slot)
            io->shadows.push_back(b.read(bb.texture("shadow_map_" + std::to_string(slot))));
          io->lit = b.write(b.create(res::kLit, outputRelative(VK_FORMAT_R16G16B16A16_SFLOAT)),
                            TextureUsage::StorageWrite);
        },
        [this, io](PassContext& pc) {
          DescriptorWriter w;
          w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
              .sampled(1, pc.view(io->depth), nearestClamp.handle())
              .sampled(2, pc.view(io->normal), nearestClamp.handle())
              .sampled(3, pc.view(io->albedo), nearestClamp.handle())
              .sampled(4, pc.view(io->material), nearestClamp.handle())
              .sampled(5, pc.view(io->emission), nearestClamp.handle())
              .buffer(6, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, lightBuffer.handle())
              .storageImage(7, pc.view(io->lit))
              .sampled(8, pc.view(io->ao), linearClamp.handle());
          for (uint32_t slot = 0; slot < kMaxShadowMaps; ++slot)
            w.sampled(9 + slot,
                      slot < io->shadows.size() ? pc.view(io->shadows[slot]) : neutralAO.view(),
                      nearestClamp.handle());
          w.buffer(13, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, shadowViewBuffer.handle())
              .sampled(14, environmentMap.handle() ? environmentMap.view() : neutralAO.view(),
                       linearRepeat.handle());
          bind(pc.cmd(), lightingPipeline, w);
          vkCmdDispatch(pc.cmd(), groups(settings.width), groups(settings.height), 1);
        });
    bb.put(res::kLit, io->lit);
  }

  void addTonemapPass(Blackboard& bb) {
    auto io = std::make_shared<std::pair<TextureHandle, TextureHandle>>();
    graph.addPass(
        "tonemap",
        [&](PassBuilder& b) {
          io->first = b.read(bb.texture(res::kLit));
          io->second = b.write(outputHandle, TextureUsage::StorageWrite);
        },
        [this, io](PassContext& pc) {
          DescriptorWriter w;
          w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
              .sampled(1, pc.view(io->first), nearestClamp.handle())
              .storageImage(2, pc.view(io->second));
          bind(pc.cmd(), tonemapPipeline, w);
          vkCmdDispatch(pc.cmd(), groups(settings.width), groups(settings.height), 1);
        });
    outputHandle = io->second;
    bb.put(res::kOutput, outputHandle);
  }

  void addFloorPass(Blackboard& bb) {
    auto io = std::make_shared<std::pair<TextureHandle, TextureHandle>>();
    graph.addPass(
        "floor",
        [&](PassBuilder& b) {
          io->first = b.read(bb.texture(res::kNormal));
          io->second = b.write(b.create(res::kFloor, outputRelative(VK_FORMAT_R8G8B8A8_UNORM)),
                               TextureUsage::StorageWrite);
        },
        [this, io](PassContext& pc) {
          DescriptorWriter w;
          w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
              .sampled(1, pc.view(io->first), nearestClamp.handle())
              .storageImage(2, pc.view(io->second));
          bind(pc.cmd(), floorPipeline, w);
          vkCmdDispatch(pc.cmd(), groups(settings.width), groups(settings.height), 1);
        });
    bb.put(res::kFloor, io->second);
  }

  // ---- frames ---------------------------------------------------------------------------

  void updateFrameUniforms() {
    gpu::FrameUniforms f{};
    const CameraView& c = cameraView;
    f.view = c.view;
    f.proj = c.proj;
    f.viewProj = c.proj * c.view;
    f.invView = glm::inverse(c.view);
    f.invProj = glm::inverse(c.proj);
    f.prevViewProj = prevViewProj;
    f.viewport =
        glm::vec4(settings.width, settings.height, 1.0f / settings.width, 1.0f / settings.height);
    f.cameraPos = glm::vec4(c.position, 1.0f);
    const Environment& e = scene.environment;
    const bool constant = e.kind == Environment::Kind::Constant;
    const float kind = constant ? 1.0f : environmentMap.handle() ? 2.0f : 0.0f;
    f.skyZenith = glm::vec4(e.zenithColor, std::max(e.intensity, 0.0f));
    f.skyHorizon = glm::vec4(e.horizonColor, kind);
    f.skyGround = glm::vec4(constant ? e.constantColor : e.groundColor, 0.0f);
    f.params = glm::vec4(settings.exposure, float(lightCount), c.znear, c.zfar);
    for (int i = 0; i < 9; ++i) f.irradianceSH[i] = glm::vec4(irradiance[i], 0.0f);
    frameBuffer.write(&f, sizeof f);
  }

  // Ends `c`, submits it and waits for it to complete.
  void submitAndWait(VkCommandBuffer c) {
    check(vkEndCommandBuffer(c), "vkEndCommandBuffer");
    VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cmdInfo.commandBuffer = c;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &cmdInfo;
    check(vkResetFences(ctx.device(), 1, &fence), "vkResetFences");
    check(vkQueueSubmit2(ctx.queue(), 1, &submit, fence), "vkQueueSubmit2");
    check(vkWaitForFences(ctx.device(), 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  }

  void renderFrame() {
    if (graphDirty) buildGraph();
    if (instancesDirty) {
      instanceBuffer.write(instances.data(), instances.size() * sizeof(gpu::Instance));
      instancesDirty = false;
    }
    updateFrameUniforms();
    descriptors.reset();
    check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    timer.beginFrame(cmd);
    FrameGraph::PassBoundary isolate;
    if (settings.isolatePasses)
      isolate = [this, &begin](VkCommandBuffer c) {
        submitAndWait(c);
        check(vkResetCommandBuffer(c, 0), "vkResetCommandBuffer");
        check(vkBeginCommandBuffer(c, &begin), "vkBeginCommandBuffer");
        return c;
      };
    graph.execute(cmd, descriptors, &timer, isolate);
    submitAndWait(cmd);
    timings.clear();
    for (auto& [name, ms] : timer.collect()) timings.push_back({name, ms});
    ++framesRendered;
  }

  void setEffectSettings(const std::string& name, const SettingValues& values) {
    for (ActiveEffect& a : effects) {
      if (a.info.name != name) continue;
      recompiledByLastChange = a.settings.graphDiffers(values);
      a.settings = values;
      if (recompiledByLastChange) {
        vkDeviceWaitIdle(ctx.device());
        graph.reset();  // the effect may replace pipelines the old graph's passes refer to
        a.effect->prepare(*this, a.settings);
        updateSurfacePoints();
        graphDirty = true;
      }
      return;
    }
    throw Error(ErrorKind::Usage, "", "effect '" + name + "' is not active in this renderer");
  }

  // ---- read-back ------------------------------------------------------------------------

  FrameGraph::TextureState stateOf(const std::string& name) {
    TextureHandle h = graph.blackboard().texture(name);
    if (!h.valid())
      throw Error(ErrorKind::Usage, "", "no resource named '" + name + "' in this frame");
    return graph.textureState(h);
  }

  // Copies a produced image into host memory (raw texels, tightly packed).
  std::vector<uint8_t> readRaw(const FrameGraph::TextureState& t) {
    if (t.layout == VK_IMAGE_LAYOUT_UNDEFINED)
      throw Error(ErrorKind::Usage, "", "target read before any frame wrote it");
    const bool depth = isDepthFormat(t.format);
    const VkImageAspectFlags aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    const size_t bytes = size_t(t.extent.width) * t.extent.height * formatBytesPerPixel(t.format);
    Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
    ctx.submitAndWait([&](VkCommandBuffer c) {
      imageBarrier(c, t.image, aspect, t.layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                   VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
      VkBufferImageCopy copy{};
      copy.imageSubresource = {aspect, 0, 0, 1};
      copy.imageExtent = {t.extent.width, t.extent.height, 1};
      vkCmdCopyImageToBuffer(c, t.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(), 1,
                             &copy);
      imageBarrier(c, t.image, aspect, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, t.layout,
                   VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0);
    });
    const auto* p = static_cast<const uint8_t*>(staging.mapped());
    return {p, p + bytes};
  }

  ImageRGBA32F readTarget(const std::string& name) {
    const FrameGraph::TextureState t = stateOf(name);
    std::vector<uint8_t> raw = readRaw(t);
    ImageRGBA32F img;
    img.width = int(t.extent.width);
    img.height = int(t.extent.height);
    const size_t n = size_t(t.extent.width) * t.extent.height;
    img.pixels.assign(n * 4, 0.0f);
    auto srgbToLinear = [](float c) {
      return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    };
    auto half = [&](size_t offset) {
      uint16_t h;
      std::memcpy(&h, &raw[offset], 2);
      return halfToFloat(h);
    };
    for (size_t i = 0; i < n; ++i) {
      float* o = &img.pixels[i * 4];
      switch (t.format) {
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_R32_SFLOAT:
          std::memcpy(&o[0], &raw[i * 4], 4);
          o[3] = 1.0f;
          break;
        case VK_FORMAT_R16G16B16A16_SFLOAT:
          for (int c = 0; c < 4; ++c) o[c] = half(i * 8 + c * 2);
          break;
        case VK_FORMAT_R16G16_SFLOAT:
          o[0] = half(i * 4);
          o[1] = half(i * 4 + 2);
          o[3] = 1.0f;
          break;
        case VK_FORMAT_R16_SFLOAT:
          o[0] = half(i * 2);
          o[3] = 1.0f;
          break;
        case VK_FORMAT_R8_UNORM:
          o[0] = raw[i] / 255.0f;
          o[3] = 1.0f;
          break;
        case VK_FORMAT_R8G8B8A8_SRGB:
          for (int c = 0; c < 4; ++c)
            o[c] = c < 3 ? srgbToLinear(raw[i * 4 + c] / 255.0f) : raw[i * 4 + c] / 255.0f;
          break;
        case VK_FORMAT_R8G8B8A8_UNORM:
          for (int c = 0; c < 4; ++c) o[c] = raw[i * 4 + c] / 255.0f;
          break;
        default:
          throw Error(ErrorKind::Unsupported, "",
                      "cannot read back '" + name + "': unsupported format");
      }
    }
    return img;
  }
};

Renderer::Renderer(Context& ctx, const Scene& scene, const RenderSettings& settings,
                   const EffectRegistry* registry)
    : impl_(std::make_unique<Impl>(ctx, scene, settings, registry)) {}
Renderer::~Renderer() = default;
void Renderer::renderFrame() {
  impl_->renderFrame();
}
void Renderer::setTime(double seconds) {
  impl_->setTime(seconds);
}
uint32_t Renderer::lastSkinnedVertexCount() const {
  return impl_->skinnedThisFrame;
}
std::vector<Renderer::DeformedMesh> Renderer::readDeformedMeshes() {
  Impl& m = *impl_;
  std::vector<DeformedMesh> out;
  if (m.deformed.empty()) return out;
  vk::Buffer staging(m.ctx, m.vertexBuffer.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  m.ctx.submitAndWait([&](VkCommandBuffer c) {
    VkBufferCopy copy{0, 0, m.vertexBuffer.size()};
    vkCmdCopyBuffer(c, m.vertexBuffer.handle(), staging.handle(), 1, &copy);
  });
  const auto* all = static_cast<const Vertex*>(staging.mapped());
  for (const Impl::Deformed& d : m.deformed)
    out.push_back({d.node, d.mesh, {all + d.dstFirst, all + d.dstFirst + d.count}});
  return out;
}
const SurfacePointSet& Renderer::surfacePoints() const {
  static const SurfacePointSet kNone;
  return impl_->surfacePoints ? impl_->surfacePoints->set() : kNone;
}
std::vector<SurfacePointSample> Renderer::readSurfacePoints() {
  if (!impl_->surfacePoints) return {};
  return impl_->surfacePoints->read(impl_->ctx);
}
const std::vector<PassTiming>& Renderer::lastTimings() const {
  return impl_->timings;
}
std::vector<std::string> Renderer::passNames() const {
  return impl_->graph.executedPasses();
}
std::vector<std::string> Renderer::culledPassNames() const {
  return impl_->graph.culledPasses();
}
std::string Renderer::graphDescription() const {
  return impl_->graph.describe();
}
std::string Renderer::graphDot() const {
  return impl_->graph.toDot();
}
double Renderer::lastCompileMs() const {
  return impl_->compileMs;
}
void Renderer::setEffectSettings(const std::string& effect, const SettingValues& values) {
  impl_->setEffectSettings(effect, values);
}
bool Renderer::graphRecompiledByLastChange() const {
  return impl_->recompiledByLastChange;
}
const CameraView& Renderer::camera() const {
  return impl_->cameraView;
}
ImageRGBA32F Renderer::readTarget(const std::string& name) {
  return impl_->readTarget(name);
}
std::vector<std::string> Renderer::viewNames() const {
  return impl_->graph.blackboard().names();
}
VkImage Renderer::outputImage() const {
  return impl_->output.handle();
}
VkExtent2D Renderer::outputExtent() const {
  return {impl_->settings.width, impl_->settings.height};
}

ImageRGBA8 Renderer::readOutput() {
  std::vector<uint8_t> raw = impl_->readRaw(impl_->stateOf(res::kOutput));
  return {int(impl_->settings.width), int(impl_->settings.height), std::move(raw)};
}

}  // namespace gi
