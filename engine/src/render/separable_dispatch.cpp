#include "gi/separable_dispatch.h"

#include "gi/vk/resources.h"

namespace gi {

void dispatchSeparable(PassContext& pc, const SeparableDispatch& d, TextureHandle in,
                       TextureHandle half, TextureHandle out) {
  const VkExtent2D extent = pc.extent(out);
  auto axis = [&](const vk::Pipeline& p, VkImageView src, VkImageLayout srcLayout,
                  VkImageView dst) {
    vk::DescriptorWriter w(p);
    if (d.bind) d.bind(w, p);
    w.texture(d.input, src, d.sampler, srcLayout).image(d.output, dst);
    pc.dispatch(p, w, extent, d.groupX, d.groupY);
  };
  if (!d.x) {
    axis(*d.y, pc.view(in), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, pc.view(out));
    return;
  }
  axis(*d.x, pc.view(in), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, pc.view(half));
  vk::storageWriteToSampledRead(pc.cmd(), pc.image(half));
  axis(*d.y, pc.view(half), VK_IMAGE_LAYOUT_GENERAL, pc.view(out));
}

}  // namespace gi
