// What a pass reads to evaluate the scene's lights at G-buffer pixels as the lighting pass does
// (sumLights in lights.glsl): the G-buffer's depth and packed texels (gbuffer.glsl), the lights
// and shadow views (uniform buffers) and the shadow maps. One declaration and one binding block
// for every such pass (the lighting pass, and effects that need the direct light, e.g. as the
// radiance of bounce senders), at five consecutive bindings from `first`:
//   first + 0  depth          (GI_DEPTH_BINDING in gbuffer.glsl)
//   first + 1  gbuffer        (GI_GBUFFER_BINDING)
//   first + 2  lights         (GI_LIGHTS_BINDING in lights.glsl)
//   first + 3  shadow views   (GI_SHADOW_VIEWS_BINDING)
//   first + 4  shadow maps    (GI_SHADOW_MAPS_BINDING)
#pragma once

#include <cstdint>
#include <vector>

#include "gi/effect.h"
#include "gi/vk/pipeline.h"

namespace gi {

struct LitSurfaceInputs {
  TextureHandle depth, gbuffer, shadowMaps;
  BufferHandle lights, shadowViews;

  static constexpr uint32_t kBindings = 5;
  // The five bindings' descriptor types, for vk::Pipeline::compute.
  static std::vector<vk::Binding> layout(uint32_t first);
  // Declares the reads in a pass's setup (the blackboard's current versions).
  void read(PassBuilder& b, Blackboard& bb);
  // Binds them (textures with `nearest`, a nearest-filtering sampler: the packed texels are
  // integers) while the pass records.
  void bind(vk::DescriptorWriter& w, PassContext& pc, uint32_t first, VkSampler nearest) const;
  // The same by the names gbuffer.glsl and lights.glsl declare (`w` made for the pipeline).
  void bind(vk::DescriptorWriter& w, PassContext& pc, VkSampler nearest) const;
};

}  // namespace gi
