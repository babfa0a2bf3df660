// Shaders (SPIR-V built at build time, or GLSL compiled at run time), descriptor layouts,
// per-frame descriptor pools and compute/graphics pipelines (created through the disk cache).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gi/vk/context.h"
#include "gi/vk/shader_interface.h"

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

// C++ structs that mirror a shader's blocks, checked against its reflected layout when the
// pipeline is made (checkBlockLayout): the push constants and uniform blocks by binding name.
struct BlockChecks {
  std::optional<CppBlock> pushConstants;  // required when the shader has push constants
  std::vector<std::pair<std::string, CppBlock>> uniforms;
};

// A compute pipeline whose descriptor layout and push-constant range are read from its SPIR-V.
struct ComputeDesc {
  std::string name;  // names the pipeline in errors, e.g. "ssao: ssao.comp"
  std::vector<uint32_t> spirv;
  std::vector<uint32_t> specialization;  // `layout(constant_id = i)` values
  BlockChecks blocks;
};

struct GraphicsDesc {
  std::vector<uint32_t> vertex, fragment;
  // With a name, the descriptor layout and push-constant range come from the shaders'
  // reflection and `blocks` is checked (leave bindings and pushConstantBytes empty).
  std::string name;
  BlockChecks blocks;
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
  // Bindings and push-constant range from the shader's own reflection; `desc.blocks` checked.
  static Pipeline compute(Context& ctx, const ComputeDesc& desc);
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
  // What the shaders declare (reflected from the SPIR-V the pipeline was built from).
  const ShaderInterface& shaderInterface() const { return interface_; }
  const std::string& name() const { return name_; }
  // Pushes `value` as the shader's push constants. With a declared CppBlock, T must be that
  // struct (its size is checked); the bytes beyond the shader's block (padding) are not sent.
  template <class T>
  void push(VkCommandBuffer cmd, const T& value) const {
    pushBytes(cmd, &value, sizeof(T));
  }
  void pushBytes(VkCommandBuffer cmd, const void* data, size_t size) const;
  void reset();
  // The guard counters (gi/vk/guard_counters.h) a compute shader declares, which every
  // descriptor set made for it binds: binding -1 when it declares none.
  struct GuardBinding {
    int binding = -1;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0, range = 0;
  };
  const GuardBinding& guardBinding() const { return guards_; }

 private:
  void createLayout(const std::vector<Binding>& bindings, uint32_t pushConstantBytes);
  void useReflection(const std::string& name, ShaderInterface iface, const BlockChecks& blocks);
  Context* ctx_ = nullptr;
  ShaderInterface interface_;
  std::string name_;
  size_t cppPushSize_ = 0;  // sizeof the declared push-constant struct (0: none declared)
  uint32_t pushRange_ = 0;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkPipelineBindPoint bindPoint_ = VK_PIPELINE_BIND_POINT_COMPUTE;
  GuardBinding guards_;
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

// Collects descriptor writes for one set, then applies them in one call. Made for a pipeline,
// it binds by the names its shader uses (the descriptor type follows from the shader) and
// update() fails naming any binding left unwritten.
class DescriptorWriter {
 public:
  DescriptorWriter() = default;
  explicit DescriptorWriter(const Pipeline& pipeline);
  // A sampled texture (sampler2D ...), element `element` of an array.
  DescriptorWriter& texture(std::string_view name, VkImageView view, VkSampler sampler,
                            VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                            uint32_t element = 0);
  DescriptorWriter& image(std::string_view name, VkImageView view, uint32_t element = 0);
  // A uniform or storage buffer (the shader says which).
  DescriptorWriter& buffer(std::string_view name, VkBuffer buffer, VkDeviceSize offset = 0,
                           VkDeviceSize range = VK_WHOLE_SIZE);

  DescriptorWriter& sampled(uint32_t binding, VkImageView view, VkSampler sampler,
                            VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                            uint32_t arrayElement = 0);
  DescriptorWriter& storageImage(uint32_t binding, VkImageView view);
  DescriptorWriter& buffer(uint32_t binding, VkDescriptorType type, VkBuffer buffer,
                           VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE);
  void update(VkDevice device, VkDescriptorSet set);

 private:
  const ShaderBinding* named(std::string_view name, VkDescriptorType expected,
                             const char* call) const;
  const Pipeline* pipeline_ = nullptr;
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
