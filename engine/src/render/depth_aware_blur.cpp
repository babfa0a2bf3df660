#include "gi/depth_aware_blur.h"

#include <algorithm>
#include <memory>

#include "gi/vk/resources.h"

namespace gi {
namespace {

constexpr uint32_t kGroupX = 32, kGroupY = 16;  // depth_aware_blur_pass.glsl

}  // namespace

void DepthAwareBlur::prepare(EffectContext& ctx, int radius) {
  vk::Context& vk = ctx.vulkan();
  vk.requireWorkgroup(kGroupX, kGroupY, "depth-aware blur");
  const std::vector<vk::Binding> bindings = {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                             {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}};
  const std::vector<uint32_t> spec = {uint32_t(std::clamp(radius, 1, kMaxRadius))};
  x_ = vk::Pipeline::compute(vk, vk::loadSpirv("depth_aware_blur_x.comp"), bindings, sizeof(float),
                             spec);
  y_ = vk::Pipeline::compute(vk, vk::loadSpirv("depth_aware_blur_y.comp"), bindings, sizeof(float),
                             spec);
}

TextureHandle DepthAwareBlur::addPass(FrameGraph& graph, EffectContext& ctx,
                                      const std::string& name, TextureHandle packed,
                                      const std::string& output,
                                      std::function<float()> tolerance) const {
  struct Io {
    TextureHandle packed, half, out;
  };
  auto io = std::make_shared<Io>();
  graph.addPass(
      name,
      [&](PassBuilder& b) {
        io->packed = b.read(packed);
        TextureDesc half{kPackedFormat, SizeClass::InputRelative};
        half.relativeTo = packed;
        io->half = b.write(b.create(name + "_x", half), TextureUsage::StorageWrite);
        TextureDesc out{kOutputFormat, SizeClass::InputRelative};
        out.relativeTo = packed;
        io->out = b.write(b.create(output, out), TextureUsage::StorageWrite);
      },
      [this, io, tolerance = std::move(tolerance),
       nearest = ctx.nearestSampler()](PassContext& pc) {
        const VkExtent2D e = pc.extent(io->out);
        const float tol = tolerance();
        auto axis = [&](const vk::Pipeline& p, VkImageView in, VkImageLayout inLayout,
                        VkImageView out) {
          vk::DescriptorWriter w;
          w.sampled(0, in, nearest, inLayout).storageImage(1, out);
          vkCmdPushConstants(pc.cmd(), p.layout(), VK_SHADER_STAGE_ALL, 0, sizeof tol, &tol);
          pc.dispatch(p, w, e, kGroupX, kGroupY);
        };
        axis(x_, pc.view(io->packed), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, pc.view(io->half));
        vk::storageWriteToSampledRead(pc.cmd(), pc.image(io->half));
        axis(y_, pc.view(io->half), VK_IMAGE_LAYOUT_GENERAL, pc.view(io->out));
      });
  return io->out;
}

}  // namespace gi
