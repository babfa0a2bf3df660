// A separable depth-aware (cross-bilateral) blur of one value per pixel, for effects whose raw
// output is noisy or interleaved (screen-space ambient occlusion and the like).
//
// The effect's own pass writes an RGBA32F texture (kPackedFormat) of
// depthAwareBlurPack(frame, value, P, N) texels (depth_aware_blur.glsl: the value, 1 / view
// distance and the tangent plane's slopes), so each blur tap is one fetch. The blur runs along x
// then y (two dispatches in one pass) into an R16F texture of the packed input's size. Weights,
// edge stopping and the 4x4-interleave cancellation: depth_aware_blur.glsl.
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

  // Builds the two pipelines; `radius` (clamped to 1..kMaxRadius) is compiled into them.
  void prepare(EffectContext& ctx, int radius);
  // Adds pass `name` blurring `packed` into a new texture `output` and returns it (publish it
  // on the blackboard yourself). `tolerance()` is read each time the pass records: how far, in
  // world units, a neighbour may lie from the centre's tangent plane and still be averaged.
  TextureHandle addPass(FrameGraph& graph, EffectContext& ctx, const std::string& name,
                        TextureHandle packed, const std::string& output,
                        std::function<float()> tolerance) const;

 private:
  vk::Pipeline x_, y_;
};

}  // namespace gi
