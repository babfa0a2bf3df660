// Effects in the frame: settings precedence (defaults < preset < scene < --set) with errors
// that name the file, key and range; the exact passes a scene's effect list executes; and
// uniform-only settings that do not recompile the graph.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "gi/effect.h"
#include "gi/effect_config.h"
#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

// Writes a constant AO with a clear (no shader needed): enough to exercise the graph.
class ConstantAO : public Effect {
 public:
  EffectInfo info() const override {
    return {"const_ao", "1", "constant ambient occlusion (test)", EffectStage::BeforeLighting, {},
            {"ao"},     "ao"};
  }
  std::vector<SettingDesc> settings() const override {
    return {{"value", SettingType::Float, 0.5, 0.0, 1.0, "AO value", false},
            {"samples", SettingType::Int, 8, 1, 64, "pretend sample count", false},
            {"half_res", SettingType::Bool, 0, 0, 1, "render at half resolution", true}};
  }
  void prepare(EffectContext&, const SettingValues&) override { ++prepares; }
  void addPasses(FrameGraph& g, EffectContext&, const SettingValues& s) override {
    auto ao = std::make_shared<TextureHandle>();
    const SettingValues* values = &s;  // read at execute time: uniform-only changes apply
    g.addPass(
        "const_ao",
        [&](PassBuilder& b) {
          TextureDesc d{VK_FORMAT_R8G8B8A8_UNORM};
          d.scale = s.flag("half_res") ? 0.5f : 1.0f;
          *ao = b.write(b.create("ao", d), TextureUsage::TransferDst);
        },
        [ao, values](PassContext& pc) {
          const float v = float(values->number("value"));
          VkClearColorValue c{{v, v, v, 1.0f}};
          VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
          vkCmdClearColorImage(pc.cmd(), pc.image(*ao), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &c, 1,
                               &range);
        });
    g.blackboard().put("ao", *ao);
  }
  static inline int prepares = 0;
};

// Produces something nobody reads: requested, but its pass must be culled.
class Orphan : public Effect {
 public:
  EffectInfo info() const override {
    return {"orphan",   "1",     "output nobody reads (test)", EffectStage::AfterLighting, {"lit"},
            {"orphan"}, "orphan"};
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext&, const SettingValues&) override {}
  void addPasses(FrameGraph& g, EffectContext&, const SettingValues&) override {
    TextureHandle out;
    g.addPass(
        "orphan",
        [&](PassBuilder& b) {
          b.read(g.blackboard().texture("lit"));
          out = b.write(b.create("orphan", TextureDesc{VK_FORMAT_R8G8B8A8_UNORM}),
                        TextureUsage::TransferDst);
        },
        [](PassContext&) {});
    g.blackboard().put("orphan", out);
  }
};

EffectRegistry testRegistry() {
  EffectRegistry r;
  r.add([] { return std::make_unique<ConstantAO>(); }, "test");
  r.add([] { return std::make_unique<Orphan>(); }, "test");
  return r;
}

std::string writeFile(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

Scene sceneWith(std::vector<EffectRequest> effects) {
  Scene s = loadScene("default");
  s.sourcePath = "scene.json";
  s.effects = std::move(effects);
  return s;
}

TEST(EffectConfig, PrecedenceDefaultsPresetSceneCommandLine) {
  EffectRegistry reg = testRegistry();
  const std::string dir = test::makeTempDir("precedence");
  Preset preset = loadPreset(
      writeFile(dir, "p.json", R"({"effects": {"const_ao": {"value": 0.2, "samples": 16}}})"));
  Scene scene = sceneWith({{"const_ao", {{"samples", 32}}}});
  auto configs = resolveEffects(scene, &preset, {}, reg);
  ASSERT_EQ(configs.size(), 1u);
  EXPECT_DOUBLE_EQ(configs[0].settings.number("value"), 0.2);  // preset over default
  EXPECT_EQ(configs[0].settings.integer("samples"), 32);       // scene over preset
  EffectOverrides cli;
  cli.sets = {"const_ao.samples=64", "const_ao.half_res=true"};
  configs = resolveEffects(scene, &preset, cli, reg);
  EXPECT_EQ(configs[0].settings.integer("samples"), 64);  // command line over scene
  EXPECT_TRUE(configs[0].settings.flag("half_res"));
  cli.sets.clear();
  cli.effects = std::vector<std::string>{};  // --effects '' runs none
  EXPECT_TRUE(resolveEffects(scene, &preset, cli, reg).empty());
}

TEST(EffectConfig, RecommendedEffectsComeFromThePreset) {
  EffectRegistry reg = testRegistry();
  const std::string dir = test::makeTempDir("recommended");
  const Preset preset = loadPreset(writeFile(
      dir, "p.json",
      R"({"recommended_effects": ["orphan", "const_ao"], "effects": {"const_ao": {"value": 0.2}}})"));
  const Scene scene = sceneWith({{"const_ao", {}}});
  EffectOverrides cli;
  cli.effects = std::vector<std::string>{"recommended"};
  const auto configs = resolveEffects(scene, &preset, cli, reg);
  ASSERT_EQ(configs.size(), 2u);
  EXPECT_EQ(configs[0].name, "orphan");
  EXPECT_EQ(configs[1].name, "const_ao");
  EXPECT_DOUBLE_EQ(configs[1].settings.number("value"), 0.2);  // with the preset's settings
  // Without a preset, or with one that recommends nothing: a usage error naming why.
  test::expectError([&] { resolveEffects(scene, nullptr, cli, reg); }, ErrorKind::Usage,
                    {"--effects", "give --preset"});
  const Preset none = loadPreset(writeFile(dir, "none.json", R"({"effects": {}})"));
  test::expectError([&] { resolveEffects(scene, &none, cli, reg); }, ErrorKind::Usage,
                    {"none.json", "recommends no effects"});
  // A preset that recommends an unknown effect, or not a list of names, names its file.
  const Preset unknown =
      loadPreset(writeFile(dir, "unknown.json", R"({"recommended_effects": ["nope"]})"));
  test::expectError([&] { resolveEffects(scene, &unknown, {}, reg); }, ErrorKind::Schema,
                    {"unknown.json", "recommended_effects", "nope"});
  for (const char* bad : {R"({"recommended_effects": "gtao"})", R"({"recommended_effects": []})",
                          R"({"recommended_effects": [1]})"})
    test::expectError([&] { loadPreset(writeFile(dir, "bad.json", bad)); }, ErrorKind::Schema,
                      {"bad.json", "recommended_effects"});
}

TEST(EffectConfig, WorldLengthDefaultsFollowABareModelsSize) {
  // The real plugins' radii are world lengths: a model loaded without a scene file (the
  // 2CylinderEngine glTF, hundreds of units across) scales their defaults by its size; the
  // built-in room and scene files keep them. A preset's lengths are for the reference size too
  // (presets are written for no scene in particular) and scale with them; scene-file and --set
  // values are in the scene's own units and are not scaled.
  EffectRegistry reg;
  reg.scanDirectory(test::binPath("plugins"));
  EffectOverrides cli;
  cli.effects = std::vector<std::string>{"ssao"};
  const Scene room = loadScene("default");
  EXPECT_EQ(room.lengthScale, 1.0f);
  EXPECT_DOUBLE_EQ(resolveEffects(room, nullptr, cli, reg)[0].settings.number("radius"), 0.5);

  const Scene model =
      loadScene(test::assimpModel("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"));
  glm::vec3 lo, hi;
  model.worldBounds(lo, hi);
  const float scale = glm::length(hi - lo) / kReferenceSceneDiagonal;
  EXPECT_FLOAT_EQ(model.lengthScale, scale);
  ASSERT_GT(scale, 10.0f) << "the engine model is hundreds of units across";
  EXPECT_NEAR(resolveEffects(model, nullptr, cli, reg)[0].settings.number("radius"), 0.5 * scale,
              1e-6 * scale);
  const std::string dir = test::makeTempDir("preset-lengths");
  const Preset preset = loadPreset(
      writeFile(dir, "p.json", R"({"effects": {"ssao": {"radius": 0.3, "samples": 8}}})"));
  EXPECT_DOUBLE_EQ(resolveEffects(room, &preset, cli, reg)[0].settings.number("radius"), 0.3);
  EXPECT_NEAR(resolveEffects(model, &preset, cli, reg)[0].settings.number("radius"), 0.3 * scale,
              1e-6 * scale);
  EXPECT_EQ(resolveEffects(model, &preset, cli, reg)[0].settings.integer("samples"), 8);
  cli.sets = {"ssao.radius=0.25"};
  EXPECT_DOUBLE_EQ(resolveEffects(model, nullptr, cli, reg)[0].settings.number("radius"), 0.25);
  EXPECT_DOUBLE_EQ(resolveEffects(model, &preset, cli, reg)[0].settings.number("radius"), 0.25);
  // Only Float settings marked as lengths scale: the tap count does not.
  EXPECT_EQ(resolveEffects(model, nullptr, cli, reg)[0].settings.integer("samples"),
            reg.defaultSettings("ssao").integer("samples"));
}

using test::expectError;

TEST(EffectConfig, ConfigureRenderIsTheWholeSetUp) {
  // One call from (scene, preset, --effects, --set, view) to the frame's settings: what every
  // app and the effect tests' fixture do.
  EffectRegistry reg = testRegistry();
  const std::string dir = test::makeTempDir("configure");
  RenderRequest request;
  request.preset = writeFile(dir, "p.json", R"({"effects": {"const_ao": {"value": 0.2},
      "engine": {"exposure": 2, "shadow_map_size": 256}}})");
  request.overrides.sets = {"const_ao.samples=64", "engine.exposure=3"};
  request.view = "orphan";  // an effect's name: its debug view
  Scene scene = sceneWith({{"const_ao", {{"samples", 32}}}, {"orphan", {}}});
  scene.effects.push_back({"engine", {{"pcf_radius", 2}}});
  RenderSettings base;
  base.width = 123;
  base.keepForReadback = {"ao"};
  const RenderSettings rs = configureRender(scene, reg, request, base);
  ASSERT_EQ(rs.effects.size(), 2u);
  EXPECT_EQ(rs.effects[0].name, "const_ao");
  EXPECT_DOUBLE_EQ(rs.effects[0].settings.number("value"), 0.2);  // preset
  EXPECT_EQ(rs.effects[0].settings.integer("samples"), 64);       // --set over the scene
  EXPECT_FLOAT_EQ(rs.exposure, 3.0f);                             // --set over the preset
  EXPECT_EQ(rs.shadowMapSize, 256u);                              // preset
  EXPECT_EQ(rs.pcfRadius, 2u);                                    // scene
  EXPECT_EQ(rs.view, "orphan");
  EXPECT_EQ(rs.width, 123u);  // the caller's own fields are kept
  EXPECT_EQ(rs.keepForReadback, std::vector<std::string>{"ao"});
  request.view = "lit";  // a resource stays itself
  EXPECT_EQ(configureRender(scene, reg, request).view, "lit");
  request.preset = dir + "/missing.json";
  expectError([&] { configureRender(scene, reg, request); }, ErrorKind::FileNotFound,
              {"missing.json"});
}

TEST(EffectConfig, BadPresetsAndSettingsNameFileKeyAndRange) {
  EffectRegistry reg = testRegistry();
  const std::string dir = test::makeTempDir("bad-presets");
  Scene scene = sceneWith({{"const_ao", {}}});
  auto withPreset = [&](const std::string& name, const std::string& text) {
    return [&, name, text] {
      Preset p = loadPreset(writeFile(dir, name, text));
      resolveEffects(scene, &p, {}, reg);
    };
  };
  expectError(withPreset("unknown_effect.json", R"({"effects": {"nope": {}}})"), ErrorKind::Schema,
              {"unknown_effect.json", "effects.nope", "unknown effect"});
  expectError(withPreset("unknown_setting.json", R"({"effects": {"const_ao": {"colour": 1}}})"),
              ErrorKind::Schema, {"unknown_setting.json", "const_ao.colour", "unknown setting"});
  expectError(withPreset("wrong_type.json", R"({"effects": {"const_ao": {"samples": "many"}}})"),
              ErrorKind::Schema, {"wrong_type.json", "const_ao.samples", "an integer in [1, 64]"});
  expectError(withPreset("range.json", R"({"effects": {"const_ao": {"samples": 65}}})"),
              ErrorKind::InvalidData, {"range.json", "const_ao.samples", "[1, 64]", "65"});
  expectError(withPreset("fraction.json", R"({"effects": {"const_ao": {"samples": 2.5}}})"),
              ErrorKind::Schema, {"fraction.json", "an integer"});
  expectError(withPreset("top_key.json", R"({"effectz": {}})"), ErrorKind::Schema,
              {"top_key.json", "effectz"});
  expectError(withPreset("bad_json.json", R"({"effects": )"), ErrorKind::Parse, {"bad_json.json"});
  expectError(withPreset("empty.json", ""), ErrorKind::EmptyFile, {"empty.json"});
  expectError([&] { loadPreset("no-such-preset-anywhere"); }, ErrorKind::FileNotFound,
              {"no-such-preset-anywhere"});
  // The input standard of every file (gi/input_file.h): named as what it is, never read on.
  std::filesystem::create_directories(dir + "/folder.json");
  expectError([&] { loadPreset(dir + "/folder.json"); }, ErrorKind::FileNotFound,
              {"folder.json", "is a directory, not a preset file"});
  std::filesystem::create_symlink("/dev/zero", dir + "/zero.json");
  expectError([&] { loadPreset(dir + "/zero.json"); }, ErrorKind::FileNotFound,
              {"zero.json", "is not a regular file"});
  expectError([&] { parsePreset(R"({"target_ms": 1e400})", "huge.json"); }, ErrorKind::InvalidData,
              {"huge.json", "number '1e400' is out of range"});
  EXPECT_EQ(parsePreset(R"({"name": "n", "target_ms": 16})", "p.json").targetMs, 16.0);

  Scene badScene = sceneWith({{"const_ao", {{"value", 7}}}});
  expectError([&] { resolveEffects(badScene, nullptr, {}, reg); }, ErrorKind::InvalidData,
              {"scene.json", "const_ao.value", "[0, 1]"});
  Scene unknown = sceneWith({{"ssao_typo", {}}});
  expectError([&] { resolveEffects(unknown, nullptr, {}, reg); }, ErrorKind::Schema,
              {"scene.json", "ssao_typo", "const_ao"});
  EffectOverrides cli;
  cli.sets = {"const_ao.samples"};
  expectError([&] { resolveEffects(scene, nullptr, cli, reg); }, ErrorKind::Usage,
              {"--set", "effect.setting=value"});
  cli.sets = {"orphan.x=1"};
  expectError([&] { resolveEffects(scene, nullptr, cli, reg); }, ErrorKind::Usage,
              {"--set", "not enabled"});
  cli.sets = {"const_ao.value=abc"};
  expectError([&] { resolveEffects(scene, nullptr, cli, reg); }, ErrorKind::Schema,
              {"--set", "const_ao.value"});
  Scene twice = sceneWith({{"const_ao", {}}, {"const_ao", {}}});
  expectError([&] { resolveEffects(twice, nullptr, {}, reg); }, ErrorKind::Schema,
              {"listed twice"});
}

class EffectGraphTest : public test::VulkanTest {
 protected:
  std::unique_ptr<Renderer> make(const Scene& scene, const std::vector<std::string>& effects,
                                 const std::string& view = "output") {
    EffectOverrides cli;
    cli.effects = effects;
    RenderSettings rs;
    rs.width = 64;
    rs.height = 48;
    rs.view = view;
    rs.effects = resolveEffects(scene, nullptr, cli, registry);
    return std::make_unique<Renderer>(ctx(), scene, rs, &registry);
  }
  EffectRegistry registry = testRegistry();
  Scene scene = sceneWith({});
};

using Passes = std::vector<std::string>;

TEST_F(EffectGraphTest, NoEffectsRunsOnlyTheEnginePasses) {
  auto r = make(scene, {});
  r->renderFrame();
  // The default scene's ceiling light casts shadows: one shadow pass, read by lighting.
  EXPECT_EQ(r->passNames(), (Passes{"gbuffer", "shadow_0", "lighting", "tonemap"}));
  // Culled: the G-buffer's unpacking passes (no channel is read) and the floor.
  EXPECT_EQ(r->culledPassNames(), (Passes{"gbuffer_normal", "gbuffer_albedo", "gbuffer_material",
                                          "gbuffer_emission", "floor"}));
}

TEST_F(EffectGraphTest, AnAOEffectFeedsLighting) {
  auto r = make(scene, {"const_ao"});
  r->renderFrame();
  EXPECT_EQ(r->passNames(), (Passes{"gbuffer", "shadow_0", "const_ao", "lighting", "tonemap"}));
}

TEST_F(EffectGraphTest, RequestedEffectWhoseOutputReachesNothingIsCulled) {
  auto r = make(scene, {"const_ao", "orphan"});
  r->renderFrame();
  EXPECT_EQ(r->passNames(), (Passes{"gbuffer", "shadow_0", "const_ao", "lighting", "tonemap"}));
  EXPECT_EQ(r->culledPassNames(), (Passes{"gbuffer_normal", "gbuffer_albedo", "gbuffer_material",
                                          "gbuffer_emission", "orphan", "floor"}));
  // Said, naming it: an enabled effect that runs no pass costs nothing but does nothing.
  ASSERT_EQ(r->warnings().size(), 1u);
  EXPECT_NE(r->warnings()[0].find("effect 'orphan' runs no pass"), std::string::npos)
      << r->warnings()[0];
  EXPECT_TRUE(make(scene, {"const_ao"})->warnings().empty());
  // Which effect reaches the image, as --print-graph and the demo panel show it.
  const auto effects = r->effectPasses();
  ASSERT_EQ(effects.size(), 2u);
  EXPECT_EQ(effects[0].effect, "const_ao");
  EXPECT_EQ(effects[0].run, 1u);
  EXPECT_EQ(effects[1].effect, "orphan");
  EXPECT_EQ(effects[1].run, 0u);
  EXPECT_EQ(effects[1].total, 1u);
  EXPECT_NE(r->graphDescription().find("orphan: 0 of 1 passes run (reaches nothing: culled)"),
            std::string::npos)
      << r->graphDescription();
}

TEST_F(EffectGraphTest, EffectsThatWouldEraseEachOtherAreRefusedNamingBoth) {
  // Two writers of "ao" where the second does not read it: the first's passes would be culled.
  EffectRegistry reg = testRegistry();
  struct Ambient : Effect {  // replaces the environment term that "ao" multiplies
    EffectInfo info() const override {
      return {"const_ambient",
              "1",
              "constant environment term (test)",
              EffectStage::BeforeLighting,
              {},
              {"ambient"},
              "ambient"};
    }
    std::vector<SettingDesc> settings() const override { return {}; }
    void prepare(EffectContext&, const SettingValues&) override {}
    void addPasses(FrameGraph& g, EffectContext&, const SettingValues&) override {
      g.addPass(
          "const_ambient",
          [&](PassBuilder& b) {
            out_ = b.write(b.create("ambient", TextureDesc{VK_FORMAT_R16G16B16A16_SFLOAT}),
                           TextureUsage::TransferDst);
          },
          [this](PassContext& pc) {
            const VkClearColorValue c{.float32 = {0.25f, 0.25f, 0.25f, 1.0f}};
            const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdClearColorImage(pc.cmd(), pc.image(out_), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &c,
                                 1, &all);
          });
      g.blackboard().put("ambient", out_);
    }
    TextureHandle out_;  // read by the recording, after addPasses returned
  };
  reg.add([] { return std::make_unique<Ambient>(); }, "test");
  const Scene scene = loadScene("default");
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  // Alone, each renders.
  rs.effects = {{"const_ambient", reg.defaultSettings("const_ambient")}};
  Renderer(ctx(), scene, rs, &reg).renderFrame();
  // Together, the environment term const_ao would darken is replaced: refused, both named.
  rs.effects.push_back({"const_ao", reg.defaultSettings("const_ao")});
  test::expectError([&] { Renderer(ctx(), scene, rs, &reg); }, ErrorKind::Usage,
                    {"effect 'const_ambient' writes 'ambient' (replaces the environment term)",
                     "'const_ao''s 'ao' (multiplies the environment term)", "reach nothing"});
  // Switched in live, refused; the renderer keeps what it had.
  rs.effects.pop_back();
  Renderer live(ctx(), scene, rs, &reg);
  test::expectError(
      [&] {
        live.setEffects({{"const_ao", reg.defaultSettings("const_ao")},
                         {"const_ambient", reg.defaultSettings("const_ambient")}});
      },
      ErrorKind::Usage, {"'const_ambient'", "'const_ao'"});
  live.renderFrame();
  EXPECT_EQ(live.settings().effects.size(), 1u);
}

TEST_F(EffectGraphTest, DebugViewKeepsOnlyWhatFeedsIt) {
  auto r = make(scene, {"const_ao"}, "ao");
  r->renderFrame();
  EXPECT_EQ(r->passNames(), (Passes{"const_ao"}));
  ImageRGBA32F ao = r->readTarget("ao");
  EXPECT_NEAR(ao.pixels[0], 0.5f, 1.0f / 255);
}

TEST_F(EffectGraphTest, AOTermDarkensTheAmbientLight) {
  auto lit = [&](double value) {
    auto r = make(scene, {"const_ao"});
    SettingValues s = registry.defaultSettings("const_ao");
    s.set("value", value, "test");
    r->setEffectSettings("const_ao", s);
    r->renderFrame();
    ImageRGBA32F img = r->readTarget("lit");
    double sum = 0;
    for (size_t i = 0; i < img.pixels.size(); i += 4) sum += img.pixels[i + 1];
    return sum;
  };
  EXPECT_LT(lit(0.0), lit(1.0) * 0.99) << "AO 0 must remove the ambient term";
}

TEST_F(EffectGraphTest, UniformOnlySettingsDoNotRecompile) {
  auto r = make(scene, {"const_ao"});
  r->renderFrame();
  const int preparesBefore = ConstantAO::prepares;
  SettingValues s = registry.defaultSettings("const_ao");
  s.set("value", 0.9, "test");
  r->setEffectSettings("const_ao", s);
  EXPECT_FALSE(r->graphRecompiledByLastChange());
  EXPECT_EQ(ConstantAO::prepares, preparesBefore);
  r->renderFrame();
  EXPECT_NEAR(r->readTarget("ao").pixels[0], 0.9f, 1.0f / 255);
  s.set("half_res", true, "test");
  r->setEffectSettings("const_ao", s);
  EXPECT_TRUE(r->graphRecompiledByLastChange());
  EXPECT_EQ(ConstantAO::prepares, preparesBefore + 1);
  r->renderFrame();
  EXPECT_EQ(r->readTarget("ao").width, 32);
}

// Plugin code that throws, of any type, in any call the renderer makes: a gi::Error naming the
// effect and the call, and the renderer keeps its previous configuration and goes on.
class Thrower : public Effect {
 public:
  EffectInfo info() const override {
    return {"thrower",        "1", "throws where told (test)", EffectStage::BeforeLighting, {},
            {resources::kAO}, ""};
  }
  std::vector<SettingDesc> settings() const override {
    SettingDesc where =
        SettingDesc::enumeration("where", {"nowhere", "prepare", "addPasses", "update", "record"},
                                 0, "where it throws", true);
    return {where, {"an_int", SettingType::Bool, 0, 0, 1, "throw an int", true}};
  }
  void prepare(EffectContext&, const SettingValues& s) override { maybeThrow(s, "prepare"); }
  void addPasses(FrameGraph& graph, EffectContext&, const SettingValues& s) override {
    maybeThrow(s, "addPasses");
    if (s.option("where") != "record") return;
    // A pass that feeds the lighting (so it is not culled) and throws as it records.
    auto out = std::make_shared<TextureHandle>();
    graph.addPass(
        "thrower_pass",
        [&](PassBuilder& b) {
          *out = b.write(b.create("thrower_ao", TextureDesc{VK_FORMAT_R8_UNORM}),
                         TextureUsage::StorageWrite);
        },
        [values = &s](PassContext&) { maybeThrow(*values, "record"); });
    graph.blackboard().put(resources::kAO, *out);
  }
  void update(EffectContext&, const SettingValues& s) override { maybeThrow(s, "update"); }

 private:
  static void maybeThrow(const SettingValues& s, const std::string& call) {
    if (s.option("where") != call) return;
    if (s.flag("an_int")) throw 42;
    throw std::runtime_error("out of cheese");
  }
};

TEST_F(EffectGraphTest, AnEffectThatThrowsIsAnErrorNamingItAndTheCall) {
  EffectRegistry reg = testRegistry();
  reg.add([] { return std::make_unique<Thrower>(); }, "test");
  const Scene scene = loadScene("default");
  auto config = [&](const std::string& where, bool anInt) {
    SettingValues v = reg.defaultSettings("thrower");
    v.set("where", where, "test");
    v.set("an_int", anInt, "test");
    return EffectConfig{"thrower", v};
  };
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  for (const bool anInt : {false, true}) {
    const std::string why = anInt ? "not a std::exception" : "out of cheese";
    rs.effects = {config("prepare", anInt)};
    test::expectError([&] { Renderer(ctx(), scene, rs, &reg); }, ErrorKind::InvalidData,
                      {"effect 'thrower' failed in prepare()", why});
    rs.effects = {config("addPasses", anInt)};
    test::expectError([&] { Renderer(ctx(), scene, rs, &reg); }, ErrorKind::InvalidData,
                      {"effect 'thrower' failed in addPasses()", why});
    rs.effects = {config("update", anInt)};
    Renderer updating(ctx(), scene, rs, &reg);
    test::expectError([&] { updating.renderFrame(); }, ErrorKind::InvalidData,
                      {"effect 'thrower' failed in update()", why});
    // Switched in live, it is refused and the renderer keeps what it had.
    rs.effects = {{"const_ao", reg.defaultSettings("const_ao")}};
    Renderer live(ctx(), scene, rs, &reg);
    live.renderFrame();
    test::expectError([&] { live.setEffects({config("prepare", anInt)}); }, ErrorKind::InvalidData,
                      {"failed in prepare()"});
    test::expectError([&] { live.setEffects({config("addPasses", anInt)}); },
                      ErrorKind::InvalidData, {"failed in addPasses()"});
    live.renderFrame();
    EXPECT_EQ(live.settings().effects.size(), 1u);
    EXPECT_EQ(live.settings().effects[0].name, "const_ao");
    // A pass of the effect that throws while it records: an EffectError naming the effect
    // (what an app needs to turn it off), the pass and why, every frame it stays on; once it is
    // off, the same renderer draws again (validation clean: nothing half-recorded remains).
    rs.effects = {config("record", anInt)};
    Renderer recording(ctx(), scene, rs, &reg);
    for (int frame = 0; frame < 2; ++frame) {
      try {
        recording.renderFrame();
        ADD_FAILURE() << "a pass that throws while recording did not fail the frame";
      } catch (const EffectError& e) {
        EXPECT_EQ(e.effect(), "thrower");
        const std::string what = e.what();
        EXPECT_NE(what.find("effect 'thrower', pass 'thrower_pass' failed while recording: "),
                  std::string::npos)
            << what;
        EXPECT_NE(what.find(why), std::string::npos) << what;
      }
    }
    recording.setEffects({{"const_ao", reg.defaultSettings("const_ao")}});
    recording.renderFrame();
    EXPECT_NEAR(recording.readTarget("ao").pixels[0], 0.5f, 1.0f / 255);  // const_ao's default
  }
}

TEST_F(EffectGraphTest, ReadingWhatNobodyPublishedNamesTheEffectPassAndResource) {
  // An effect that declares and looks up a resource no pass publishes: the error says which
  // effect, which pass and which name, not just "invalid resource handle".
  struct Reader : Effect {
    EffectInfo info() const override {
      return {
          "reader", "1", "reads what nobody writes (test)", EffectStage::BeforeLighting, {"nosuch"},
          {},       ""};
    }
    std::vector<SettingDesc> settings() const override { return {}; }
    void prepare(EffectContext&, const SettingValues&) override {}
    void addPasses(FrameGraph& g, EffectContext&, const SettingValues&) override {
      g.addPass(
          "reader_pass", [&](PassBuilder& b) { b.read(g.blackboard().texture("nosuch")); },
          [](PassContext&) {});
    }
  };
  EffectRegistry reg;
  reg.add([] { return std::make_unique<Reader>(); }, "test");
  const Scene scene = loadScene("default");
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  rs.effects = {{"reader", reg.defaultSettings("reader")}};
  test::expectError(
      [&] { Renderer(ctx(), scene, rs, &reg); }, ErrorKind::Usage,
      {"effect 'reader', addPasses()", "pass 'reader_pass'", "published by no pass: 'nosuch'"});
}

TEST_F(EffectGraphTest, UnknownViewListsTheAvailableOnes) {
  expectError([&] { make(scene, {}, "nope"); }, ErrorKind::Usage,
              {"unknown view 'nope'", "normal", "depth"});
}

// Every preset shipped in assets/presets names real effects and in-range settings, and is
// found by name from the build tree.
// `--presets all` and every table list the quality levels in their order, then the others.
TEST(ShippedPresets, NamesListTheQualityLevelsInOrderFirst) {
  const std::vector<std::string> names = presetNames();
  ASSERT_GE(names.size(), 5u);
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 4),
            (std::vector<std::string>{"low", "medium", "high", "ultra"}));
  EXPECT_NE(std::find(names.begin() + 4, names.end(), "lavapipe"), names.end());
}

TEST(ShippedPresets, ValidateAgainstThePlugins) {
  EffectRegistry registry;
  registry.scanDirectory(test::binPath("plugins"));
  ASSERT_TRUE(registry.has("ssao"))
      << "the ssao plugin must be built into " << test::binPath("plugins");
  size_t count = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(GI_SOURCE_DIR) + "/assets/presets")) {
    Preset p = loadPreset(entry.path().string());
    EXPECT_NO_THROW(validatePreset(p, registry)) << entry.path();
    EXPECT_GT(p.targetMs, 0.0) << entry.path();
    EXPECT_GT(p.referenceWidth, 0u) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 5u);
  for (const char* name : {"low", "medium", "high", "ultra", "lavapipe"}) {
    auto r = test::runCommand(test::binPath("gi-render") +
                              " --scene default --width 64 --height 48 --effects ssao --out "
                              "/tmp/gi-preset.png --preset " +
                              name);
    EXPECT_EQ(r.exitCode, 0) << name << ": " << r.output;
  }
}

TEST(GiRenderEffects, CommandLineErrorsAreClear) {
  const std::string bin = test::binPath("gi-render");
  auto r = test::runCommand(bin + " --scene default --out /tmp/gi-x.png --effects no_such_effect");
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("unknown effect 'no_such_effect'"), std::string::npos) << r.output;
  r = test::runCommand(bin + " --scene default --out /tmp/gi-x.png --preset no_such_preset");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("no_such_preset"), std::string::npos) << r.output;
  r = test::runCommand(
      bin + " --scene default --out /tmp/gi-x.png --effects '' --print-graph --view normal");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("[culled] lighting"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace gi
