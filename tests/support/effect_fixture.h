// A Vulkan test of one effect plugin: the registry holds the build's plugins, and SetUp fails
// the test when `effectName()` is not among them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gi/effect_registry.h"
#include "gi/renderer.h"
#include "vulkan_fixture.h"

namespace gi::test {

class EffectTest : public VulkanTest {
 protected:
  virtual std::string effectName() const = 0;
  void SetUp() override;
  // Settings that run the effect alone on `scene` at width x height, with `sets` (its
  // "effect.key=value" overrides, as gi-render's --set).
  RenderSettings settingsFor(const Scene& scene, const std::vector<std::string>& sets,
                             uint32_t width, uint32_t height) const;
  // The same with `effects` in place of the effect (as gi-render's --effects): another effect
  // to compare it with, several at once, or none (the engine alone). Only effectName() is
  // checked by SetUp; an effect missing from the registry throws gi::Error here.
  RenderSettings settingsFor(const std::vector<std::string>& effects, const Scene& scene,
                             const std::vector<std::string>& sets, uint32_t width,
                             uint32_t height) const;
  EffectRegistry registry;
};

}  // namespace gi::test
