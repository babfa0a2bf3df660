// The engine's implementation of gi::GpuScene: uploads the scene, keeps the animated pose
// (instance matrices, joint matrices, morphed rest vertices) and records draws of it from any
// view. The skinning pass (passes/skinning_pass.cpp) deforms the vertices it owns.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "gi/gpu_scene.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "render/surface_points_pass.h"

namespace gi {

// Frame-graph name of the shared vertex buffer once deformed meshes are written into it.
inline constexpr const char* kVerticesResource = "vertices";

class SceneGpu final : public GpuScene {
 public:
  SceneGpu(vk::Context& ctx, const Scene& scene);
  ~SceneGpu() override;

  // GpuScene
  VkBuffer vertices() const override { return vertexBuffer_.handle(); }
  VkBuffer indices() const override { return indexBuffer_.handle(); }
  VkBuffer instances() const override { return instanceBuffer_.handle(); }
  VkBuffer materials() const override { return materialBuffer_.handle(); }
  const std::vector<SceneDrawItem>& drawItems() const override { return draws_; }
  uint64_t triangleCount() const override;
  void bounds(glm::vec3& lo, glm::vec3& hi) const override;
  void declareRead(PassBuilder& builder, BufferUsage usage) const override;
  void drawDepth(PassContext& pc, const SceneTargets& targets,
                 std::span<const SceneView> views) override;
  void drawDepthFromBuffer(PassContext& pc, const SceneTargets& targets, VkBuffer views,
                           std::span<const VkRect2D> viewports) override;
  void drawGBuffer(PassContext& pc, const SceneTargets& targets, VkBuffer viewUniforms,
                   const glm::mat4* cullWorldToClip = nullptr) override;
  void drawRsm(PassContext& pc, const SceneTargets& targets, const SceneView& view,
               const LightInfo& light) override;
  void drawDepthPeeled(PassContext& pc, const SceneTargets& targets,
                       std::span<const SceneView> views, VkImageView previous) override;

  // The deformed vertices' current version in the graph being built (invalid: no skinning
  // pass), which declareRead() makes passes read.
  void setVertices(BufferHandle h) { vertices_ = h; }
  BufferHandle currentVertices() const { return vertices_; }
  // Start of a frame: previous model matrices = the last rendered frame's, uploads changed
  // instance matrices, recycles the per-view uniform slots.
  void beginFrame();
  // Poses the scene at `seconds` (instance matrices, joints, morphed rest vertices).
  void setTime(double seconds);
  const Scene& pose() const { return pose_; }
  // Bumped whenever the posed geometry changes (an instance matrix or a deformed mesh's joints
  // or morph weights): work derived from it (the surface points) is redone only then.
  const uint64_t* poseVersion() const { return &poseVersion_; }
  const Scene& source() const { return scene_; }
  // Frustum culling of the draws (on by default; off draws every instance into every view).
  void setCulling(bool on) { culling_ = on; }
  // Instance draws recorded and skipped by culling since the last beginFrame().
  struct DrawCounts {
    uint64_t drawn = 0, culled = 0;
  };
  DrawCounts drawCounts() const { return counts_; }

  // Which instances may change from frame to frame (for caches of what the others look like,
  // e.g. shadow maps of static casters). Skinned and morphed instances are dynamic from the
  // start; any other instance becomes dynamic the first time its matrix changes and stays so.
  // That change bumps staticVersion(): whatever was drawn of the static instances before is
  // out of date in the same frame.
  bool isDynamic(uint32_t instance) const { return dynamic_[instance] != 0; }
  uint64_t staticVersion() const { return staticVersion_; }
  using Box = std::pair<glm::vec3, glm::vec3>;
  // World boxes of the dynamic instances in the current pose (recomputed when it changes).
  const std::vector<Box>& dynamicBoxes();
  // drawDepth restricted to the static or the dynamic instances (targets.clear as given).
  enum class Subset { All, Static, Dynamic };
  void drawDepth(PassContext& pc, const SceneTargets& targets, std::span<const SceneView> views,
                 Subset subset);

  // Skinned/morphed mesh instances: each owns a copy of its mesh's vertices in the vertex
  // buffer, rewritten by the skinning pass from its rest vertices.
  struct Deformed {
    int node = 0, mesh = 0;
    uint32_t srcFirst = 0, dstFirst = 0, count = 0, jointFirst = 0, jointCount = 0;
    std::vector<glm::mat4> lastJoints;
    std::vector<float> lastWeights;
    bool dirty = true;
  };
  std::vector<Deformed>& deformed() { return deformed_; }
  const vk::Buffer& restBuffer() const { return restBuffer_; }
  const vk::Buffer& jointIndexBuffer() const { return jointIndexBuffer_; }
  const vk::Buffer& jointWeightBuffer() const { return jointWeightBuffer_; }
  const vk::Buffer& jointBuffer() const { return jointBuffer_; }
  const vk::Buffer& vertexBuffer() const { return vertexBuffer_; }
  const std::vector<SurfacePointsPass::InstanceRef>& instanceRefs() const { return instanceRefs_; }
  VkSampler linearRepeat() const { return linearRepeat_.handle(); }

 private:
  void upload();
  void updateDeformations();
  void createPipelines();
  const std::pair<glm::vec3, glm::vec3>& morphDeltaBounds(int mesh, size_t target) const;
  // World box of `mesh` at `node` in the current pose (morph targets and joints included).
  Box instanceBox(size_t node, int mesh) const;
  // Each instance's box, recomputed when the pose changed.
  const std::vector<Box>& instanceBoxes();
  // Whether draw `d` is to be recorded for a view with this world -> clip matrix (null: all).
  bool inView(const SceneDrawItem& d, const glm::mat4* worldToClip);
  VkDescriptorBufferInfo viewSlot(const SceneView& view, const LightInfo* light, VkExtent2D extent);
  void bindMaterial(PassContext& pc, const vk::Pipeline& p, uint32_t material, VkBuffer uniforms,
                    VkDeviceSize offset, VkDeviceSize range);
  void beginRendering(PassContext& pc, const SceneTargets& t, size_t colorCount);
  void bindGeometry(VkCommandBuffer cmd);
  static void setViewport(VkCommandBuffer cmd, const SceneView& view, VkExtent2D extent);
  void pushDraw(VkCommandBuffer cmd, const vk::Pipeline& p, const SceneDrawItem& d,
                bool modelOnly) const;

  vk::Context& ctx_;
  const Scene& scene_;
  Scene pose_;  // the renderer's own copy of the node hierarchy, posed by setTime()
  BufferHandle vertices_;
  vk::Buffer vertexBuffer_, indexBuffer_, materialBuffer_, instanceBuffer_;
  vk::Buffer materialUniforms_;  // per-material uniform slots of the G-buffer and RSM draws
  vk::Buffer restBuffer_, jointIndexBuffer_, jointWeightBuffer_, jointBuffer_;
  std::vector<SceneDrawItem> draws_;
  std::vector<int> instanceNodes_;  // node of each GpuInstance
  std::vector<GpuInstance> instances_;
  std::vector<glm::mat4> rendered_;  // model matrices of the last rendered frame
  std::vector<uint8_t> dynamic_;     // per instance: see isDynamic()
  uint64_t staticVersion_ = 1;
  bool instancesDirty_ = true;
  uint64_t poseVersion_ = 1;
  std::vector<Deformed> deformed_;
  std::vector<SurfacePointsPass::InstanceRef> instanceRefs_;
  std::vector<Material> materials_;
  std::vector<vk::Image> textures_;
  vk::Image whiteTexture_;
  vk::Sampler linearRepeat_;
  mutable std::map<int, std::vector<std::pair<glm::vec3, glm::vec3>>> morphBounds_;
  vk::Pipeline gbufferPipeline_, depthPipeline_, peelPipeline_, rsmPipeline_;
  vk::Sampler nearestClamp_;  // the peeled layer's previous depth (texelFetch)
  // Per-view uniform slots of drawDepth/drawRsm, host-visible, recycled every frame.
  std::vector<vk::Buffer> viewChunks_;
  size_t viewSlotsUsed_ = 0;
  bool culling_ = true;
  std::vector<Box> instanceBoxes_, dynamicBoxes_;
  uint64_t boxesVersion_ = 0, dynamicBoxesVersion_ = 0;
  DrawCounts counts_;
};

}  // namespace gi
