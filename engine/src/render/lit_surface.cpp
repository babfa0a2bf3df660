#include "gi/lit_surface.h"

namespace gi {

namespace res = resources;

std::vector<vk::Binding> LitSurfaceInputs::layout(uint32_t first) {
  const auto tex = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
             ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  return {{first, tex}, {first + 1, tex}, {first + 2, ubo}, {first + 3, ubo}, {first + 4, tex}};
}

void LitSurfaceInputs::read(PassBuilder& b, Blackboard& bb) {
  depth = b.read(bb.texture(res::kDepth));
  gbuffer = b.read(bb.texture(res::kGBuffer));
  lights = b.read(bb.buffer(res::kLights));
  shadowViews = b.read(bb.buffer(res::kShadowViews));
  shadowMaps = b.read(bb.texture(res::kShadowMaps));
}

void LitSurfaceInputs::bind(vk::DescriptorWriter& w, PassContext& pc, uint32_t first,
                            VkSampler nearest) const {
  const auto ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  w.sampled(first, pc.view(depth), nearest)
      .sampled(first + 1, pc.view(gbuffer), nearest)
      .buffer(first + 2, ubo, pc.buffer(lights))
      .buffer(first + 3, ubo, pc.buffer(shadowViews))
      .sampled(first + 4, pc.view(shadowMaps), nearest);
}

void LitSurfaceInputs::bind(vk::DescriptorWriter& w, PassContext& pc, VkSampler nearest) const {
  w.texture("giDepth", pc.view(depth), nearest)
      .texture("giGBuffer", pc.view(gbuffer), nearest)
      .buffer("Lights", pc.buffer(lights))
      .buffer("ShadowViews", pc.buffer(shadowViews))
      .texture("shadowMaps", pc.view(shadowMaps), nearest);
}

}  // namespace gi
