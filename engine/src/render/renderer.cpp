#include "gi/renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "gpu_types.h"

namespace gi {

using namespace gi::vk;

namespace {

constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

// A render target and the layout it was left in.
struct TargetImage {
  Image image;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

// Cofactor of the upper 3x3 (columns b x c, c x a, a x b), signed by the determinant: transforms
// normals like the inverse transpose but stays finite when the matrix is singular.
glm::mat4 normalMatrixOf(const glm::mat4& m) {
  glm::vec3 a(m[0]), b(m[1]), c(m[2]);
  glm::mat3 cof(glm::cross(b, c), glm::cross(c, a), glm::cross(a, b));
  float det = glm::dot(a, glm::cross(b, c));
  if (det < 0.0f) cof = -cof;
  return glm::mat4(cof);
}

uint32_t groups(uint32_t n) {
  return (n + 7) / 8;
}

}  // namespace

struct Renderer::Impl {
  Context& ctx;
  RenderSettings settings;
  const Scene& scene;
  CameraView cameraView;

  // Scene data on the GPU.
  Buffer vertexBuffer, indexBuffer, materialBuffer, instanceBuffer, lightBuffer, frameBuffer;
  struct Draw {
    uint32_t firstIndex, indexCount;
    int32_t vertexOffset;
    uint32_t instance, material;
  };
  std::vector<Draw> draws;
  std::vector<Material> sceneMaterials;
  std::vector<Image> textures;
  Image whiteTexture;
  Sampler linearSampler, nearestSampler;
  uint32_t lightCount = 0;

  // Targets.
  TargetImage depth, normal, albedo, material, emission, motion, lit, output, floorTarget;

  Pipeline gbufferPipeline, lightingPipeline, tonemapPipeline, floorPipeline;
  DescriptorArena descriptors;
  GpuTimer timer;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  std::vector<PassTiming> timings;
  std::vector<std::string> executed;

  Impl(Context& c, const Scene& s, const RenderSettings& rs)
      : ctx(c), settings(rs), scene(s), descriptors(c), timer(c) {
    if (settings.width == 0 || settings.height == 0 || settings.width > 16384 ||
        settings.height > 16384)
      throw Error(ErrorKind::Usage, "", "image size must be between 1x1 and 16384x16384");
    cameraView = activeCamera(scene, float(settings.width) / float(settings.height));
    uploadScene();
    createTargets();
    createPipelines();
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = ctx.commandPool();
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(ctx.device(), &alloc, &cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(ctx.device(), &fenceInfo, nullptr, &fence), "vkCreateFence");
  }

  ~Impl() {
    vkDeviceWaitIdle(ctx.device());
    vkDestroyFence(ctx.device(), fence, nullptr);
    vkFreeCommandBuffers(ctx.device(), ctx.commandPool(), 1, &cmd);
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
    vertexBuffer =
        createDeviceBuffer(ctx, vertices.data(), vertices.size() * sizeof(Vertex),
                           VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    indexBuffer =
        createDeviceBuffer(ctx, indices.data(), indices.size() * sizeof(uint32_t),
                           VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    std::vector<gpu::Instance> instances;
    for (const Node& node : scene.nodes) {
      for (int m : node.meshes) {
        const Mesh& mesh = scene.meshes[m];
        if (mesh.indices.empty()) continue;
        gpu::Instance inst;
        inst.model = inst.prevModel = node.world;
        inst.normalMatrix = normalMatrixOf(node.world);
        const uint32_t materialIndex =
            std::min<uint32_t>(mesh.material, uint32_t(sceneMaterials.size() - 1));
        inst.material = glm::uvec4(materialIndex, 0, 0, 0);
        draws.push_back({ranges[m].firstIndex, ranges[m].indexCount, ranges[m].vertexOffset,
                         uint32_t(instances.size()), materialIndex});
        instances.push_back(inst);
      }
    }
    // Grouped by material so each material's descriptor set is bound once.
    std::stable_sort(draws.begin(), draws.end(),
                     [](const Draw& a, const Draw& b) { return a.material < b.material; });
    if (instances.empty()) instances.emplace_back();  // keep the buffer non-empty
    instanceBuffer =
        createDeviceBuffer(ctx, instances.data(), instances.size() * sizeof(gpu::Instance),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

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

    for (const Texture& t : scene.textures) {
      bool valid = t.width > 0 && t.height > 0 && t.rgba8.size() == size_t(t.width) * t.height * 4;
      const uint8_t white[4] = {255, 255, 255, 255};
      ImageDesc desc;
      desc.format = VK_FORMAT_R8G8B8A8_SRGB;
      desc.width = valid ? uint32_t(t.width) : 1;
      desc.height = valid ? uint32_t(t.height) : 1;
      desc.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
      Image img(ctx, desc);
      uploadImage(ctx, img, valid ? t.rgba8.data() : white, valid ? t.rgba8.size() : 4);
      textures.push_back(std::move(img));
    }
    {  // bound for materials without a texture (the binding must always be valid)
      const uint8_t white[4] = {255, 255, 255, 255};
      ImageDesc desc;
      desc.format = VK_FORMAT_R8G8B8A8_SRGB;
      desc.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
      whiteTexture = Image(ctx, desc);
      uploadImage(ctx, whiteTexture, white, 4);
    }
    linearSampler = Sampler(ctx, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT);
    nearestSampler = Sampler(ctx, VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);

    std::vector<gpu::Light> lights;
    for (const Node& node : scene.nodes) {
      if (node.light < 0) continue;
      const Light& l = scene.lights[node.light];
      gpu::Light g{};
      glm::vec3 pos = glm::vec3(cameraView.view * node.world * glm::vec4(0, 0, 0, 1));
      glm::vec3 dir = glm::vec3(cameraView.view * node.world * glm::vec4(0, 0, -1, 0));
      float type = l.type == LightType::Directional ? 0.0f
                   : l.type == LightType::Point     ? 1.0f
                                                    : 2.0f;
      g.positionRange = glm::vec4(pos, std::max(l.range, 0.0f));
      g.directionType = glm::vec4(dir, type);
      g.radiance = glm::vec4(l.color * std::max(l.intensity, 0.0f), 0.0f);
      g.cone = glm::vec4(std::cos(l.innerConeAngle), std::cos(l.outerConeAngle), 0, 0);
      lights.push_back(g);
    }
    lightCount = uint32_t(lights.size());
    if (lights.empty()) lights.emplace_back();
    lightBuffer = createDeviceBuffer(ctx, lights.data(), lights.size() * sizeof(gpu::Light),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    frameBuffer = Buffer(ctx, sizeof(gpu::FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
  }

  TargetImage makeTarget(VkFormat format, VkImageUsageFlags usage) {
    ImageDesc d;
    d.format = format;
    d.width = settings.width;
    d.height = settings.height;
    d.usage = usage | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    return {Image(ctx, d), VK_IMAGE_LAYOUT_UNDEFINED};
  }

  void createTargets() {
    const VkImageUsageFlags color = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    depth = makeTarget(kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
    normal = makeTarget(VK_FORMAT_R16G16B16A16_SFLOAT, color);
    albedo = makeTarget(VK_FORMAT_R8G8B8A8_SRGB, color);
    material = makeTarget(VK_FORMAT_R8G8B8A8_UNORM, color);
    emission = makeTarget(VK_FORMAT_R16G16B16A16_SFLOAT, color);
    motion = makeTarget(VK_FORMAT_R16G16_SFLOAT, color);
    lit = makeTarget(VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT);
    output = makeTarget(VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT);
    floorTarget = makeTarget(VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT);
  }

  void createPipelines() {
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
    g.colorFormats = {normal.image.desc().format, albedo.image.desc().format,
                      material.image.desc().format, emission.image.desc().format,
                      motion.image.desc().format};
    g.depthFormat = kDepthFormat;
    gbufferPipeline = Pipeline::graphics(ctx, g);
    lightingPipeline = Pipeline::compute(
        ctx, loadSpirv("lighting.comp"),
        {{0, ubo}, {1, tex}, {2, tex}, {3, tex}, {4, tex}, {5, tex}, {6, ssbo}, {7, img}});
    tonemapPipeline =
        Pipeline::compute(ctx, loadSpirv("tonemap.comp"), {{0, ubo}, {1, tex}, {2, img}});
    floorPipeline = Pipeline::compute(ctx, loadSpirv("floor.comp"), {{0, ubo}, {1, tex}, {2, img}});
  }

  void updateFrameUniforms() {
    gpu::FrameUniforms f{};
    const CameraView& c = cameraView;
    f.view = c.view;
    f.proj = c.proj;
    f.viewProj = c.proj * c.view;
    f.invView = glm::inverse(c.view);
    f.invProj = glm::inverse(c.proj);
    f.prevViewProj = f.viewProj;  // static camera until animation exists
    f.viewport =
        glm::vec4(settings.width, settings.height, 1.0f / settings.width, 1.0f / settings.height);
    f.cameraPos = glm::vec4(c.position, 1.0f);
    const Environment& e = scene.environment;
    const bool constant = e.kind == Environment::Kind::Constant;
    f.skyZenith = glm::vec4(e.zenithColor, std::max(e.intensity, 0.0f));
    f.skyHorizon = glm::vec4(e.horizonColor, constant ? 1.0f : 0.0f);
    f.skyGround = glm::vec4(constant ? e.constantColor : e.groundColor, 0.0f);
    f.params = glm::vec4(settings.exposure, float(lightCount), c.znear, c.zfar);
    frameBuffer.write(&f, sizeof f);
  }

  // Moves a target to `layout` for the given use (all earlier work must be visible).
  void transition(TargetImage& t, VkImageLayout layout, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess) {
    imageBarrier(cmd, t.image.handle(), t.image.aspect(), t.layout, layout,
                 VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT, dstStage,
                 dstAccess);
    t.layout = layout;
  }

  void bind(const Pipeline& p, DescriptorWriter& writer) {
    VkDescriptorSet set = descriptors.allocate(p.setLayout());
    writer.update(ctx.device(), set);
    vkCmdBindPipeline(cmd, p.bindPoint(), p.handle());
    vkCmdBindDescriptorSets(cmd, p.bindPoint(), p.layout(), 0, 1, &set, 0, nullptr);
  }

  void bindMaterialSet(uint32_t materialIndex) {
    const Material& m = sceneMaterials[materialIndex];
    const bool textured = m.baseColorTexture >= 0 && m.baseColorTexture < int(textures.size());
    VkDescriptorSet set = descriptors.allocate(gbufferPipeline.setLayout());
    DescriptorWriter()
        .buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
        .buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, instanceBuffer.handle())
        .buffer(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, materialBuffer.handle())
        .sampled(3, textured ? textures[m.baseColorTexture].view() : whiteTexture.view(),
                 linearSampler.handle())
        .update(ctx.device(), set);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferPipeline.layout(), 0, 1,
                            &set, 0, nullptr);
  }

  void gbufferPass() {
    timer.begin(cmd, "gbuffer");
    const auto colorStage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
    const auto colorWrite = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
    std::array<TargetImage*, 5> colors = {&normal, &albedo, &material, &emission, &motion};
    for (TargetImage* t : colors) {
      t->layout = VK_IMAGE_LAYOUT_UNDEFINED;  // contents are rewritten every frame
      transition(*t, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, colorStage, colorWrite);
    }
    depth.layout = VK_IMAGE_LAYOUT_UNDEFINED;
    transition(
        depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
            VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);

    std::array<VkRenderingAttachmentInfo, 5> attachments{};
    for (size_t i = 0; i < colors.size(); ++i) {
      attachments[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
      attachments[i].imageView = colors[i]->image.view();
      attachments[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
      attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
      attachments[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      attachments[i].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
    }
    VkRenderingAttachmentInfo depthAttachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depthAttachment.imageView = depth.image.view();
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
    vkCmdBeginRendering(cmd, &info);

    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, gbufferPipeline.handle());
    VkViewport viewport{0, 0, float(settings.width), float(settings.height), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, {settings.width, settings.height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    if (!draws.empty()) {
      VkDeviceSize offset = 0;
      VkBuffer vb = vertexBuffer.handle();
      vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
      vkCmdBindIndexBuffer(cmd, indexBuffer.handle(), 0, VK_INDEX_TYPE_UINT32);
      uint32_t boundMaterial = UINT32_MAX;
      for (const Draw& d : draws) {
        if (d.material != boundMaterial) {
          bindMaterialSet(d.material);
          boundMaterial = d.material;
        }
        vkCmdPushConstants(cmd, gbufferPipeline.layout(), VK_SHADER_STAGE_ALL, 0, sizeof(uint32_t),
                           &d.instance);
        vkCmdDrawIndexed(cmd, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
      }
    }
    vkCmdEndRendering(cmd);
    timer.end(cmd);
    executed.push_back("gbuffer");
  }

  void readForCompute(TargetImage& t) {
    transition(t, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
               VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
  }
  void writeFromCompute(TargetImage& t) {
    t.layout = VK_IMAGE_LAYOUT_UNDEFINED;
    transition(t, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
               VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  }

  void lightingPass() {
    for (TargetImage* t : {&depth, &normal, &albedo, &material, &emission}) readForCompute(*t);
    writeFromCompute(lit);
    timer.begin(cmd, "lighting");
    DescriptorWriter w;
    w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
        .sampled(1, depth.image.view(), nearestSampler.handle())
        .sampled(2, normal.image.view(), nearestSampler.handle())
        .sampled(3, albedo.image.view(), nearestSampler.handle())
        .sampled(4, material.image.view(), nearestSampler.handle())
        .sampled(5, emission.image.view(), nearestSampler.handle())
        .buffer(6, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, lightBuffer.handle())
        .storageImage(7, lit.image.view());
    bind(lightingPipeline, w);
    vkCmdDispatch(cmd, groups(settings.width), groups(settings.height), 1);
    timer.end(cmd);
    executed.push_back("lighting");
  }

  void tonemapPass() {
    readForCompute(lit);
    writeFromCompute(output);
    timer.begin(cmd, "tonemap");
    DescriptorWriter w;
    w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
        .sampled(1, lit.image.view(), nearestSampler.handle())
        .storageImage(2, output.image.view());
    bind(tonemapPipeline, w);
    vkCmdDispatch(cmd, groups(settings.width), groups(settings.height), 1);
    timer.end(cmd);
    executed.push_back("tonemap");
  }

  void floorPass() {
    readForCompute(normal);
    writeFromCompute(floorTarget);
    timer.begin(cmd, "floor");
    DescriptorWriter w;
    w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frameBuffer.handle())
        .sampled(1, normal.image.view(), nearestSampler.handle())
        .storageImage(2, floorTarget.image.view());
    bind(floorPipeline, w);
    vkCmdDispatch(cmd, groups(settings.width), groups(settings.height), 1);
    timer.end(cmd);
    executed.push_back("floor");
  }

  void renderFrame() {
    updateFrameUniforms();
    descriptors.reset();
    executed.clear();
    check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    timer.beginFrame(cmd);
    gbufferPass();
    lightingPass();
    tonemapPass();
    if (settings.floorPass) floorPass();
    check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

    VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cmdInfo.commandBuffer = cmd;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &cmdInfo;
    check(vkResetFences(ctx.device(), 1, &fence), "vkResetFences");
    check(vkQueueSubmit2(ctx.queue(), 1, &submit, fence), "vkQueueSubmit2");
    check(vkWaitForFences(ctx.device(), 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    timings.clear();
    for (auto& [name, ms] : timer.collect()) timings.push_back({name, ms});
  }

  TargetImage& target(Target t) {
    switch (t) {
      case Target::Depth:
        return depth;
      case Target::Normal:
        return normal;
      case Target::Albedo:
        return albedo;
      case Target::Material:
        return material;
      case Target::Emission:
        return emission;
      case Target::Motion:
        return motion;
      case Target::Lit:
        return lit;
      case Target::Output:
        return output;
      case Target::Floor:
        return floorTarget;
    }
    return output;
  }

  // Copies a target into host memory (raw texels, tightly packed).
  std::vector<uint8_t> readRaw(TargetImage& t) {
    if (t.layout == VK_IMAGE_LAYOUT_UNDEFINED)
      throw Error(ErrorKind::Usage, "", "target read before any frame wrote it");
    const ImageDesc& d = t.image.desc();
    const size_t bytes = size_t(d.width) * d.height * formatBytesPerPixel(d.format);
    Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
    ctx.submitAndWait([&](VkCommandBuffer c) {
      imageBarrier(c, t.image.handle(), t.image.aspect(), t.layout,
                   VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                   VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                   VK_ACCESS_2_TRANSFER_READ_BIT);
      VkBufferImageCopy copy{};
      copy.imageSubresource = {t.image.aspect(), 0, 0, 1};
      copy.imageExtent = {d.width, d.height, 1};
      vkCmdCopyImageToBuffer(c, t.image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             staging.handle(), 1, &copy);
      imageBarrier(c, t.image.handle(), t.image.aspect(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                   t.layout, VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                   0);
    });
    const auto* p = static_cast<const uint8_t*>(staging.mapped());
    return {p, p + bytes};
  }

  ImageRGBA32F readTarget(Target which) {
    TargetImage& t = target(which);
    std::vector<uint8_t> raw = readRaw(t);
    const ImageDesc& d = t.image.desc();
    ImageRGBA32F img;
    img.width = int(d.width);
    img.height = int(d.height);
    const size_t n = size_t(d.width) * d.height;
    img.pixels.assign(n * 4, 0.0f);
    auto srgbToLinear = [](float c) {
      return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    };
    for (size_t i = 0; i < n; ++i) {
      float* o = &img.pixels[i * 4];
      switch (d.format) {
        case VK_FORMAT_D32_SFLOAT:
          std::memcpy(&o[0], &raw[i * 4], 4);
          o[3] = 1.0f;
          break;
        case VK_FORMAT_R16G16B16A16_SFLOAT:
          for (int c = 0; c < 4; ++c) {
            uint16_t h;
            std::memcpy(&h, &raw[i * 8 + c * 2], 2);
            o[c] = halfToFloat(h);
          }
          break;
        case VK_FORMAT_R16G16_SFLOAT:
          for (int c = 0; c < 2; ++c) {
            uint16_t h;
            std::memcpy(&h, &raw[i * 4 + c * 2], 2);
            o[c] = halfToFloat(h);
          }
          o[3] = 1.0f;
          break;
        case VK_FORMAT_R8G8B8A8_SRGB:
          for (int c = 0; c < 4; ++c)
            o[c] = c < 3 ? srgbToLinear(raw[i * 4 + c] / 255.0f) : raw[i * 4 + c] / 255.0f;
          break;
        default:  // 8-bit UNORM
          for (int c = 0; c < 4; ++c) o[c] = raw[i * 4 + c] / 255.0f;
      }
    }
    return img;
  }
};

Renderer::Renderer(Context& ctx, const Scene& scene, const RenderSettings& settings)
    : impl_(std::make_unique<Impl>(ctx, scene, settings)) {}
Renderer::~Renderer() = default;
void Renderer::renderFrame() {
  impl_->renderFrame();
}
const std::vector<PassTiming>& Renderer::lastTimings() const {
  return impl_->timings;
}
std::vector<std::string> Renderer::passNames() const {
  return impl_->executed;
}
const CameraView& Renderer::camera() const {
  return impl_->cameraView;
}
ImageRGBA32F Renderer::readTarget(Target target) {
  return impl_->readTarget(target);
}
VkImage Renderer::outputImage() const {
  return impl_->output.image.handle();
}
VkExtent2D Renderer::outputExtent() const {
  return {impl_->settings.width, impl_->settings.height};
}

ImageRGBA8 Renderer::readOutput() {
  std::vector<uint8_t> raw = impl_->readRaw(impl_->output);
  return {int(impl_->settings.width), int(impl_->settings.height), std::move(raw)};
}

}  // namespace gi
