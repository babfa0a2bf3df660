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
  EffectOverrides cli;
  cli.effects = {effectName()};
  cli.sets = sets;
  RenderSettings rs;
  rs.width = width;
  rs.height = height;
  rs.effects = resolveEffects(scene, nullptr, cli, registry);
  return rs;
}

}  // namespace gi::test
