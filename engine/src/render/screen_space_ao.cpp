#include "gi/screen_space_ao.h"

#include <utility>

namespace gi {

EffectInfo aoEffectInfo(std::string name, std::string description) {
  return {.name = std::move(name),
          .version = "1.0",
          .description = std::move(description),
          .stage = EffectStage::BeforeLighting,
          .reads = {resources::kDepth, resources::kGBuffer},
          .writes = {resources::kAO},
          .debugView = resources::kAO,
          .estimates = GroundTruth::AmbientOcclusion,
          .range = "radius"};
}

SettingDesc aoRadiusSetting(std::string help) {
  return SettingDesc::length("radius", 0.5, 1e-6, 1e9, std::move(help));
}

SettingDesc interleaveSetting(std::string help) {
  return {"interleave", SettingType::Bool, 1, 0, 1, std::move(help), false};
}

void ScreenSpaceAO::prepare(EffectContext& ctx, const SettingValues& settings,
                            const std::string& effect, const vk::ComputeDesc& producer,
                            double tolerance, int scale) {
  effect_ = effect;
  ctx.vulkan().requireWorkgroup(kGroupX, kGroupY, effect);
  pipeline_ = vk::Pipeline::compute(ctx.vulkan(), producer);
  const int radius = settings.integer("blur_radius");
  // The blur radius and scale are compiled into the blur (changesGraph: prepare runs again).
  blurred_ = radius > 0 || scale > 1;
  if (blurred_) blur_.prepare(ctx, radius, scale);
  tolerance_ = tolerance;
  radius_ = settings.handle<double>("radius");
}

std::string ScreenSpaceAO::rawName() const {
  return blurred_ ? effect_ + "_raw" : resources::kAO;
}

TextureHandle ScreenSpaceAO::publish(FrameGraph& graph, EffectContext& ctx, TextureHandle raw,
                                     const SettingValues& settings) const {
  TextureHandle ao = raw;
  if (blurred_)
    ao = blur_.addPass(graph, ctx, effect_ + "_blur", raw, resources::kAO,
                       [values = &settings, radius = radius_, tolerance = tolerance_] {
                         return float(tolerance * (*values)[radius]);
                       });
  graph.blackboard().put(resources::kAO, ao);
  return ao;
}

TextureHandle ScreenSpaceAO::addPasses(FrameGraph& graph, EffectContext& ctx,
                                       std::function<void(vk::DescriptorWriter&)> bind,
                                       const SettingValues& settings) const {
  const TextureHandle raw = DepthAwareBlur::addProducer(
      graph, ctx, {effect_, &pipeline_, "outAO", kGroupX, kGroupY, std::move(bind)}, rawName());
  return publish(graph, ctx, raw, settings);
}

}  // namespace gi
