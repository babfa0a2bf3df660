#include "gi/depth_aware_blur.h"

#include <algorithm>
#include <memory>

#include "gi/errors.h"
#include "gi/image_pass.h"
#include "gi/separable_dispatch.h"

namespace gi {
namespace {

constexpr uint32_t kGroupX = 32, kGroupY = 16;  // depth_aware_blur_pass.glsl, _upsample.comp

}  // namespace

void DepthAwareBlur::prepare(EffectContext& ctx, int radius, int scale) {
  vk::Context& vk = ctx.vulkan();
  vk.requireWorkgroup(kGroupX, kGroupY, "depth-aware blur");
  radius_ = std::clamp(radius, 0, kMaxRadius);
  scale_ = std::clamp(scale, 1, kMaxScale);
  if (radius_ == 0 && scale_ == 1)
    throw Error(ErrorKind::Usage, {},
                "depth-aware blur: radius 0 at full resolution has nothing to do");
  auto make = [&](const char* shader, std::vector<uint32_t> spec) {
    vk::ComputeDesc d{std::string("depth-aware blur: ") + shader, vk::loadSpirv(shader),
                      std::move(spec)};
    d.blocks.pushConstants = GI_CPP_BLOCK(Push, tolerance);
    return vk::Pipeline::compute(vk, d);
  };
  if (radius_ > 0) {
    x_ = make("depth_aware_blur_x.comp", {uint32_t(radius_)});
    // Upsampled later: the y pass keeps the packed texel (its 1/z and slopes) for the upsample.
    y_ = make(scale_ > 1 ? "depth_aware_blur_y_packed.comp" : "depth_aware_blur_y.comp",
              {uint32_t(radius_)});
  }
  if (scale_ > 1) upsample_ = make("depth_aware_upsample.comp", {uint32_t(scale_)});
}

TextureHandle DepthAwareBlur::addPass(FrameGraph& graph, EffectContext& ctx,
                                      const std::string& name, TextureHandle packed,
                                      const std::string& output,
                                      std::function<float()> tolerance) const {
  const VkSampler nearest = ctx.nearestSampler();
  TextureHandle blurred = packed;
  if (radius_ > 0) {
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
          TextureDesc out{scale_ > 1 ? kPackedFormat : kOutputFormat, SizeClass::InputRelative};
          out.relativeTo = packed;
          io->out =
              b.write(b.create(scale_ > 1 ? name + "_y" : output, out), TextureUsage::StorageWrite);
        },
        [this, io, tolerance, nearest](PassContext& pc) {
          const Push push{tolerance()};
          dispatchSeparable(pc,
                            {.x = &x_,
                             .y = &y_,
                             .input = "inPacked",
                             .output = "outValue",
                             .sampler = nearest,
                             .bind = [&](vk::DescriptorWriter&,
                                         const vk::Pipeline& p) { p.push(pc.cmd(), push); },
                             .groupX = kGroupX,
                             .groupY = kGroupY},
                            io->packed, io->half, io->out);
        });
    blurred = io->out;
    if (scale_ == 1) return blurred;
  }

  struct Up {
    TextureHandle packed, depth, out;
  };
  auto up = std::make_shared<Up>();
  graph.addPass(
      name + "_upsample",
      [&](PassBuilder& b) {
        up->packed = b.read(blurred);
        up->depth = b.read(graph.blackboard().texture(resources::kDepth));
        up->out = b.write(b.create(output, TextureDesc{kOutputFormat}), TextureUsage::StorageWrite);
      },
      [this, up, tolerance = std::move(tolerance), nearest,
       frame = ctx.frameUniforms()](PassContext& pc) {
        vk::DescriptorWriter w(upsample_);
        w.texture("inPacked", pc.view(up->packed), nearest)
            .image("outValue", pc.view(up->out))
            .texture("gDepth", pc.view(up->depth), nearest)
            .buffer("Frame", frame);
        pc.dispatch(upsample_, w, pc.extent(up->out), kGroupX, kGroupY, Push{tolerance()});
      });
  return up->out;
}

SettingDesc DepthAwareBlur::radiusSetting(int defaultRadius) {
  return {"blur_radius",
          SettingType::Int,
          double(defaultRadius),
          0.0,
          double(kMaxRadius),
          "depth-aware blur radius in pixels (0: no blur pass; even radii cancel the 4x4 "
          "interleave pattern exactly)",
          true};
}

TextureHandle DepthAwareBlur::addProducer(FrameGraph& graph, EffectContext& ctx, Producer producer,
                                          const std::string& texture) {
  auto bind = std::move(producer.bind);
  return addImagePass(graph, ctx,
                      {producer.name,
                       producer.pipeline,
                       {{resources::kDepth, "gDepth"}, {resources::kGBuffer, "giGBuffer"}},
                       texture,
                       TextureDesc{kPackedFormat},
                       producer.image,
                       producer.groupX,
                       producer.groupY,
                       [bind](vk::DescriptorWriter& w, PassContext&) {
                         if (bind) bind(w);
                       }});
}

}  // namespace gi
