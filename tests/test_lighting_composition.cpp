// Lighting composition: the optional inputs ao / ambient / indirect / contact_shadow /
// direct_light with their neutral fallbacks, effects ordered by their declared reads and
// writes, and the check of those declarations against what an effect's passes really do.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <fstream>

#include "gi/effect.h"
#include "gi/effect_config.h"
#include "gi/effect_registry.h"
#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

// Fills named resources with constant colours (a clear each); `reads` are looked up and read.
class ConstantEffect : public Effect {
 public:
  struct Output {
    std::string name;
    VkFormat format;
    VkClearColorValue value;
  };
  ConstantEffect(std::string name, EffectStage stage, std::vector<std::string> reads,
                 std::vector<Output> outputs, std::vector<std::string> declaredReads = {},
                 std::vector<std::string> declaredWrites = {})
      : name_(std::move(name)),
        stage_(stage),
        reads_(std::move(reads)),
        outputs_(std::move(outputs)),
        declaredReads_(std::move(declaredReads)),
        declaredWrites_(std::move(declaredWrites)) {
    if (declaredReads_.empty()) declaredReads_ = reads_;
    if (declaredWrites_.empty())
      for (const Output& o : outputs_) declaredWrites_.push_back(o.name);
  }
  EffectInfo info() const override {
    EffectInfo i{name_, "1", "constant outputs (test)", stage_};
    i.reads = declaredReads_;
    i.writes = declaredWrites_;
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext&, const SettingValues&) override {}
  void addPasses(FrameGraph& g, EffectContext&, const SettingValues&) override {
    auto handles = std::make_shared<std::vector<TextureHandle>>();
    g.addPass(
        name_,
        [&](PassBuilder& b) {
          for (const std::string& r : reads_) b.read(g.blackboard().texture(r));
          for (const Output& o : outputs_)
            handles->push_back(
                b.write(b.create(o.name, TextureDesc{o.format}), TextureUsage::TransferDst));
        },
        [this, handles](PassContext& pc) {
          for (size_t i = 0; i < outputs_.size(); ++i) {
            VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdClearColorImage(pc.cmd(), pc.image((*handles)[i]),
                                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &outputs_[i].value, 1,
                                 &range);
          }
        });
    for (size_t i = 0; i < outputs_.size(); ++i)
      g.blackboard().put(outputs_[i].name, (*handles)[i]);
  }

 private:
  std::string name_;
  EffectStage stage_;
  std::vector<std::string> reads_;
  std::vector<Output> outputs_;
  std::vector<std::string> declaredReads_, declaredWrites_;
};

constexpr VkFormat kRGBA16F = VK_FORMAT_R16G16B16A16_SFLOAT;

struct Frame {
  ImageRGBA32F lit, depth, albedo, material;
  ImageRGBA8 output;
  std::vector<std::string> passes;
};

Frame renderWith(vk::Context& ctx, const Scene& scene, EffectRegistry& reg,
                 const std::vector<std::string>& effects) {
  RenderSettings rs;
  rs.width = 96;
  rs.height = 72;
  rs.keepForReadback = {"lit", "depth", "albedo", "material"};  // read after the frame
  for (const std::string& e : effects) rs.effects.push_back({e, reg.defaultSettings(e)});
  Renderer r(ctx, scene, rs, &reg);
  r.renderFrame();
  return {r.readTarget("lit"),      r.readTarget("depth"), r.readTarget("albedo"),
          r.readTarget("material"), r.readOutput(),        r.passNames()};
}

class LightingCompositionTest : public VulkanTest {};

TEST_F(LightingCompositionTest, NeutralInputsReproduceTheImageWithoutEffectsBitForBit) {
  const Scene scene = loadScene("default");
  EffectRegistry reg;
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "neutral", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{
            {"ao", VK_FORMAT_R8G8B8A8_UNORM, {{1.0f, 1.0f, 1.0f, 1.0f}}},
            {"indirect", kRGBA16F, {{0.0f, 0.0f, 0.0f, 0.0f}}},
            {"ambient", kRGBA16F, {{0.0f, 0.0f, 0.0f, 0.0f}}}});
  });
  const Frame plain = renderWith(ctx(), scene, reg, {});
  const Frame neutral = renderWith(ctx(), scene, reg, {"neutral"});
  EXPECT_EQ(neutral.output.pixels, plain.output.pixels);
  EXPECT_EQ(neutral.lit.pixels, plain.lit.pixels);
  EXPECT_NE(std::find(neutral.passes.begin(), neutral.passes.end(), "neutral"),
            neutral.passes.end());
}

// The default room without lights and emission: lit = the environment term (+ indirect).
Scene environmentOnlyScene() {
  Scene scene = loadScene("default");
  scene.lights.clear();
  for (Node& n : scene.nodes) n.light = -1;
  for (Material& m : scene.materials) m.emission = glm::vec3(0.0f);
  return scene;
}

TEST_F(LightingCompositionTest, AmbientReplacesTheEnvironmentTermAndIndirectAdds) {
  const Scene scene = environmentOnlyScene();
  EffectRegistry reg;
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "ambient_only", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{{"ambient", kRGBA16F, {{0.25f, 0.5f, 0.75f, 1.0f}}}});
  });
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "indirect_only", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{{"indirect", kRGBA16F, {{0.125f, 0.0f, 0.5f, 0.0f}}}});
  });
  const Frame plain = renderWith(ctx(), scene, reg, {});
  const Frame ambient = renderWith(ctx(), scene, reg, {"ambient_only"});
  const Frame indirect = renderWith(ctx(), scene, reg, {"indirect_only"});
  size_t geometry = 0;
  for (size_t i = 0; i < plain.lit.pixels.size(); i += 4) {
    if (plain.depth.pixels[i] <= 0.0f) continue;  // sky: not composed
    ++geometry;
    EXPECT_FLOAT_EQ(ambient.lit.pixels[i], 0.25f);
    EXPECT_FLOAT_EQ(ambient.lit.pixels[i + 1], 0.5f);
    EXPECT_FLOAT_EQ(ambient.lit.pixels[i + 2], 0.75f);
    EXPECT_NEAR(indirect.lit.pixels[i] - plain.lit.pixels[i], 0.125f, 2e-3f);
    EXPECT_NEAR(indirect.lit.pixels[i + 1] - plain.lit.pixels[i + 1], 0.0f, 2e-3f);
    EXPECT_NEAR(indirect.lit.pixels[i + 2] - plain.lit.pixels[i + 2], 0.5f, 4e-3f);
  }
  EXPECT_GT(geometry, plain.lit.pixels.size() / 8);
}

// ambient with alpha 2 is per unit diffuse albedo: the lighting pass multiplies it by
// albedo x (1 - metallic) (G-buffer albedo decoded from sRGB on the CPU here). Tolerance 1%:
// lavapipe's sRGB decode differs from the exact curve by up to ~0.6% (measured), plus the
// half-float lit image (2^-11 relative).
TEST_F(LightingCompositionTest, AmbientWithAlphaTwoIsMultipliedByTheDiffuseAlbedo) {
  const Scene scene = environmentOnlyScene();
  EffectRegistry reg;
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "ambient_per_albedo", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{{"ambient", kRGBA16F, {{0.5f, 1.0f, 2.0f, 2.0f}}}});
  });
  const Frame f = renderWith(ctx(), scene, reg, {"ambient_per_albedo"});
  const float term[3] = {0.5f, 1.0f, 2.0f};
  size_t geometry = 0, differs = 0;
  for (size_t i = 0; i < f.lit.pixels.size(); i += 4) {
    if (f.depth.pixels[i] <= 0.0f) continue;  // sky: not composed
    ++geometry;
    const float diffuse = 1.0f - f.material.pixels[i + 1];
    for (int c = 0; c < 3; ++c) {
      const float expected = term[c] * f.albedo.pixels[i + c] * diffuse;
      ASSERT_NEAR(f.lit.pixels[i + c], expected, 0.01f * expected + 1e-4f) << i / 4 << " " << c;
      // Not the alpha-1 reading (the term itself) unless the albedo happens to be 1.
      if (std::abs(f.lit.pixels[i + c] - term[c]) > 0.01f * term[c]) ++differs;
    }
  }
  EXPECT_GT(geometry, f.lit.pixels.size() / 8);
  EXPECT_GT(differs, geometry);  // most pixels' albedo is not white
}

// contact_shadow: channel 0 scales the first *shadow-casting* light's direct term (here the
// second light: the first casts no shadow) and nothing else. Two directional lights on a plane
// with a box; lit(contact k) = lit(both) - (1 - k) x (lit(both) - lit(unshadowed light only)),
// k = 128/255 (0.5 in RGBA8, exact: the clear value is a multiple of 1/255). Tolerance: the
// half-float lit image (2^-11 relative of each term, three images).
TEST_F(LightingCompositionTest, ContactShadowScalesOnlyTheShadowedLightsDirectTerm) {
  auto scene = [](bool withShadowed) {
    const std::string path =
        test::makeTempDir("scenes") + "/contact_" + (withShadowed ? "two" : "one") + ".json";
    std::ofstream(path) << R"({
      "models": [ { "primitive": "plane", "size": 20, "material": { "base_color": [0.6, 0.6, 0.6] } },
                  { "primitive": "box", "size": [1, 1, 1], "translation": [0, 0.5, 0] } ],
      "lights": [ { "type": "directional", "direction": [0.3, -1, 0.2], "intensity": 1.5,
                    "casts_shadows": false })"
                        << (withShadowed ? R"(,
                  { "type": "directional", "direction": [-0.5, -1, -0.4], "intensity": 2.5,
                    "color": [1, 0.8, 0.6], "casts_shadows": true })"
                                         : "")
                        << R"( ],
      "camera": { "position": [0, 3, 5], "target": [0, 0, 0] } })";
    return loadSceneJson(path);
  };
  const float k = 128.0f / 255.0f;
  EffectRegistry reg;
  reg.add([k] {
    return std::make_unique<ConstantEffect>(
        "contact", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{
            {resources::kContactShadow, VK_FORMAT_R8G8B8A8_UNORM, {{k, 1.0f, 1.0f, 1.0f}}}});
  });
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "contact_neutral", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{
            {resources::kContactShadow, VK_FORMAT_R8G8B8A8_UNORM, {{1.0f, 1.0f, 1.0f, 1.0f}}}});
  });
  const Scene two = scene(true), one = scene(false);
  const Frame both = renderWith(ctx(), two, reg, {});
  const Frame halved = renderWith(ctx(), two, reg, {"contact"});
  const Frame neutral = renderWith(ctx(), two, reg, {"contact_neutral"});
  const Frame unshadowed = renderWith(ctx(), one, reg, {});
  const Frame unshadowedContact = renderWith(ctx(), one, reg, {"contact"});
  // The unshadowed light alone is untouched, and channels of 1 change nothing, bit for bit.
  EXPECT_EQ(unshadowedContact.lit.pixels, unshadowed.lit.pixels);
  EXPECT_EQ(neutral.lit.pixels, both.lit.pixels);
  size_t lit = 0;
  for (size_t i = 0; i < both.lit.pixels.size(); i += 4) {
    if (both.depth.pixels[i] <= 0.0f) continue;  // sky
    for (size_t c = 0; c < 3; ++c) {
      const float full = both.lit.pixels[i + c], rest = unshadowed.lit.pixels[i + c];
      const float expected = rest + k * (full - rest);
      ASSERT_TRUE(std::isfinite(halved.lit.pixels[i + c]));
      ASSERT_NEAR(halved.lit.pixels[i + c], expected, 2e-3f * (full + rest) + 1e-5f)
          << "pixel " << i / 4 << " channel " << c;
    }
    if (both.lit.pixels[i] - unshadowed.lit.pixels[i] > 0.05f) ++lit;
  }
  EXPECT_GT(lit, both.lit.pixels.size() / 4 / 4) << "the shadowed light must light the view";
}

// direct_light replaces the lighting pass's sum of the lights: lit(with it) = lit(the same scene
// without lights) + the published radiance on geometry; published beside contact_shadow (whose
// factors apply to single lights, already summed in it) the frame is refused with the reason.
TEST_F(LightingCompositionTest, DirectLightReplacesTheLightsAndRefusesContactShadowsBesideIt) {
  const Scene lit = loadScene("default");
  Scene dark = lit;
  dark.lights.clear();
  for (Node& n : dark.nodes) n.light = -1;
  EffectRegistry reg;
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "direct_const", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{
            {resources::kDirectLight, kRGBA16F, {{0.25f, 0.5f, 0.125f, 1.0f}}}});
  });
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "contact_const", EffectStage::BeforeLighting, std::vector<std::string>{},
        std::vector<ConstantEffect::Output>{
            {resources::kContactShadow, VK_FORMAT_R8G8B8A8_UNORM, {{0.5f, 1.0f, 1.0f, 1.0f}}}});
  });
  const Frame own = renderWith(ctx(), lit, reg, {});
  const Frame replaced = renderWith(ctx(), lit, reg, {"direct_const"});
  const Frame unlit = renderWith(ctx(), dark, reg, {});
  size_t geometry = 0, changed = 0;
  const float c[3] = {0.25f, 0.5f, 0.125f};
  for (size_t i = 0; i < own.lit.pixels.size(); i += 4) {
    if (own.depth.pixels[i] <= 0.0f) continue;  // sky: not composed
    ++geometry;
    for (size_t k = 0; k < 3; ++k)
      ASSERT_NEAR(replaced.lit.pixels[i + k], unlit.lit.pixels[i + k] + c[k],
                  2e-3f * (unlit.lit.pixels[i + k] + c[k]))
          << "pixel " << i / 4 << " channel " << k;
    if (std::abs(own.lit.pixels[i + 1] - replaced.lit.pixels[i + 1]) > 0.01f) ++changed;
  }
  EXPECT_GT(geometry, own.lit.pixels.size() / 8);
  EXPECT_GT(changed, geometry / 2) << "the scene's own lights must differ from the constant";
  try {
    renderWith(ctx(), lit, reg, {"direct_const", "contact_const"});
    FAIL() << "direct_light beside contact_shadow must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("direct_light must apply the contact shadows"),
              std::string::npos)
        << e.what();
  }
}

// A declared optional lighting input may stay unpublished (an effect's setting turns it off):
// the neutral fallback stands in, bit for bit; any other declared write must be published.
// Guard GI_MAX_RADIANCE (common.glsl): legal extremes (an environment, a light and an emission
// of ~1e38, each inside its declared range) give the lit image's brightest finite value, 65504,
// never inf or NaN, with no effect and with effects that sum light of their own.
TEST_F(LightingCompositionTest, LegalExtremeRadianceStaysFinite) {
  const test::TempDir dir("extreme_radiance");
  EffectRegistry registry;
  registry.scanDirectory(test::binPath("plugins"));
  for (const char* environment : {R"("type": "sky", "intensity": 1e38)",
                                  R"("type": "constant", "color": [1, 1, 1], "intensity": 1e38)"}) {
    const std::string path = dir.write("scene.json", std::string(R"({
      "models": [ { "primitive": "plane", "size": 20 },
                  { "primitive": "box", "size": [1, 1, 1], "translation": [0, 0.5, 0],
                    "material": { "emission": [3.4e38, 3.4e38, 3.4e38] } } ],
      "lights": [ { "type": "point", "position": [1, 2, 1], "intensity": 3.4e38 } ],
      "camera": { "position": [0, 3, 5], "target": [0, 0, 0] },
      "environment": { )") + environment + " } }");
    const Scene scene = loadScene(path);
    for (const std::vector<std::string>& effects :
         {std::vector<std::string>{}, {"ssao"}, {"ssdo"}, {"ism"}}) {
      RenderRequest request;
      request.overrides.effects = effects;
      RenderSettings base;
      base.width = 48;
      base.height = 36;
      base.keepForReadback = {resources::kLit};
      Renderer renderer(ctx(), scene, configureRender(scene, registry, request, base), &registry);
      renderer.renderFrame();
      const ImageRGBA32F lit = renderer.readTarget(resources::kLit);
      float brightest = 0.0f;
      size_t nonFinite = 0;
      for (size_t i = 0; i < lit.pixels.size(); ++i) {
        if (i % 4 == 3) continue;
        nonFinite += !std::isfinite(lit.pixels[i]);
        if (std::isfinite(lit.pixels[i])) brightest = std::max(brightest, lit.pixels[i]);
      }
      const std::string what = std::string(environment) + ", effects " +
                               (effects.empty() ? std::string("none") : effects[0]);
      EXPECT_EQ(nonFinite, 0u) << what;
      EXPECT_EQ(brightest, 65504.0f) << what;
    }
  }
}

TEST_F(LightingCompositionTest, DeclaredOptionalInputsMayStayUnpublished) {
  const Scene scene = loadScene("default");
  EffectRegistry reg;
  for (const char* declared : {resources::kContactShadow, "required_out"})
    reg.add([declared] {
      return std::make_unique<ConstantEffect>(
          std::string("declares_") + declared, EffectStage::BeforeLighting,
          std::vector<std::string>{},
          std::vector<ConstantEffect::Output>{{"own_out", kRGBA16F, {{0.0f, 0.0f, 0.0f, 0.0f}}}},
          std::vector<std::string>{}, std::vector<std::string>{"own_out", declared});
    });
  const Frame plain = renderWith(ctx(), scene, reg, {});
  const Frame optional = renderWith(ctx(), scene, reg, {"declares_contact_shadow"});
  EXPECT_EQ(optional.lit.pixels, plain.lit.pixels);
  try {
    renderWith(ctx(), scene, reg, {"declares_required_out"});
    FAIL() << "an unpublished declared write must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("published nothing under that name"), std::string::npos)
        << e.what();
  }
}

TEST_F(LightingCompositionTest, AfterLightingEffectsRunInDependencyOrderWhateverTheSceneOrder) {
  const Scene scene = loadScene("default");
  EffectRegistry reg;
  // "second" reads what "first" writes and rewrites lit; "first" reads lit.
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "first", EffectStage::AfterLighting, std::vector<std::string>{"lit"},
        std::vector<ConstantEffect::Output>{{"first_out", kRGBA16F, {{0.5f, 0.5f, 0.5f, 1.0f}}}});
  });
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "second", EffectStage::AfterLighting, std::vector<std::string>{"lit", "first_out"},
        std::vector<ConstantEffect::Output>{{"lit", kRGBA16F, {{0.0f, 1.0f, 0.0f, 1.0f}}}});
  });
  for (const auto& order :
       {std::vector<std::string>{"second", "first"}, std::vector<std::string>{"first", "second"}}) {
    const Frame f = renderWith(ctx(), scene, reg, order);
    const auto first = std::find(f.passes.begin(), f.passes.end(), "first");
    const auto second = std::find(f.passes.begin(), f.passes.end(), "second");
    ASSERT_NE(first, f.passes.end());
    ASSERT_NE(second, f.passes.end());
    EXPECT_LT(first - f.passes.begin(), second - f.passes.begin()) << order[0];
    EXPECT_EQ(f.lit.pixels[1], 1.0f) << "the blackboard's lit is the last writer's";
  }
}

TEST_F(LightingCompositionTest, CyclicDependenciesAreAnErrorNamingTheEffects) {
  const Scene scene = loadScene("default");
  EffectRegistry reg;
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "ping", EffectStage::AfterLighting, std::vector<std::string>{"pong_out"},
        std::vector<ConstantEffect::Output>{{"ping_out", kRGBA16F, {}}});
  });
  reg.add([] {
    return std::make_unique<ConstantEffect>(
        "pong", EffectStage::AfterLighting, std::vector<std::string>{"ping_out"},
        std::vector<ConstantEffect::Output>{{"pong_out", kRGBA16F, {}}});
  });
  try {
    renderWith(ctx(), scene, reg, {"ping", "pong"});
    FAIL() << "a cycle must not build";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("ping"), std::string::npos) << m;
    EXPECT_NE(m.find("pong"), std::string::npos) << m;
    EXPECT_NE(m.find("cycle"), std::string::npos) << m;
  }
}

TEST_F(LightingCompositionTest, UndeclaredReadsAndWritesAreErrorsNamingTheEffect) {
  const Scene scene = loadScene("default");
  struct Case {
    const char* name;
    std::vector<std::string> reads, declaredReads, declaredWrites;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"sneaky_read", {"normal"}, {"depth"}, {}, "reads 'normal'"},
      {"sneaky_write", {}, {}, {"something_else"}, "publishes 'sneaky_write_out'"},
  };
  for (const Case& c : cases) {
    EffectRegistry reg;
    reg.add([c] {
      return std::make_unique<ConstantEffect>(
          c.name, EffectStage::BeforeLighting, c.reads,
          std::vector<ConstantEffect::Output>{
              {std::string(c.name) + "_out", kRGBA16F, {{0.0f, 0.0f, 0.0f, 0.0f}}}},
          c.declaredReads, c.declaredWrites);
    });
    try {
      renderWith(ctx(), scene, reg, {c.name});
      FAIL() << c.name << " must be refused";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(std::string("effect '") + c.name + "'"), std::string::npos) << m;
      EXPECT_NE(m.find(c.expected), std::string::npos) << m;
    }
  }
}

}  // namespace
}  // namespace gi
