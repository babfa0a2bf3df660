// Live changes on one renderer (what the demo's UI does): toggling effects, changing a
// graph-changing setting, the view, the size and engine settings give the same image as a
// fresh renderer built with that configuration; a bad change throws and changes nothing.
#include <gtest/gtest.h>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

std::string pluginDir() {
  return std::string(GI_BIN_DIR) + "/plugins";
}

class LiveChangesTest : public VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    registry_.scanDirectory(pluginDir());
    ASSERT_TRUE(registry_.has("ssao")) << "the SSAO plugin is built into " << pluginDir();
  }
  RenderSettings base() const {
    RenderSettings rs;
    rs.width = 96;
    rs.height = 72;
    return rs;
  }
  EffectConfig ssao(int blurRadius) const {
    EffectConfig c{"ssao", registry_.defaultSettings("ssao")};
    c.settings.set("blur_radius", blurRadius, "test");
    c.settings.set("samples", 8, "test");
    return c;
  }
  ImageRGBA32F fresh(const RenderSettings& rs, const std::string& target) {
    Renderer r(ctx(), scene_, rs, &registry_);
    r.renderFrame();
    return r.readTarget(target);
  }
  Scene scene_ = loadScene("default");
  EffectRegistry registry_;
};

void expectSame(const ImageRGBA32F& a, const ImageRGBA32F& b, const std::string& what) {
  ASSERT_EQ(a.width, b.width) << what;
  ASSERT_EQ(a.height, b.height) << what;
  EXPECT_EQ(a.pixels, b.pixels) << what;
}

TEST_F(LiveChangesTest, ToggleEffectsAndGraphSettingsMatchFreshRenderers) {
  RenderSettings rs = base();
  Renderer live(ctx(), scene_, rs, &registry_);
  live.renderFrame();
  const ImageRGBA32F plain = live.readTarget("output");
  expectSame(plain, fresh(rs, "output"), "no effects");

  // Toggle SSAO on: same as a renderer built with it.
  RenderSettings withSsao = rs;
  withSsao.effects = {ssao(2)};
  live.setEffects(withSsao.effects);
  EXPECT_TRUE(live.graphRecompiledByLastChange());
  live.renderFrame();
  expectSame(live.readTarget("output"), fresh(withSsao, "output"), "ssao on");
  const auto passes = live.passNames();
  EXPECT_NE(std::find(passes.begin(), passes.end(), "ssao_blur"), passes.end());

  // A graph-changing setting (blur radius 0 drops the blur pass).
  RenderSettings noBlur = rs;
  noBlur.effects = {ssao(0)};
  live.setEffectSettings("ssao", noBlur.effects[0].settings);
  EXPECT_TRUE(live.graphRecompiledByLastChange());
  live.renderFrame();
  expectSame(live.readTarget("output"), fresh(noBlur, "output"), "ssao without blur");
  const auto fewer = live.passNames();
  EXPECT_EQ(std::find(fewer.begin(), fewer.end(), "ssao_blur"), fewer.end());

  // Off again: the image without effects.
  live.setEffects({});
  live.renderFrame();
  expectSame(live.readTarget("output"), plain, "ssao off");
}

TEST_F(LiveChangesTest, ViewSizeAndEngineSettingsMatchFreshRenderers) {
  RenderSettings rs = base();
  rs.effects = {ssao(2)};
  Renderer live(ctx(), scene_, rs, &registry_);
  live.renderFrame();

  live.setView("ao");
  live.renderFrame();
  RenderSettings view = rs;
  view.view = "ao";
  expectSame(live.readTarget("ao"), fresh(view, "ao"), "view ao");
  const std::vector<std::string> passes = live.passNames();
  EXPECT_EQ(std::find(passes.begin(), passes.end(), "lighting"), passes.end())
      << "lighting is culled for the ao view";

  // Size, shadow-map size, PCF, exposure and environment intensity in one change.
  RenderSettings next = rs;
  next.width = 64;
  next.height = 80;
  next.shadowMapSize = 256;
  next.pcfRadius = 2;
  next.exposure = 1.7f;
  next.environmentIntensity = 0.5f;
  live.applySettings(next);
  live.renderFrame();
  expectSame(live.readTarget("output"), fresh(next, "output"), "resized with engine settings");
  EXPECT_EQ(live.outputExtent().width, 64u);
}

TEST_F(LiveChangesTest, AFailedChangeKeepsThePreviousConfiguration) {
  RenderSettings rs = base();
  Renderer live(ctx(), scene_, rs, &registry_);
  live.renderFrame();
  const ImageRGBA32F before = live.readTarget("output");
  EXPECT_THROW(live.setView("no_such_view"), Error);
  EXPECT_THROW(live.setEffects({{"no_such_effect", SettingValues()}}), Error);
  live.renderFrame();
  expectSame(live.readTarget("output"), before, "after failed changes");
  EXPECT_EQ(live.settings().view, "output");
}

// With effects active, failed changes of every kind leave the renderer working with its
// previous configuration, and settings() reports what is really active.
TEST_F(LiveChangesTest, FailedChangesWithEffectsActiveKeepEverything) {
  RenderSettings rs = base();
  rs.effects = {ssao(2)};
  Renderer live(ctx(), scene_, rs, &registry_);
  live.renderFrame();
  const ImageRGBA32F before = live.readTarget("output");

  RenderSettings badView = rs;
  badView.width = 64;  // a resize that must be undone too
  badView.view = "no_such_view";
  EXPECT_THROW(live.applySettings(badView), Error);
  RenderSettings badEffect = rs;
  badEffect.shadowMapSize = 256;
  badEffect.effects.push_back({"no_such_effect", SettingValues()});
  EXPECT_THROW(live.applySettings(badEffect), Error);
  EXPECT_THROW(live.setEffects({ssao(0), {"no_such_effect", SettingValues()}}), Error);
  live.renderFrame();
  expectSame(live.readTarget("output"), before, "after failed changes");
  EXPECT_EQ(live.settings().width, 96u);
  EXPECT_EQ(live.settings().shadowMapSize, rs.shadowMapSize);
  ASSERT_EQ(live.settings().effects.size(), 1u);
  EXPECT_EQ(live.settings().effects[0].settings.integer("blur_radius"), 2);

  // setEffectSettings is reflected in settings(), so applying the old list changes it back.
  live.setEffectSettings("ssao", ssao(0).settings);
  EXPECT_EQ(live.settings().effects[0].settings.integer("blur_radius"), 0);
  live.applySettings(rs);
  EXPECT_TRUE(live.graphRecompiledByLastChange());
  live.renderFrame();
  expectSame(live.readTarget("output"), before, "back to blur radius 2");
}

}  // namespace
}  // namespace gi
