// What a pass reads to evaluate the scene's lights at G-buffer pixels as the lighting pass does
// (sumLights in lights.glsl): the G-buffer's depth and packed texels (gbuffer.glsl), the lights
// and shadow views (uniform buffers) and the shadow maps. One declaration and one binding block
// for every such pass (the lighting pass, and effects that need the direct light, e.g. as the
// radiance of bounce senders), bound by the names gbuffer.glsl and lights.glsl declare:
//   giDepth (GI_DEPTH_BINDING), giGBuffer (GI_GBUFFER_BINDING), Lights (GI_LIGHTS_BINDING),
//   ShadowViews (GI_SHADOW_VIEWS_BINDING), shadowMaps (GI_SHADOW_MAPS_BINDING).
#pragma once

#include <cstdint>
#include <vector>

#include "gi/effect.h"
#include "gi/vk/pipeline.h"

namespace gi {

struct LitSurfaceInputs {
  TextureHandle depth, gbuffer, shadowMaps;
  BufferHandle lights, shadowViews;

  // Declares the reads in a pass's setup (the blackboard's current versions).
  void read(PassBuilder& b, Blackboard& bb);
  // Binds them by name (`w` made for the pass's pipeline; textures with `nearest`, a
  // nearest-filtering sampler: the packed texels are integers) while the pass records.
  void bind(vk::DescriptorWriter& w, PassContext& pc, VkSampler nearest) const;
};

}  // namespace gi
