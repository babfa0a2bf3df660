// Shaders (SPIR-V built at build time, or GLSL compiled at run time), descriptor layouts,
// per-frame descriptor pools and compute/graphics pipelines (created through the disk cache).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include "gi/vk/context.h"

namespace gi::vk {

// Folder holding the build-time SPIR-V: $GI_SHADER_DIR, else <executable dir>/shaders.
std::string shaderDirectory();
// Loads <shaderDirectory()>/<name>.spv (e.g. "lighting.comp"); throws gi::Error if missing.
std::vector<uint32_t> loadSpirv(const std::string& name);
// Compiles GLSL at run time (glslang library); errors name the source and carry the compiler log.
std::vector<uint32_t> compileGlsl(const std::string& source, VkShaderStageFlagBits stage,
                                  const std::string& sourceName,
                                  const std::vector<std::string>& includeDirs = {});
std::vector<uint32_t> compileGlslFile(const std::string& path,
                                      const std::vector<std::string>& includeDirs = {});

struct Binding {
  uint32_t binding;
  VkDescriptorType type;
  uint32_t count = 1;
  VkShaderStageFlags stages = VK_SHADER_STAGE_ALL;
};

struct VertexLayout {
  uint32_t stride = 0;
  std::vector<VkVertexInputAttributeDescription> attributes;
};

struct GraphicsDesc {
  std::vector<uint32_t> vertex, fragment;
  std::vector<Binding> bindings;
  uint32_t pushConstantBytes = 0;
  VertexLayout vertexLayout;
  std::vector<VkFormat> colorFormats;
  VkFormat depthFormat = VK_FORMAT_UNDEFINED;
  VkCompareOp depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;  // reverse-Z
  bool depthWrite = true;
  VkCullModeFlags cullMode = VK_CULL_MODE_NONE;
};

// One pipeline with its single descriptor-set layout (set 0) and push-constant range.
class Pipeline {
 public:
  Pipeline() = default;
  // `specialization[i]` is the 32-bit value of the shader's `layout(constant_id = i)` constant:
  // the driver folds the branches it decides before compiling (on llvmpipe an `if` costs its
  // whole body even when no pixel takes it, so settings known at build time belong there).
  static Pipeline compute(Context& ctx, const std::vector<uint32_t>& spirv,
                          const std::vector<Binding>& bindings, uint32_t pushConstantBytes = 0,
                          const std::vector<uint32_t>& specialization = {});
  static Pipeline graphics(Context& ctx, const GraphicsDesc& desc);
  ~Pipeline() { reset(); }
  Pipeline(Pipeline&& o) noexcept { *this = std::move(o); }
  Pipeline& operator=(Pipeline&& o) noexcept;
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  VkPipeline handle() const { return pipeline_; }
  VkPipelineLayout layout() const { return layout_; }
  VkDescriptorSetLayout setLayout() const { return setLayout_; }
  VkPipelineBindPoint bindPoint() const { return bindPoint_; }
  void reset();

 private:
  void createLayout(const std::vector<Binding>& bindings, uint32_t pushConstantBytes);
  Context* ctx_ = nullptr;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkPipelineBindPoint bindPoint_ = VK_PIPELINE_BIND_POINT_COMPUTE;
};

// Descriptor sets that live for one frame: allocate freely, reset() when the frame is done.
// Grows by adding pools, so callers never size it.
class DescriptorWriter;

class DescriptorArena {
 public:
  explicit DescriptorArena(Context& ctx) : ctx_(&ctx) {}
  ~DescriptorArena();
  DescriptorArena(const DescriptorArena&) = delete;
  DescriptorArena& operator=(const DescriptorArena&) = delete;
  VkDescriptorSet allocate(VkDescriptorSetLayout layout);
  // Allocates a set for `p`, applies `writer` to it and binds the pipeline and the set.
  void bind(VkCommandBuffer cmd, const Pipeline& p, DescriptorWriter& writer);
  void reset();

 private:
  VkDescriptorPool newPool();
  Context* ctx_;
  std::vector<VkDescriptorPool> pools_;
  size_t current_ = 0;
};

// Collects descriptor writes for one set, then applies them in one call.
class DescriptorWriter {
 public:
  DescriptorWriter& sampled(uint32_t binding, VkImageView view, VkSampler sampler,
                            VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                            uint32_t arrayElement = 0);
  DescriptorWriter& storageImage(uint32_t binding, VkImageView view);
  DescriptorWriter& buffer(uint32_t binding, VkDescriptorType type, VkBuffer buffer,
                           VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE);
  void update(VkDevice device, VkDescriptorSet set);

 private:
  struct Pending {
    uint32_t binding, element;
    VkDescriptorType type;
    size_t info;  // index into images_ or buffers_
  };
  std::vector<Pending> pending_;
  std::vector<VkDescriptorImageInfo> images_;
  std::vector<VkDescriptorBufferInfo> buffers_;
};

}  // namespace gi::vk
