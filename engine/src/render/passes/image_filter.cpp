// The frame-uniforms + one input + one storage output compute pass of tonemap and floor.
#include "gi/errors.h"
#include "gi/vk/pipeline.h"
#include "render/passes/builtin_passes.h"

namespace gi {

namespace {
// The shader's one binding of `type` (its name is the shader's own: litColor, gPacked, ...).
const std::string& onlyBinding(const vk::Pipeline& p, VkDescriptorType type) {
  const vk::ShaderBinding* found = nullptr;
  for (const vk::ShaderBinding& b : p.shaderInterface().bindings)
    if (b.type == type) {
      if (found)
        throw Error(ErrorKind::ShaderInterface, "",
                    p.name() + ": an image filter has one " + vk::descriptorTypeName(type));
      found = &b;
    }
  if (!found)
    throw Error(ErrorKind::ShaderInterface, "",
                p.name() + ": an image filter needs a " + vk::descriptorTypeName(type));
  return found->name;
}
}  // namespace

vk::Pipeline makeImageFilterPipeline(vk::Context& ctx, const std::string& spirvName,
                                     std::vector<uint32_t> specialization) {
  vk::Pipeline p =
      vk::Pipeline::compute(ctx, {spirvName, vk::loadSpirv(spirvName), std::move(specialization)});
  onlyBinding(p, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);  // the contract, checked once
  onlyBinding(p, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
  return p;
}

void recordImageFilter(PassContext& pc, const vk::Pipeline& pipeline, VkBuffer frame,
                       VkSampler sampler, TextureHandle in, TextureHandle out, uint32_t groupX,
                       uint32_t groupY) {
  vk::DescriptorWriter w(pipeline);
  w.buffer("Frame", frame)
      .texture(onlyBinding(pipeline, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER), pc.view(in),
               sampler)
      .image(onlyBinding(pipeline, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE), pc.view(out));
  pc.dispatch(pipeline, w, pc.extent(out), groupX, groupY);
}

}  // namespace gi
