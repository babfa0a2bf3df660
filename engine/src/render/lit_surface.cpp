#include "gi/lit_surface.h"

namespace gi {

namespace res = resources;

std::vector<vk::Binding> LitSurfaceInputs::layout(uint32_t first) {
  const auto tex = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
             ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  return {{first, tex},     {first + 1, tex}, {first + 2, tex}, {first + 3, tex},
          {first + 4, tex}, {first + 5, ubo}, {first + 6, ubo}, {first + 7, tex}};
}

void LitSurfaceInputs::read(PassBuilder& b, Blackboard& bb) {
  depth = b.read(bb.texture(res::kDepth));
  normal = b.read(bb.texture(res::kNormal));
  albedo = b.read(bb.texture(res::kAlbedo));
  material = b.read(bb.texture(res::kMaterial));
  emission = b.read(bb.texture(res::kEmission));
  lights = b.read(bb.buffer(res::kLights));
  shadowViews = b.read(bb.buffer(res::kShadowViews));
  shadowMaps = b.read(bb.texture(res::kShadowMaps));
}

void LitSurfaceInputs::bind(vk::DescriptorWriter& w, PassContext& pc, uint32_t first,
                            VkSampler sampler) const {
  const auto ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  w.sampled(first, pc.view(depth), sampler)
      .sampled(first + 1, pc.view(normal), sampler)
      .sampled(first + 2, pc.view(albedo), sampler)
      .sampled(first + 3, pc.view(material), sampler)
      .sampled(first + 4, pc.view(emission), sampler)
      .buffer(first + 5, ubo, pc.buffer(lights))
      .buffer(first + 6, ubo, pc.buffer(shadowViews))
      .sampled(first + 7, pc.view(shadowMaps), sampler);
}

}  // namespace gi
