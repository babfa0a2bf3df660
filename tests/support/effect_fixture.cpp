#include "effect_fixture.h"

#include "gi/effect_config.h"
#include "test_support.h"

namespace gi::test {

void EffectTest::SetUp() {
  VulkanTest::SetUp();
  registry.scanDirectory(binPath("plugins"));
  ASSERT_TRUE(registry.has(effectName()))
      << effectName() << " plugin missing from " << binPath("plugins");
}

RenderSettings EffectTest::settingsFor(const Scene& scene, const std::vector<std::string>& sets,
                                       uint32_t width, uint32_t height) const {
  return settingsFor({effectName()}, scene, sets, width, height);
}

RenderSettings EffectTest::settingsFor(const std::vector<std::string>& effects, const Scene& scene,
                                       const std::vector<std::string>& sets, uint32_t width,
                                       uint32_t height) const {
  RenderRequest request;
  request.overrides.effects = effects;
  request.overrides.sets = sets;
  RenderSettings base;
  base.width = width;
  base.height = height;
  return configureRender(scene, registry, request, base);  // as every app sets a frame up
}

}  // namespace gi::test
