// An effect module built in two versions from this file (tests/test_plugin_reload.cpp):
// "reloadable" writes a constant ambient visibility (RELOADABLE_AO) with a clear, so each
// version's code is visible in the image. Version 2 also changes its settings: "samples" turns
// from an Int into a Bool and "strength" is new; "value" keeps its name and type. A third build
// (RELOADABLE_FAILS, tests/test_demo.cpp) is version 1 whose pass throws while it records once
// "value" is above 0.9, a uniform-only setting: a plugin that fails in the middle of a run.
#include <memory>
#include <stdexcept>

#include "gi/effect.h"
#include "gi/effect_registry.h"

namespace {

class Reloadable final : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    gi::EffectInfo i{"reloadable", RELOADABLE_VERSION, "constant AO (plugin reload test)"};
    i.writes = {gi::resources::kAO};
    i.debugView = gi::resources::kAO;
    return i;
  }
  std::vector<gi::SettingDesc> settings() const override {
    using T = gi::SettingType;
#if RELOADABLE_AO_TIMES_4 == 1
    return {{"value", T::Float, 0.5, 0.0, 1.0, "unused by the image", false},
            { "samples",
              T::Int,
              8,
              1,
              64,
              "unused",
              false }};
#else
    return {{"value", T::Float, 0.5, 0.0, 1.0, "unused by the image", false},
            {"samples", T::Bool, 0, 0, 1, "unused (an Int in version 1)", false},
            {"strength", T::Float, 1.0, 0.0, 2.0, "unused (new in version 2)", false}};
#endif
  }
  void prepare(gi::EffectContext&, const gi::SettingValues&) override {}
  void addPasses(gi::FrameGraph& g, gi::EffectContext&, const gi::SettingValues& s) override {
    auto ao = std::make_shared<gi::TextureHandle>();
    g.addPass(
        "reloadable",
        [&](gi::PassBuilder& b) {
          *ao = b.write(b.create(gi::resources::kAO, gi::TextureDesc{VK_FORMAT_R8G8B8A8_UNORM}),
                        gi::TextureUsage::TransferDst);
        },
        [ao, values = &s](gi::PassContext& pc) {
#if RELOADABLE_FAILS
          if (values->number("value") > 0.9) throw std::runtime_error("value above 0.9");
#else
          (void)values;
#endif
          const float v = 0.25f * RELOADABLE_AO_TIMES_4;
          VkClearColorValue c{{v, v, v, 1.0f}};
          VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
          vkCmdClearColorImage(pc.cmd(), pc.image(*ao), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &c, 1,
                               &range);
        });
    g.blackboard().put(gi::resources::kAO, *ao);
  }
};

}  // namespace

GI_EFFECT_MODULE(Reloadable)
