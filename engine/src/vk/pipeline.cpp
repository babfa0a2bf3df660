#include "gi/vk/pipeline.h"

#include <algorithm>
#include <utility>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/guard_counters.h"
#include "gi/vk/shader_overrides.h"

namespace gi::vk {

namespace {

// guards.glsl's counter block and specialization constant.
constexpr const char* kGuardBlock = "GiGuardCounters";
constexpr const char* kGuardConstant = "giCountGuards";
// `code` is what resolveShader returned: a hot-reloaded override of a registered effect shader,
// or the shader itself.
VkShaderModule createModule(VkDevice device, const std::vector<uint32_t>& code) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = code.size() * 4;
  info.pCode = code.data();
  VkShaderModule module;
  check(vkCreateShaderModule(device, &info, nullptr, &module), "vkCreateShaderModule");
  return module;
}
}  // namespace

void Pipeline::createLayout(const std::vector<Binding>& bindings, uint32_t pushConstantBytes) {
  std::vector<VkDescriptorSetLayoutBinding> vkBindings;
  for (const Binding& b : bindings)
    vkBindings.push_back({b.binding, b.type, b.count, b.stages, nullptr});
  VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  setInfo.bindingCount = static_cast<uint32_t>(vkBindings.size());
  setInfo.pBindings = vkBindings.data();
  check(vkCreateDescriptorSetLayout(ctx_->device(), &setInfo, nullptr, &setLayout_),
        "vkCreateDescriptorSetLayout");
  VkPushConstantRange range{VK_SHADER_STAGE_ALL, 0, pushConstantBytes};
  VkPipelineLayoutCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  info.setLayoutCount = 1;
  info.pSetLayouts = &setLayout_;
  info.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
  info.pPushConstantRanges = &range;
  check(vkCreatePipelineLayout(ctx_->device(), &info, nullptr, &layout_), "vkCreatePipelineLayout");
  pushRange_ = pushConstantBytes;
}

// A layout from the shader's reflection; the declared C++ blocks are checked against it first,
// so a mismatch fails before anything is created.
void Pipeline::useReflection(const std::string& name, ShaderInterface iface,
                             const BlockChecks& blocks) {
  name_ = name;
  interface_ = std::move(iface);
  const BlockLayout& push = interface_.pushConstants;
  if (push.size && !blocks.pushConstants)
    throw Error(ErrorKind::ShaderInterface, "",
                name + ": the shader has push constants (block '" + push.name +
                    "'); declare the C++ struct that mirrors it (BlockChecks::pushConstants)");
  if (blocks.pushConstants) {
    if (!push.size)
      throw Error(ErrorKind::ShaderInterface, "",
                  name + ": C++ push constants " + blocks.pushConstants->type +
                      " are declared but the shader has none");
    checkBlockLayout(push, *blocks.pushConstants, name);
    cppPushSize_ = blocks.pushConstants->size;
  }
  for (const auto& [bindingName, cpp] : blocks.uniforms) {
    const ShaderBinding* b = interface_.find(bindingName);
    if (!b || b->block.members.empty())
      throw Error(ErrorKind::ShaderInterface, "",
                  name + ": no uniform or storage block '" + bindingName + "' in the shader (" +
                      interface_.describe() + ")");
    checkBlockLayout(b->block, cpp, name);
  }
  std::vector<Binding> bindings;
  for (const ShaderBinding& b : interface_.bindings)
    if (interface_.bound(b)) bindings.push_back({b.binding, b.type, b.count, VK_SHADER_STAGE_ALL});
  createLayout(bindings, push.size);
}

void Pipeline::pushBytes(VkCommandBuffer cmd, const void* data, size_t size) const {
  if (pushRange_ == 0)
    throw Error(ErrorKind::ShaderInterface, "", name_ + ": the shader has no push constants");
  if (cppPushSize_ && size != cppPushSize_)
    throw Error(ErrorKind::ShaderInterface, "",
                name_ + ": pushed " + std::to_string(size) +
                    " bytes of push constants, but the declared C++ struct is " +
                    std::to_string(cppPushSize_));
  if (size < pushRange_)
    throw Error(ErrorKind::ShaderInterface, "",
                name_ + ": pushed " + std::to_string(size) + " bytes, the shader's block is " +
                    std::to_string(pushRange_));
  vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_ALL, 0, pushRange_, data);
}

namespace {
// The explicit bindings a pipeline is given must cover what its shader declares.
void checkExplicitBindings(const std::vector<Binding>& given, const ShaderInterface& shader) {
  for (const ShaderBinding& s : shader.bindings) {
    if (!s.active) continue;  // unused: the explicit layout may leave it out
    auto g = std::find_if(given.begin(), given.end(),
                          [&](const Binding& b) { return b.binding == s.binding; });
    if (g == given.end())
      throw Error(ErrorKind::ShaderInterface, "",
                  "shader " + shader.shader + ": binding " + std::to_string(s.binding) + " ('" +
                      s.name + "') is missing from the pipeline's bindings");
    if (g->type != s.type || g->count < s.count)
      throw Error(ErrorKind::ShaderInterface, "",
                  "shader " + shader.shader + ": binding " + std::to_string(s.binding) + " ('" +
                      s.name + "') is a " + descriptorTypeName(s.type) + " of " +
                      std::to_string(s.count) + ", the pipeline declares a " +
                      descriptorTypeName(g->type) + " of " + std::to_string(g->count));
  }
}

VkComputePipelineCreateInfo computeInfo(VkShaderModule module, VkPipelineLayout layout,
                                        const VkSpecializationInfo* spec) {
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = spec;
  info.layout = layout;
  return info;
}

// `specialization` gives constant_id 0, 1, ...; `extra` more (id, value) pairs.
VkPipeline createCompute(Context& ctx, const std::vector<uint32_t>& code, VkPipelineLayout layout,
                         const std::vector<uint32_t>& specialization,
                         const std::vector<std::pair<uint32_t, uint32_t>>& extra = {}) {
  VkShaderModule module = createModule(ctx.device(), code);
  std::vector<VkSpecializationMapEntry> entries;
  std::vector<uint32_t> values = specialization;
  for (uint32_t i = 0; i < specialization.size(); ++i)
    entries.push_back({i, i * uint32_t(sizeof(uint32_t)), sizeof(uint32_t)});
  for (const auto& [id, value] : extra) {
    if (id < specialization.size()) {  // a positional list that already reaches it (by name)
      values[id] = value;
      continue;
    }
    entries.push_back({id, uint32_t(values.size() * sizeof(uint32_t)), sizeof(uint32_t)});
    values.push_back(value);
  }
  const VkSpecializationInfo spec{uint32_t(entries.size()), entries.data(),
                                  values.size() * sizeof(uint32_t), values.data()};
  const VkComputePipelineCreateInfo info =
      computeInfo(module, layout, entries.empty() ? nullptr : &spec);
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkResult r =
      vkCreateComputePipelines(ctx.device(), ctx.pipelineCache(), 1, &info, nullptr, &pipeline);
  vkDestroyShaderModule(ctx.device(), module, nullptr);
  check(r, "vkCreateComputePipelines");
  return pipeline;
}
}  // namespace

Pipeline Pipeline::compute(Context& ctx, const ComputeDesc& d) {
  Pipeline p;
  p.ctx_ = &ctx;
  p.bindPoint_ = VK_PIPELINE_BIND_POINT_COMPUTE;
  const std::vector<uint32_t> code = resolveShader(d.spirv);
  p.useReflection(d.name, reflectShader(code, VK_SHADER_STAGE_COMPUTE_BIT, d.name), d.blocks);
  // Guard counting (guards.glsl): the counters bound for this pipeline's name, and counting
  // compiled in while the context counts.
  std::vector<std::pair<uint32_t, uint32_t>> extra;
  if (const ShaderBinding* g = p.interface_.find(kGuardBlock); g && p.interface_.bound(*g)) {
    const GuardCounters::Slot slot = ctx.guards().slot(p.name_);
    p.guards_ = {int(g->binding), slot.buffer, slot.offset, slot.range};
    for (const SpecializationConstant& c : reflectSpecializationConstants(code, p.name_))
      if (c.name == kGuardConstant && extra.empty())
        extra.push_back({c.id, ctx.guards().enabled() ? 1u : 0u});
  }
  p.pipeline_ = createCompute(ctx, code, p.layout_, d.specialization, extra);
  return p;
}

Pipeline Pipeline::compute(Context& ctx, const std::vector<uint32_t>& spirv,
                           const std::vector<Binding>& bindings, uint32_t pushConstantBytes,
                           const std::vector<uint32_t>& specialization) {
  Pipeline p;
  p.ctx_ = &ctx;
  p.bindPoint_ = VK_PIPELINE_BIND_POINT_COMPUTE;
  const std::vector<uint32_t> code = resolveShader(spirv);
  p.name_ = "compute shader";
  p.interface_ = reflectShader(code, VK_SHADER_STAGE_COMPUTE_BIT, p.name_);
  checkExplicitBindings(bindings, p.interface_);
  p.createLayout(bindings, pushConstantBytes);
  p.pipeline_ = createCompute(ctx, code, p.layout_, specialization);
  return p;
}

Pipeline Pipeline::graphics(Context& ctx, const GraphicsDesc& d) {
  Pipeline p;
  p.ctx_ = &ctx;
  p.bindPoint_ = VK_PIPELINE_BIND_POINT_GRAPHICS;
  const std::vector<uint32_t> vertex = resolveShader(d.vertex),
                              fragment = resolveShader(d.fragment);
  const std::string label = d.name.empty() ? std::string("graphics pipeline") : d.name;
  ShaderInterface iface =
      mergeInterfaces(reflectShader(vertex, VK_SHADER_STAGE_VERTEX_BIT, label + " (vertex)"),
                      reflectShader(fragment, VK_SHADER_STAGE_FRAGMENT_BIT, label + " (fragment)"));
  if (d.name.empty()) {
    p.name_ = label;
    checkExplicitBindings(d.bindings, iface);
    p.interface_ = std::move(iface);
    p.createLayout(d.bindings, d.pushConstantBytes);
  } else {
    if (!d.bindings.empty() || d.pushConstantBytes)
      throw Error(ErrorKind::ShaderInterface, "",
                  d.name + ": a named graphics pipeline takes its bindings from the shaders");
    p.useReflection(d.name, std::move(iface), d.blocks);
  }

  VkShaderModule vs = createModule(ctx.device(), vertex);
  VkShaderModule fs = createModule(ctx.device(), fragment);
  VkPipelineShaderStageCreateInfo stages[2] = {
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT,
       vs, "main", nullptr},
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0,
       VK_SHADER_STAGE_FRAGMENT_BIT, fs, "main", nullptr}};

  VkVertexInputBindingDescription vbinding{0, d.vertexLayout.stride, VK_VERTEX_INPUT_RATE_VERTEX};
  VkPipelineVertexInputStateCreateInfo vertexInput{
      VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  if (d.vertexLayout.stride) {
    vertexInput.vertexBindingDescriptionCount = 1;
    vertexInput.pVertexBindingDescriptions = &vbinding;
    vertexInput.vertexAttributeDescriptionCount =
        static_cast<uint32_t>(d.vertexLayout.attributes.size());
    vertexInput.pVertexAttributeDescriptions = d.vertexLayout.attributes.data();
  }
  VkPipelineInputAssemblyStateCreateInfo assembly{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = d.cullMode;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo msaa{
      VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  msaa.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{
      VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  depth.depthTestEnable = d.depthFormat != VK_FORMAT_UNDEFINED;
  depth.depthWriteEnable = d.depthWrite;
  depth.depthCompareOp = d.depthCompare;
  std::vector<VkPipelineColorBlendAttachmentState> blends(d.colorFormats.size());
  for (auto& b : blends) b.colorWriteMask = 0xF;
  VkPipelineColorBlendStateCreateInfo blend{
      VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend.attachmentCount = static_cast<uint32_t>(blends.size());
  blend.pAttachments = blends.data();
  VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dynamic.dynamicStateCount = 2;
  dynamic.pDynamicStates = dynamicStates;
  VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  rendering.colorAttachmentCount = static_cast<uint32_t>(d.colorFormats.size());
  rendering.pColorAttachmentFormats = d.colorFormats.data();
  rendering.depthAttachmentFormat = d.depthFormat;

  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.pNext = &rendering;
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &vertexInput;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &msaa;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend;
  info.pDynamicState = &dynamic;
  info.layout = p.layout_;
  VkResult r =
      vkCreateGraphicsPipelines(ctx.device(), ctx.pipelineCache(), 1, &info, nullptr, &p.pipeline_);
  vkDestroyShaderModule(ctx.device(), vs, nullptr);
  vkDestroyShaderModule(ctx.device(), fs, nullptr);
  check(r, "vkCreateGraphicsPipelines");
  return p;
}

Pipeline& Pipeline::operator=(Pipeline&& o) noexcept {
  if (this != &o) {
    reset();
    ctx_ = std::exchange(o.ctx_, nullptr);
    setLayout_ = std::exchange(o.setLayout_, VK_NULL_HANDLE);
    layout_ = std::exchange(o.layout_, VK_NULL_HANDLE);
    pipeline_ = std::exchange(o.pipeline_, VK_NULL_HANDLE);
    bindPoint_ = o.bindPoint_;
    interface_ = std::move(o.interface_);
    name_ = std::move(o.name_);
    cppPushSize_ = o.cppPushSize_;
    pushRange_ = o.pushRange_;
    guards_ = o.guards_;
  }
  return *this;
}

void Pipeline::reset() {
  if (!ctx_) return;
  VkDevice d = ctx_->device();
  if (pipeline_) vkDestroyPipeline(d, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(d, layout_, nullptr);
  if (setLayout_) vkDestroyDescriptorSetLayout(d, setLayout_, nullptr);
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
  ctx_ = nullptr;
}

DescriptorArena::~DescriptorArena() {
  for (VkDescriptorPool p : pools_) vkDestroyDescriptorPool(ctx_->device(), p, nullptr);
}

VkDescriptorPool DescriptorArena::newPool() {
  const VkDescriptorPoolSize sizes[] = {
      {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 512}, {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 128},
      {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 128},         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 128},
      {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 128},          {VK_DESCRIPTOR_TYPE_SAMPLER, 32}};
  VkDescriptorPoolCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  info.maxSets = 128;
  info.poolSizeCount = static_cast<uint32_t>(std::size(sizes));
  info.pPoolSizes = sizes;
  VkDescriptorPool pool;
  check(vkCreateDescriptorPool(ctx_->device(), &info, nullptr, &pool), "vkCreateDescriptorPool");
  pools_.push_back(pool);
  return pool;
}

void DescriptorArena::bind(VkCommandBuffer cmd, const Pipeline& p, DescriptorWriter& writer) {
  VkDescriptorSet set = allocate(p.setLayout());
  writer.update(ctx_->device(), set);
  vkCmdBindPipeline(cmd, p.bindPoint(), p.handle());
  vkCmdBindDescriptorSets(cmd, p.bindPoint(), p.layout(), 0, 1, &set, 0, nullptr);
}

VkDescriptorSet DescriptorArena::allocate(VkDescriptorSetLayout layout) {
  for (;;) {
    if (current_ == pools_.size()) newPool();
    VkDescriptorSetAllocateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    info.descriptorPool = pools_[current_];
    info.descriptorSetCount = 1;
    info.pSetLayouts = &layout;
    VkDescriptorSet set;
    VkResult r = vkAllocateDescriptorSets(ctx_->device(), &info, &set);
    if (r == VK_SUCCESS) return set;
    if (r != VK_ERROR_OUT_OF_POOL_MEMORY && r != VK_ERROR_FRAGMENTED_POOL)
      check(r, "vkAllocateDescriptorSets");
    ++current_;  // this pool is full: move on to the next (created on demand)
  }
}

void DescriptorArena::reset() {
  for (VkDescriptorPool p : pools_) vkResetDescriptorPool(ctx_->device(), p, 0);
  current_ = 0;
}

DescriptorWriter& DescriptorWriter::sampled(uint32_t binding, VkImageView view, VkSampler sampler,
                                            VkImageLayout layout, uint32_t element) {
  images_.push_back({sampler, view, layout});
  pending_.push_back(
      {binding, element, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, images_.size() - 1});
  return *this;
}

DescriptorWriter& DescriptorWriter::storageImage(uint32_t binding, VkImageView view) {
  images_.push_back({VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL});
  pending_.push_back({binding, 0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, images_.size() - 1});
  return *this;
}

DescriptorWriter& DescriptorWriter::buffer(uint32_t binding, VkDescriptorType type, VkBuffer buffer,
                                           VkDeviceSize offset, VkDeviceSize range) {
  buffers_.push_back({buffer, offset, range});
  pending_.push_back({binding, 0, type, buffers_.size() - 1});
  return *this;
}

DescriptorWriter::DescriptorWriter(const Pipeline& pipeline) : pipeline_(&pipeline) {}

const ShaderBinding* DescriptorWriter::named(std::string_view name, VkDescriptorType expected,
                                             const char* call) const {
  if (!pipeline_)
    throw Error(ErrorKind::ShaderInterface, "",
                std::string("DescriptorWriter::") + call + "('" + std::string(name) +
                    "'): binding by name needs the writer made for a pipeline");
  const ShaderInterface& iface = pipeline_->shaderInterface();
  const ShaderBinding* b = iface.find(name);
  if (!b)
    throw Error(ErrorKind::ShaderInterface, "",
                pipeline_->name() + ": the shader has no binding named '" + std::string(name) +
                    "' (it has " + iface.describe() + ")");
  const bool buffer =
      b->type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || b->type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  const bool ok = expected == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER ? buffer : b->type == expected;
  if (!ok)
    throw Error(ErrorKind::ShaderInterface, "",
                pipeline_->name() + ": '" + b->name + "' is a " + descriptorTypeName(b->type) +
                    ", not bound with " + call + "()");
  return iface.bound(*b) ? b : nullptr;  // an unused alias of a used binding: nothing to write
}

DescriptorWriter& DescriptorWriter::texture(std::string_view name, VkImageView view,
                                            VkSampler sampler, VkImageLayout layout,
                                            uint32_t element) {
  const ShaderBinding* b = named(name, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, "texture");
  return b ? sampled(b->binding, view, sampler, layout, element) : *this;
}

DescriptorWriter& DescriptorWriter::image(std::string_view name, VkImageView view,
                                          uint32_t element) {
  const ShaderBinding* b = named(name, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, "image");
  if (!b) return *this;
  images_.push_back({VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL});
  pending_.push_back({b->binding, element, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, images_.size() - 1});
  return *this;
}

DescriptorWriter& DescriptorWriter::buffer(std::string_view name, VkBuffer buffer,
                                           VkDeviceSize offset, VkDeviceSize range) {
  const ShaderBinding* b = named(name, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, "buffer");
  return b ? this->buffer(b->binding, b->type, buffer, offset, range) : *this;
}

void DescriptorWriter::update(VkDevice device, VkDescriptorSet set) {
  // The guard counters are the engine's to bind (gi/vk/guard_counters.h).
  if (pipeline_ && pipeline_->guardBinding().binding >= 0) {
    const Pipeline::GuardBinding& g = pipeline_->guardBinding();
    if (std::none_of(pending_.begin(), pending_.end(),
                     [&](const Pending& p) { return p.binding == uint32_t(g.binding); }))
      buffer(uint32_t(g.binding), VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, g.buffer, g.offset, g.range);
  }
  if (pipeline_)  // a binding the shader declares and nobody wrote is an error, not a crash
    for (const ShaderBinding& b : pipeline_->shaderInterface().bindings)
      if (pipeline_->shaderInterface().bound(b) &&
          std::none_of(pending_.begin(), pending_.end(),
                       [&](const Pending& p) { return p.binding == b.binding; }))
        throw Error(ErrorKind::ShaderInterface, "",
                    pipeline_->name() + ": binding '" + b.name + "' (" +
                        descriptorTypeName(b.type) + ", binding " + std::to_string(b.binding) +
                        ") was not given");
  std::vector<VkWriteDescriptorSet> writes;
  for (const Pending& p : pending_) {
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.dstBinding = p.binding;
    w.dstArrayElement = p.element;
    w.descriptorCount = 1;
    w.descriptorType = p.type;
    if (p.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || p.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)
      w.pBufferInfo = &buffers_[p.info];
    else
      w.pImageInfo = &images_[p.info];
    writes.push_back(w);
  }
  vkUpdateDescriptorSets(device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  pending_.clear();
  images_.clear();
  buffers_.clear();
}

}  // namespace gi::vk
