// A do-nothing effect for the registry tests' modules: registered, listed, never rendered.
#pragma once

#include <string>
#include <vector>

#include "gi/effect.h"
#include "gi/effect_registry.h"

namespace gi::test {

template <const char* Name>
class NamedEffect : public Effect {
 public:
  EffectInfo info() const override {
    return {Name, "1", "registry test effect", EffectStage::BeforeLighting, {}, {}, "lit"};
  }
  std::vector<SettingDesc> settings() const override {
    return {{"amount", SettingType::Float, 0.5, 0.0, 1.0, "unused", false}};
  }
  void prepare(EffectContext&, const SettingValues&) override {}
  void addPasses(FrameGraph&, EffectContext&, const SettingValues&) override {}
};

}  // namespace gi::test
