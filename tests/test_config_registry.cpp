// The effect registry's refusals: a module built against another ABI version, a duplicate
// effect name, a file that is not a module; scanning a folder loads what it can and reports the
// rest; and gi-render --list-effects shows the in-tree plugins and GI_PLUGIN_PATH's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "gi/effect_registry.h"
#include "gi/errors.h"
#include "process.h"

namespace gi {
namespace {

namespace fs = std::filesystem;

std::string modulePath(const std::string& name) {
  return std::string(GI_TEST_MODULE_DIR) + "/gi_test_" + name + ".so";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Runs `f`, which must throw gi::Error; returns it.
template <class F>
Error thrownBy(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no gi::Error thrown";
  return Error(ErrorKind::Usage, "", "not thrown");
}

TEST(Registry, LoadsAValidModule) {
  EffectRegistry registry;
  registry.loadModule(modulePath("good_module"));
  ASSERT_EQ(registry.names(), std::vector<std::string>{"test_good"});
  EXPECT_EQ(registry.origin("test_good"), modulePath("good_module"));
  EXPECT_EQ(registry.defaultSettings("test_good").number("amount"), 0.5);
  EXPECT_NE(registry.create("test_good"), nullptr);
  EXPECT_TRUE(registry.problems().empty());
}

TEST(Registry, RefusesAModuleBuiltAgainstAnotherAbiVersion) {
  EffectRegistry registry;
  const std::string path = modulePath("bad_abi");
  const Error e = thrownBy([&] { registry.loadModule(path); });
  EXPECT_EQ(e.kind(), ErrorKind::Unsupported);
  EXPECT_EQ(e.file(), path);
  const std::string message = e.what();
  EXPECT_TRUE(contains(message, path)) << message;
  EXPECT_TRUE(contains(message, "ABI version " + std::to_string(GI_EFFECT_ABI_VERSION + 1)))
      << message;
  EXPECT_TRUE(contains(message, "engine's " + std::to_string(GI_EFFECT_ABI_VERSION))) << message;
  EXPECT_TRUE(registry.names().empty()) << "the module's effects must not be registered";
}

TEST(Registry, RefusesADuplicateEffectNameAndStaysUnchanged) {
  EffectRegistry registry;
  const std::string good = modulePath("good_module"), dup = modulePath("duplicate_module");
  registry.loadModule(good);
  const Error e = thrownBy([&] { registry.loadModule(dup); });
  EXPECT_EQ(e.kind(), ErrorKind::InvalidData);
  EXPECT_EQ(e.file(), dup);
  const std::string message = e.what();
  EXPECT_TRUE(contains(message, "duplicate effect 'test_good'")) << message;
  EXPECT_TRUE(contains(message, dup)) << message;   // the module refused
  EXPECT_TRUE(contains(message, good)) << message;  // the one that registered the name first
  // Nothing of the refused module stays: not even the effect it registered before failing.
  EXPECT_EQ(registry.names(), std::vector<std::string>{"test_good"});
  EXPECT_EQ(registry.origin("test_good"), good);
  EXPECT_FALSE(registry.has("test_fresh"));
}

TEST(Registry, RefusesAModuleDuplicatingABuiltInEffect) {
  EffectRegistry registry;
  // Effects can also be registered directly (origin "built-in"); a module may not shadow them.
  registry.add([] {
    struct Builtin : Effect {
      EffectInfo info() const override { return {"test_good", "1", "built in"}; }
      std::vector<SettingDesc> settings() const override { return {}; }
      void prepare(EffectContext&, const SettingValues&) override {}
      void addPasses(FrameGraph&, EffectContext&, const SettingValues&) override {}
    };
    return std::unique_ptr<Effect>(new Builtin());
  });
  const Error e = thrownBy([&] { registry.loadModule(modulePath("good_module")); });
  EXPECT_EQ(e.kind(), ErrorKind::InvalidData);
  const std::string message = e.what();
  EXPECT_TRUE(contains(message, modulePath("good_module"))) << message;
  EXPECT_TRUE(contains(message, "built-in")) << message;
  EXPECT_EQ(registry.origin("test_good"), "built-in");
  EXPECT_EQ(registry.info("test_good").description, "built in");
}

TEST(Registry, AModuleThatThrowsIsRefusedByName) {
  // Whatever its constructor throws (even what is not a std::exception), the app gets an error
  // naming the module, and a scan goes on with the others.
  for (const char* name : {"throws_int", "throws_std"}) {
    EffectRegistry registry;
    const std::string path = modulePath(name);
    const Error e = thrownBy([&] { registry.loadModule(path); });
    EXPECT_EQ(e.kind(), ErrorKind::InvalidData);
    EXPECT_EQ(e.file(), path);
    EXPECT_TRUE(contains(e.what(), "failed while registering its effects")) << e.what();
    if (std::string(name) == "throws_std") {
      EXPECT_TRUE(contains(e.what(), "the GPU is on fire")) << e.what();
    }
    EXPECT_TRUE(registry.names().empty());
  }
  const std::string dir = test::makeTempDir("registry-throwing");
  for (const char* name : {"throws_int", "good_module", "throws_std"})
    fs::copy_file(modulePath(name), dir + "/gi_test_" + std::string(name) + ".so");
  EffectRegistry registry;
  registry.scanDirectory(dir);
  EXPECT_EQ(registry.names(), std::vector<std::string>{"test_good"});
  EXPECT_EQ(registry.problems().size(), 2u);
}

TEST(Registry, TruncatedModulesAndLinkLoopsAreRefusedNotFatal) {
  // A module cut short (as while a build writes it) would fault (SIGBUS) once mapped: refused
  // before dlopen. A link loop and a dangling link in the folder are not modules.
  const std::string dir = test::makeTempDir("registry-truncated");
  const std::string good = modulePath("good_module"), cut = dir + "/gi_test_cut.so";
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 4096u);
  for (const size_t keep : {size_t(64 + 56), bytes.size() / 2, bytes.size() - 1}) {
    std::ofstream(cut, std::ios::binary | std::ios::trunc)
        .write(bytes.data(), std::streamsize(keep));
    EffectRegistry registry;
    const Error e = thrownBy([&] { registry.loadModule(cut); });
    EXPECT_EQ(e.file(), cut);
    EXPECT_TRUE(contains(e.what(), "truncated module") || contains(e.what(), "cannot load"))
        << keep << " bytes: " << e.what();
  }
  fs::create_symlink(dir + "/loop_b.so", dir + "/loop_a.so");
  fs::create_symlink(dir + "/loop_a.so", dir + "/loop_b.so");
  fs::create_symlink(dir + "/missing.so", dir + "/dangling.so");
  fs::copy_file(good, dir + "/gi_test_good_module.so");
  EffectRegistry registry;
  registry.scanDirectory(dir);
  EXPECT_EQ(registry.names(), std::vector<std::string>{"test_good"});
  ASSERT_EQ(registry.problems().size(), 1u);  // the truncated one
  EXPECT_TRUE(contains(registry.problems()[0], "gi_test_cut.so")) << registry.problems()[0];
}

TEST(Registry, RefusesLoadingTheSameModuleTwice) {
  EffectRegistry registry;
  registry.loadModule(modulePath("good_module"));
  const Error e = thrownBy([&] { registry.loadModule(modulePath("good_module")); });
  EXPECT_TRUE(contains(e.what(), "already loaded")) << e.what();
  EXPECT_EQ(registry.names().size(), 1u);
}

TEST(Registry, RefusesFilesThatAreNotModules) {
  EffectRegistry registry;
  // A shared library without the entry points.
  const std::string lib = modulePath("not_a_module");
  Error e = thrownBy([&] { registry.loadModule(lib); });
  EXPECT_EQ(e.kind(), ErrorKind::InvalidData);
  EXPECT_EQ(e.file(), lib);
  EXPECT_TRUE(contains(e.what(), "not an effect module")) << e.what();
  EXPECT_TRUE(contains(e.what(), "gi_effect_abi_version")) << e.what();

  // Not a shared library at all.
  const std::string dir = test::makeTempDir("registry-junk");
  const std::string junk = dir + "/junk.so";
  std::ofstream(junk) << "this is not an ELF file\n";
  e = thrownBy([&] { registry.loadModule(junk); });
  EXPECT_EQ(e.kind(), ErrorKind::InvalidData);
  EXPECT_EQ(e.file(), junk);
  EXPECT_TRUE(contains(e.what(), "cannot load module")) << e.what();

  // Missing.
  e = thrownBy([&] { registry.loadModule(dir + "/missing.so"); });
  EXPECT_TRUE(contains(e.what(), dir + "/missing.so")) << e.what();
  EXPECT_TRUE(registry.names().empty());
  fs::remove_all(dir);
}

// A folder with one good module, one of another ABI and a file that is no module.
std::string mixedFolder(const std::string& name) {
  const std::string dir = test::makeTempDir(name);
  fs::copy_file(modulePath("good_module"), dir + "/a_good.so");
  fs::copy_file(modulePath("bad_abi"), dir + "/b_bad_abi.so");
  std::ofstream(dir + "/c_junk.so") << "junk";
  std::ofstream(dir + "/readme.txt") << "not a .so: ignored";
  return dir;
}

TEST(Registry, ScanLoadsTheGoodModulesAndReportsTheOthers) {
  const std::string dir = mixedFolder("registry-scan");
  EffectRegistry registry;
  registry.scanDirectory(dir);
  EXPECT_EQ(registry.names(), std::vector<std::string>{"test_good"});
  EXPECT_EQ(registry.origin("test_good"), dir + "/a_good.so");
  ASSERT_EQ(registry.problems().size(), 2u);
  EXPECT_TRUE(contains(registry.problems()[0], dir + "/b_bad_abi.so"));
  EXPECT_TRUE(contains(registry.problems()[0], "ABI version"));
  EXPECT_TRUE(contains(registry.problems()[1], dir + "/c_junk.so"));
  const std::string listing = registry.describe();
  EXPECT_TRUE(contains(listing, "refused: " + dir + "/b_bad_abi.so")) << listing;
  // A missing folder is skipped quietly.
  registry.scanDirectory(dir + "/missing");
  EXPECT_EQ(registry.problems().size(), 2u);
  fs::remove_all(dir);
}

TEST(Registry, GiRenderListsPluginsFromGiPluginPath) {
  const std::string dir = mixedFolder("registry-plugin-path");
  const test::ProcessResult r = test::runCommand(
      "GI_PLUGIN_PATH=" + dir + " " + std::string(GI_BIN_DIR) + "/gi-render --list-effects");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\ntest_good 1 - registry test effect\n") ||
              r.output.rfind("test_good 1 - registry test effect\n", 0) == 0)
      << r.output;
  EXPECT_TRUE(contains(r.output, "  module: " + dir + "/a_good.so\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "  test_good.amount (float, default 0.5, range [0, 1]"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "refused: " + dir + "/b_bad_abi.so")) << r.output;
  EXPECT_TRUE(contains(r.output, "refused: " + dir + "/c_junk.so")) << r.output;
  fs::remove_all(dir);
}

TEST(Registry, DescribesEachDeclaredQuantityWithTheParametersItUses) {
  using K = EstimatedQuantity::Kind;
  EstimatedQuantity q;
  q.radius = 0.25;
  q.membership = "smoothstep";
  q.kind = K::AmbientOcclusion;
  EXPECT_EQ(describe(q), "ao(r=0.25)");  // no membership: AO has none
  q.kind = K::Obscurance;
  EXPECT_EQ(describe(q), "obscurance(r=0.25, membership=smoothstep)");
  q.kind = K::Alchemy;
  q.epsilon = 1e-8;
  EXPECT_EQ(describe(q), "alchemy(r=0.25, sigma=1, u=0, epsilon=1e-08, contrast=1)");
  q.kind = K::AlchemyDisk;  // the hemisphere form has no bias, the disk form does
  q.bias = 2e-4;
  EXPECT_EQ(describe(q),
            "alchemy-disk(r=0.25, sigma=1, u=0, epsilon=1e-08, contrast=1, bias=0.0002)");
  q.kind = K::DirectIndirect;
  EXPECT_EQ(describe(q), "direct+indirect light");
  q.kind = K::DirectLight;
  EXPECT_EQ(describe(q), "direct light");
}

TEST(Registry, GiRenderListsTheInTreeSsaoPlugin) {
  const std::string ssao = std::string(GI_BIN_DIR) + "/plugins/gi_effect_ssao.so";
  if (!fs::exists(ssao)) GTEST_SKIP() << "no ssao module built (" << ssao << ")";
  const test::ProcessResult r = test::runCommand(
      "env -u GI_PLUGIN_PATH " + std::string(GI_BIN_DIR) + "/gi-render --list-effects");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(r.output.rfind("ssao ", 0) == 0 || contains(r.output, "\nssao ")) << r.output;
  EXPECT_TRUE(contains(r.output, "  module: " + fs::weakly_canonical(ssao).string()) ||
              contains(r.output, "  module: " + ssao))
      << r.output;
  EXPECT_TRUE(contains(r.output, "  ssao.")) << "ssao's settings are listed\n" << r.output;
  // Its exact quantity with the parameters of its defaults (radius 0.5, linear falloff).
  EXPECT_TRUE(
      contains(r.output, "  declares at its defaults: obscurance(r=0.5, membership=linear)"))
      << r.output;
  EXPECT_FALSE(contains(r.output, "refused:")) << r.output;
}

}  // namespace
}  // namespace gi
