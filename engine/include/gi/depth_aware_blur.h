// A separable depth-aware (cross-bilateral) blur of one value per pixel, for effects whose raw
// output is noisy or interleaved (screen-space ambient occlusion and the like), optionally
// computed at a reduced resolution and upsampled.
//
// The effect's own pass writes an RGBA32F texture (kPackedFormat) of
// depthAwareBlurPack(frame, value, P, N) texels (depth_aware_blur.glsl: the value, 1 / view
// distance and the tangent plane's slopes), so each blur tap is one fetch. The blur runs along x
// then y (two dispatches in one pass) into an R16F texture of the packed input's size. Weights,
// edge stopping and the 4x4-interleave cancellation: depth_aware_blur.glsl.
//
// Reduced resolution (`scale` > 1): the packed texture has 1 / scale of the frame's pixels in
// each axis, its pixel q standing for the frame's pixel q x scale, with slopes per low-resolution
// pixel (depthAwareBlurPackScaled). The blur runs there, and a second pass upsamples the result
// to the frame's resolution: each pixel mixes its 4 nearest low-resolution values bilinearly,
// keeping those whose tangent plane predicts its own depth within the tolerance (the blur's
// test, so no value crosses a depth edge); when none does, the one whose plane comes nearest.
#pragma once

#include <functional>
#include <string>

#include "gi/effect.h"
#include "gi/vk/pipeline.h"

namespace gi {

class DepthAwareBlur {
 public:
  static constexpr VkFormat kPackedFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  static constexpr VkFormat kOutputFormat = VK_FORMAT_R16_SFLOAT;
  static constexpr int kMaxRadius = 8;
  static constexpr int kMaxScale = 4;

  // The "blur_radius" setting of an effect that blurs with this (changesGraph: the radius is
  // compiled into the blur), 0..kMaxRadius.
  static SettingDesc radiusSetting(int defaultRadius = 2);

  // Builds the pipelines. `radius` (at most kMaxRadius; 0: no blur, only the upsample, which
  // needs scale > 1) and `scale` (1..kMaxScale) are compiled into them.
  void prepare(EffectContext& ctx, int radius, int scale = 1);
  // Adds pass `name` blurring `packed` (and, with scale > 1, pass `name`_upsample, which reads
  // the G-buffer depth) into a new texture `output` of the frame's resolution and returns it
  // (publish it on the blackboard yourself). `tolerance()` is read each time a pass records: how
  // far, in world units, a neighbour may lie from the centre's tangent plane and still be
  // averaged.
  TextureHandle addPass(FrameGraph& graph, EffectContext& ctx, const std::string& name,
                        TextureHandle packed, const std::string& output,
                        std::function<float()> tolerance) const;

  // The pass that writes the packed texels, in the shape most effects share: `pipeline` runs
  // over every pixel of a new kPackedFormat texture `texture` of the frame's size, its shader
  // reading the frame uniforms as "Frame" and the G-buffer as "gDepth" and "giGBuffer"
  // (gbuffer.glsl) and writing the texels to its storage image `image`. `bind` adds the pass's
  // own resources while it records (read uniform-only settings and upload there).
  struct Producer {
    std::string name;  // the pass
    const vk::Pipeline* pipeline = nullptr;
    std::string image;
    uint32_t groupX = 32, groupY = 16;
    std::function<void(vk::DescriptorWriter&)> bind;
  };
  static TextureHandle addProducer(FrameGraph& graph, EffectContext& ctx, Producer producer,
                                   const std::string& texture);

 private:
  struct Push {  // depth_aware_blur_pass.glsl's and depth_aware_upsample.comp's push constants
    float tolerance;
  };
  vk::Pipeline x_, y_, upsample_;
  int radius_ = 0, scale_ = 1;
};

}  // namespace gi
