// The engine's own settings, handled like an effect's under the name "engine": defaults are
// RenderSettings', then the preset's "engine" entry, the scene's, and --set engine.key=value,
// with the same validation and messages; "engine" is never taken for an effect. gi-render's
// --exposure is a shorthand for --set engine.exposure and a higher exposure brightens.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "gi/effect_config.h"
#include "gi/engine_settings.h"
#include "gi/errors.h"
#include "gi/image_io.h"
#include "gi/scene_io.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

using test::expectError;

TEST(EngineSettings, DefaultsAreRenderSettingsDefaults) {
  const std::vector<SettingDesc> descs = engineSettingDescs();
  EXPECT_NO_THROW(validateSettingDescs(kEngineSettingsOwner, descs));
  const SettingValues v(kEngineSettingsOwner, descs);
  const RenderSettings d;
  EXPECT_EQ(v.integer("shadow_map_size"), int(d.shadowMapSize));
  EXPECT_EQ(v.integer("pcf_radius"), int(d.pcfRadius));
  EXPECT_DOUBLE_EQ(v.number("exposure"), double(d.exposure));
  EXPECT_DOUBLE_EQ(v.number("environment_intensity"), double(d.environmentIntensity));
  EXPECT_EQ(v.integer("surface_points"), int(d.surfacePoints));
  EXPECT_EQ(v.integer("surface_point_seed"), int(d.surfacePointSeed));
  EXPECT_EQ(engineSettingsOf(d).toJson(), v.toJson());
  std::vector<std::string> graph;
  for (const SettingDesc& s : descs)
    if (s.changesGraph) graph.push_back(s.name);
  EXPECT_EQ(graph,
            (std::vector<std::string>{"shadow_map_size", "surface_points", "surface_point_seed"}));
  const SettingDesc& shadow = v.desc("shadow_map_size");
  EXPECT_EQ(shadow.type, SettingType::Int);
  EXPECT_EQ(shadow.minValue, 16);
  EXPECT_EQ(shadow.maxValue, 8192);
  EXPECT_TRUE(shadow.logScale);
  EXPECT_TRUE(v.desc("exposure").logScale);
  EXPECT_EQ(v.desc("pcf_radius").maxValue, 3);
  EXPECT_EQ(v.desc("environment_intensity").maxValue, 100);
}

TEST(EngineSettings, ApplyAndReadBack) {
  SettingValues v(kEngineSettingsOwner, engineSettingDescs());
  v.setFromString("shadow_map_size", "256", "t");
  v.setFromString("pcf_radius", "0", "t");
  v.setFromString("exposure", "2.5", "t");
  v.setFromString("environment_intensity", "0.25", "t");
  v.setFromString("surface_points", "5000", "t");
  v.setFromString("surface_point_seed", "7", "t");
  RenderSettings s;
  s.width = 17;
  applyEngineSettings(v, s);
  EXPECT_EQ(s.shadowMapSize, 256u);
  EXPECT_EQ(s.pcfRadius, 0u);
  EXPECT_EQ(s.exposure, 2.5f);
  EXPECT_EQ(s.environmentIntensity, 0.25f);
  EXPECT_EQ(s.surfacePoints, 5000u);
  EXPECT_EQ(s.surfacePointSeed, 7u);
  EXPECT_EQ(s.width, 17u);  // not an engine setting: untouched
  EXPECT_EQ(engineSettingsOf(s).toJson(), v.toJson());
  s.shadowMapSize = 4;  // out of the declared range
  expectError([&] { engineSettingsOf(s); }, ErrorKind::InvalidData,
              {"engine.shadow_map_size", "[16, 8192]"});
  const SettingValues other("fx", {});
  expectError([&] { applyEngineSettings(other, s); }, ErrorKind::InvalidData, {"'fx'"});
}

// A real preset file and a real scene file, both with an "engine" entry.
struct Files {
  test::TempDir dir{"engine-settings"};
  std::string presetPath = dir.write("preset.json", R"({
    "name": "p",
    "effects": { "engine": { "shadow_map_size": 512, "pcf_radius": 2, "exposure": 0.5 } }
  })");
  std::string scenePath = dir.write("scene.json", R"({
    "include_default_scene": true,
    "effects": [ { "name": "engine", "settings": { "pcf_radius": 3, "exposure": 0.75 } } ]
  })");
};

TEST(EngineSettings, PrecedencePresetSceneCommandLine) {
  Files f;
  const Preset preset = loadPreset(f.presetPath);
  const Scene scene = loadScene(f.scenePath);
  RenderSettings base;
  base.environmentIntensity = 3.0f;  // the caller's base, below everything else
  EffectRegistry none;
  EffectOverrides cli;
  // "engine" in the scene's effect list is not an effect: no config, no unknown-effect error.
  EXPECT_TRUE(resolveEffects(scene, &preset, cli, none).empty());
  SettingValues v = resolveEngineSettings(scene, &preset, cli, base);
  EXPECT_EQ(v.integer("shadow_map_size"), 512);              // preset over default
  EXPECT_EQ(v.integer("pcf_radius"), 3);                     // scene over preset
  EXPECT_DOUBLE_EQ(v.number("exposure"), 0.75);              // scene over preset
  EXPECT_DOUBLE_EQ(v.number("environment_intensity"), 3.0);  // base kept
  EXPECT_EQ(v.integer("surface_points"), 0);
  cli.sets = {"engine.exposure=2", "engine.shadow_map_size=64", "engine.exposure=4"};
  EXPECT_TRUE(resolveEffects(scene, &preset, cli, none).empty());
  v = resolveEngineSettings(scene, &preset, cli, base);
  EXPECT_DOUBLE_EQ(v.number("exposure"), 4.0);  // --set over scene, the last one wins
  EXPECT_EQ(v.integer("shadow_map_size"), 64);
  EXPECT_EQ(v.integer("pcf_radius"), 3);
  // Without the preset and the scene's entry: the base's values.
  v = resolveEngineSettings(loadScene("default"), nullptr, {}, base);
  EXPECT_EQ(v.toJson(), engineSettingsOf(base).toJson());
}

TEST(EngineSettings, ErrorsNameFileKeyAndRangeLikeAnEffects) {
  Files f;
  const Scene scene = loadScene(f.scenePath);
  EffectRegistry none;
  auto withPreset = [&](const std::string& name, const std::string& text) {
    return [&, name, text] {
      const Preset p = loadPreset(f.dir.write(name, text));
      resolveEffects(scene, &p, {}, none);
    };
  };
  expectError(withPreset("range.json", R"({"effects": {"engine": {"shadow_map_size": 9000}}})"),
              ErrorKind::InvalidData,
              {"range.json", "engine.shadow_map_size", "[16, 8192]", "9000"});
  expectError(withPreset("key.json", R"({"effects": {"engine": {"shadow_size": 512}}})"),
              ErrorKind::Schema,
              {"key.json", "engine.shadow_size", "unknown setting", "shadow_map_size"});
  expectError(withPreset("type.json", R"({"effects": {"engine": {"pcf_radius": "wide"}}})"),
              ErrorKind::Schema, {"type.json", "engine.pcf_radius", "an integer in [0, 3]"});
  const Preset bad =
      loadPreset(f.dir.write("bad.json", R"({"effects": {"engine": {"exposure": 0}}})"));
  expectError([&] { validatePreset(bad, none); }, ErrorKind::InvalidData,
              {"bad.json", "engine.exposure"});
  expectError([&] { resolveEngineSettings(scene, &bad, {}, {}); }, ErrorKind::InvalidData,
              {"bad.json", "engine.exposure", "[0.001, 1000]"});

  const Scene badScene = loadScene(f.dir.write("bad_scene.json",
                                               R"({"include_default_scene": true,
          "effects": [{"name": "engine", "settings": {"environment_intensity": -1}}]})"));
  expectError([&] { resolveEngineSettings(badScene, nullptr, {}, {}); }, ErrorKind::InvalidData,
              {"bad_scene.json", "engine.environment_intensity", "[0, 100]", "-1"});
  expectError([&] { resolveEffects(badScene, nullptr, {}, none); }, ErrorKind::InvalidData,
              {"bad_scene.json", "engine.environment_intensity"});

  EffectOverrides cli;
  cli.sets = {"engine.nope=1"};
  for (const auto& call :
       std::vector<std::function<void()>>{[&] { resolveEngineSettings(scene, nullptr, cli, {}); },
                                          [&] { resolveEffects(scene, nullptr, cli, none); }})
    expectError(call, ErrorKind::Schema,
                {"--set", "engine.nope", "unknown setting",
                 "engine has: shadow_map_size, shadow_cache, shadow_update_period, pcf_radius, "
                 "exposure, environment_intensity, "
                 "surface_points, surface_point_seed"});
  cli.sets = {"engine.surface_points=-5"};
  expectError([&] { resolveEngineSettings(scene, nullptr, cli, {}); }, ErrorKind::InvalidData,
              {"--set", "engine.surface_points", "-5"});
  cli.sets = {"engine.exposure"};
  expectError([&] { resolveEngineSettings(scene, nullptr, cli, {}); }, ErrorKind::Usage,
              {"--set", "effect.setting=value"});
  cli.sets.clear();
  cli.effects = std::vector<std::string>{"engine"};
  expectError([&] { resolveEffects(scene, nullptr, cli, none); }, ErrorKind::Usage,
              {"--effects", "'engine'", "--set engine."});
}

double meanOf(const ImageRGBA8& img) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < img.pixels.size(); i += 4, ++n)
    sum += img.pixels[i] + img.pixels[i + 1] + img.pixels[i + 2];
  return sum / double(3 * n);
}

std::string render(const std::string& out, const std::string& extra) {
  return test::binPath("gi-render") +
         " --validation --width 96 --height 72 --scene default --effects '' --out '" + out + "' " +
         extra;
}

TEST(GiRenderEngineSettings, ExposureBrightensAndTheFlagIsASetShorthand) {
  test::TempDir dir("engine-cli");
  auto r = test::runCommand(render(dir.path("default.png"), ""));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = test::runCommand(render(dir.path("set2.png"), "--set engine.exposure=2"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = test::runCommand(render(dir.path("flag2.png"), "--exposure 2"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  // The flag acts like --set at its place in the order: the later --set wins.
  r = test::runCommand(render(dir.path("back1.png"), "--exposure 2 --set engine.exposure=1"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const ImageRGBA8 base = readPng(dir.path("default.png")), set2 = readPng(dir.path("set2.png"));
  const double m0 = meanOf(base), m2 = meanOf(set2);
  EXPECT_GT(m0, 5.0) << "default image is black";
  EXPECT_GT(m2, m0 * 1.1) << "exposure 2 must brighten: mean " << m2 << " vs " << m0;
  EXPECT_EQ(readPng(dir.path("flag2.png")).pixels, set2.pixels);
  EXPECT_EQ(readPng(dir.path("back1.png")).pixels, base.pixels);
  // The same through a scene file's "engine" entry.
  const std::string scene = dir.write("bright.json", R"({"include_default_scene": true,
                         "effects": [{"name": "engine", "settings": {"exposure": 2}}]})");
  r = test::runCommand(test::binPath("gi-render") +
                       " --validation --width 96 --height 72 --effects '' --scene '" + scene +
                       "' --out '" + dir.path("scene2.png") + "'");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NEAR(meanOf(readPng(dir.path("scene2.png"))), m2, 0.5);
}

TEST(GiRenderEngineSettings, UnknownKeyAndListing) {
  test::TempDir dir("engine-cli-errors");
  auto r = test::runCommand(render(dir.path("x.png"), "--set engine.nope=1"));
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("engine.nope: unknown setting (engine has: shadow_map_size, "
                          "shadow_cache, shadow_update_period, "),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path("x.png")));
  r = test::runCommand(render(dir.path("x.png"), "--exposure 0"));
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("engine.exposure: expected a number in [0.001, 1000], got 0"),
            std::string::npos)
      << r.output;
  r = test::runCommand(test::binPath("gi-render") + " --list-effects");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  for (const char* line :
       {"engine.shadow_map_size (int, default 1024, range [16, 8192], log scale, changes the "
        "graph)",
        "engine.exposure (float, default 1, range [0.001, 1000], log scale, uniform only)",
        "engine.surface_points (int, default 0, range [0, 16777216], changes the graph)"})
    EXPECT_NE(r.output.find(line), std::string::npos) << line << "\n" << r.output;
}

}  // namespace
}  // namespace gi
