#include "gi/lit_surface.h"

namespace gi {

namespace res = resources;

void LitSurfaceInputs::read(PassBuilder& b, Blackboard& bb) {
  depth = b.read(bb.texture(res::kDepth));
  gbuffer = b.read(bb.texture(res::kGBuffer));
  lights = b.read(bb.buffer(res::kLights));
  shadowViews = b.read(bb.buffer(res::kShadowViews));
  shadowMaps = b.read(bb.texture(res::kShadowMaps));
}

void LitSurfaceInputs::bind(vk::DescriptorWriter& w, PassContext& pc, VkSampler nearest) const {
  w.texture("giDepth", pc.view(depth), nearest)
      .texture("giGBuffer", pc.view(gbuffer), nearest)
      .buffer("Lights", pc.buffer(lights))
      .buffer("ShadowViews", pc.buffer(shadowViews))
      .texture("shadowMaps", pc.view(shadowMaps), nearest);
}

}  // namespace gi
