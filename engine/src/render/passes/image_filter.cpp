// The frame-uniforms + one input + one storage output compute pass of tonemap and floor.
#include "gi/vk/pipeline.h"
#include "render/passes/builtin_passes.h"

namespace gi {

vk::Pipeline makeImageFilterPipeline(vk::Context& ctx, const std::string& spirvName) {
  return vk::Pipeline::compute(ctx, vk::loadSpirv(spirvName),
                               {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                                {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}});
}

void recordImageFilter(PassContext& pc, const vk::Pipeline& pipeline, VkBuffer frame,
                       VkSampler sampler, TextureHandle in, TextureHandle out, uint32_t groupX,
                       uint32_t groupY) {
  vk::DescriptorWriter w;
  w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frame)
      .sampled(1, pc.view(in), sampler)
      .storageImage(2, pc.view(out));
  pc.dispatch(pipeline, w, pc.extent(out), groupX, groupY);
}

}  // namespace gi
