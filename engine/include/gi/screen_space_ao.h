// The shape the screen-space ambient-occlusion effects share: what they declare (info, the
// `radius` and `interleave` settings) and their passes: a producer writing DepthAwareBlur's
// packed texels, the optional depth-aware blur of them into "ao", and the publication of "ao".
// An AO effect with another shape (its own outputs, its own blur) can still take the pieces.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include "gi/depth_aware_blur.h"
#include "gi/effect.h"
#include "gi/setting_uniforms.h"

namespace gi {

// Runs before lighting, reads depth and the G-buffer, writes "ao" (also its debug view) and
// estimates ambient occlusion.
EffectInfo aoEffectInfo(std::string name, std::string description);
// The world-space "radius" R of the occlusion, 0.5 by default (a length: a model loaded without
// a scene file scales it to its size); read by aoEffectInfo's default estimatedQuantity.
SettingDesc aoRadiusSetting(std::string help);
// The uniform-only "interleave" flag, on by default: rotations in a 4x4 pixel pattern that the
// blur averages away.
SettingDesc interleaveSetting(std::string help);

// The producer, blur and publication of "ao". A member of the effect: prepare() in the effect's
// prepare(), addPasses() (or rawName() and publish() around a pass of its own) in addPasses().
class ScreenSpaceAO {
 public:
  // The producer's workgroup (its shader's local_size_x/y). Large groups: on llvmpipe each
  // workgroup carries a fixed scheduling cost, which 8x8 groups paid 3600 times at 640x360 (a
  // quarter of SSAO's 64-tap pass); 32x16 measured fastest (32x32 loses cache locality).
  static constexpr uint32_t kGroupX = 32, kGroupY = 16;

  // Builds the producer's pipeline (passes and messages carry `effect`'s name) and reads
  // "blur_radius" (DepthAwareBlur::radiusSetting) and the "radius" handle; builds the blur when
  // blur_radius > 0 or `scale` > 1 (a reduced resolution is upsampled even without a blur). The
  // blur averages a neighbour within `tolerance` x radius of the centre's tangent plane.
  void prepare(EffectContext& ctx, const SettingValues& settings, const std::string& effect,
               const vk::ComputeDesc& producer, double tolerance, int scale = 1);
  const vk::Pipeline& pipeline() const { return pipeline_; }
  bool blurred() const { return blurred_; }
  // What the producer writes: "ao" itself when nothing blurs it (the packed texel's first
  // channel is the AO), else <effect>_raw.
  std::string rawName() const;
  // Blurs `raw` into "ao" (pass <effect>_blur) when blurred, publishes "ao" and returns it.
  // `settings` are addPasses' (they outlive the graph: the tolerance follows the radius).
  TextureHandle publish(FrameGraph& graph, EffectContext& ctx, TextureHandle raw,
                        const SettingValues& settings) const;
  // The common case: the producer as DepthAwareBlur::addProducer's pass <effect> over the frame,
  // its storage image "outAO", `bind` adding its own resources as it records; then publish().
  TextureHandle addPasses(FrameGraph& graph, EffectContext& ctx,
                          std::function<void(vk::DescriptorWriter&)> bind,
                          const SettingValues& settings) const;

 private:
  std::string effect_;
  vk::Pipeline pipeline_;
  DepthAwareBlur blur_;
  bool blurred_ = false;
  double tolerance_ = 0.0;
  Setting<double> radius_;
};

// The whole effect when the producer reads one uniform block made from a few settings (SSAO,
// HBAO): the effect declares info() and settings() and calls prepareAO() from prepare(); the
// passes follow.
template <class T, size_t N>
class ScreenSpaceAOEffect : public Effect {
 public:
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues& settings) override {
    ao_.addPasses(graph, ctx, uniforms_.binding(block_, settings), settings);
  }

 protected:
  // The producer's uniform block: its name in the shader and its checked C++ layout, the
  // settings it is made from and how (SettingUniforms: rebuilt only when one changed).
  struct Block {
    std::string name;
    vk::CppBlock layout;
    std::array<const char*, N> settings;
    std::function<T(const typename SettingUniforms<T, N>::Values&)> make;
  };
  // ScreenSpaceAO::prepare with `block` checked against the producer and bound to it.
  void prepareAO(EffectContext& ctx, const SettingValues& settings, const std::string& effect,
                 vk::ComputeDesc producer, double tolerance, Block block) {
    producer.blocks.uniforms = {{block.name, std::move(block.layout)}};
    ao_.prepare(ctx, settings, effect, producer, tolerance);
    uniforms_.prepare(ctx.vulkan(), settings, block.settings, std::move(block.make));
    block_ = std::move(block.name);
  }

 private:
  ScreenSpaceAO ao_;
  SettingUniforms<T, N> uniforms_;
  std::string block_;
};

}  // namespace gi
