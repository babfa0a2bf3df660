// Plugin hot reload (EffectRegistry::reloadModule): a rebuilt module replaces its effects in a
// live renderer, settings that keep their name and type carry over (SettingValues::adopt), and a
// broken rebuild changes nothing and names the file. The two module versions are
// tests/modules/reloadable_module.cpp built twice (AO 0.25, then 0.75).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gi/effect_config.h"
#include "gi/effect_registry.h"
#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

namespace fs = std::filesystem;

std::string testModule(const std::string& name) {
  return std::string(GI_TEST_MODULE_DIR) + "/gi_test_" + name + ".so";
}

// The AO the frame wrote at the centre (the module clears the whole image to one value).
float centreAO(Renderer& r) {
  const ImageRGBA32F ao = r.readTarget(resources::kAO);
  return ao.pixels[(size_t(ao.height / 2) * ao.width + ao.width / 2) * 4];
}

// A rebuild as a linker writes it: a new file at the module's path.
void rebuild(const std::string& from, const std::string& plugin) {
  fs::remove(plugin);
  fs::copy_file(from, plugin);
}

// Files in the plugin's folder and the temporary folder that hold a private copy of it.
size_t privateCopiesLeft(const std::string& plugin) {
  const std::string mark = ".reload-" + std::to_string(getpid()) + "-";
  size_t n = 0;
  for (const fs::path& dir : {fs::path(plugin).parent_path(), fs::temp_directory_path()})
    for (const auto& e : fs::directory_iterator(dir))
      n += e.path().filename().string().find(mark) != std::string::npos;
  return n;
}

class PluginReload : public test::VulkanTest {};

TEST_F(PluginReload, ARebuiltModuleReplacesItsEffectInALiveRenderer) {
  const test::TempDir dir("plugin_reload");
  const std::string plugin = dir.path("gi_effect_reloadable.so");
  fs::copy_file(testModule("reloadable_v1"), plugin);
  EffectRegistry registry;
  registry.scanDirectory(fs::path(plugin).parent_path().string());
  ASSERT_TRUE(registry.has("reloadable")) << "scan of " << plugin;
  EXPECT_EQ(registry.modulePaths(), std::vector<std::string>{plugin});
  EXPECT_EQ(registry.info("reloadable").version, "1");

  const Scene scene = loadScene("default");
  RenderRequest request;
  request.overrides.effects = {"reloadable"};
  request.overrides.sets = {"reloadable.value=0.9", "reloadable.samples=32"};
  RenderSettings base;
  base.width = 32;
  base.height = 24;
  base.keepForReadback = {resources::kAO};
  const RenderSettings rs = configureRender(scene, registry, request, base);
  Renderer renderer(ctx(), scene, rs, &registry);
  renderer.renderFrame();
  EXPECT_NEAR(centreAO(renderer), 0.25f, 1.0f / 255.0f);

  rebuild(testModule("reloadable_v2"), plugin);
  EXPECT_EQ(registry.reloadModule(plugin), std::vector<std::string>{"reloadable"});
  EXPECT_EQ(registry.info("reloadable").version, "2");
  EXPECT_EQ(registry.names(), std::vector<std::string>{"reloadable"});  // replaced, not added
  EXPECT_EQ(privateCopiesLeft(plugin), 0u);
  // The instance made from version 1 keeps running (its code stays mapped) until re-created.
  renderer.renderFrame();
  EXPECT_NEAR(centreAO(renderer), 0.25f, 1.0f / 255.0f);

  // What the user set carries over where the name and type still match.
  SettingValues next = registry.defaultSettings("reloadable");
  EXPECT_EQ(next.adopt(rs.effects[0].settings), std::vector<std::string>{"value"});
  EXPECT_DOUBLE_EQ(next.number("value"), 0.9);
  EXPECT_FALSE(next.flag("samples"));  // an Int before, a Bool now: the new default
  EXPECT_DOUBLE_EQ(next.number("strength"), 1.0);
  renderer.setEffects({});
  renderer.setEffects({{"reloadable", next}});
  renderer.renderFrame();
  EXPECT_NEAR(centreAO(renderer), 0.75f, 1.0f / 255.0f);

  // Broken rebuilds change nothing: the error names the file, version 2 stays registered and
  // can still be created.
  { std::ofstream(plugin, std::ios::trunc) << "half-written"; }
  test::expectError([&] { registry.reloadModule(plugin); }, ErrorKind::InvalidData,
                    {plugin, "cannot load module"});
  rebuild(testModule("bad_abi"), plugin);
  test::expectError([&] { registry.reloadModule(plugin); }, ErrorKind::Unsupported,
                    {plugin, "ABI version"});
  EXPECT_EQ(registry.info("reloadable").version, "2");
  EXPECT_EQ(privateCopiesLeft(plugin), 0u);
  renderer.setEffects({});
  renderer.setEffects({{"reloadable", next}});
  renderer.renderFrame();
  EXPECT_NEAR(centreAO(renderer), 0.75f, 1.0f / 255.0f);

  // Only a loaded module can be reloaded.
  test::expectError([&] { registry.reloadModule(testModule("good_module")); }, ErrorKind::Usage,
                    {"never loaded"});
}

}  // namespace
}  // namespace gi
