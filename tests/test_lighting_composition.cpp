// Lighting composition: the optional inputs ao / ambient / indirect with their neutral
// fallbacks, effects ordered by their declared reads and writes, and the check of those
// declarations against what an effect's passes really do.
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
  ImageRGBA32F lit, depth;
  ImageRGBA8 output;
  std::vector<std::string> passes;
};

Frame renderWith(vk::Context& ctx, const Scene& scene, EffectRegistry& reg,
                 const std::vector<std::string>& effects) {
  RenderSettings rs;
  rs.width = 96;
  rs.height = 72;
  for (const std::string& e : effects) rs.effects.push_back({e, reg.defaultSettings(e)});
  Renderer r(ctx, scene, rs, &reg);
  r.renderFrame();
  return {r.readTarget("lit"), r.readTarget("depth"), r.readOutput(), r.passNames()};
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

TEST_F(LightingCompositionTest, AmbientReplacesTheEnvironmentTermAndIndirectAdds) {
  // No lights, no emission: lit = the environment term (+ indirect) on geometry.
  Scene scene = loadScene("default");
  scene.lights.clear();
  for (Node& n : scene.nodes) n.light = -1;
  for (Material& m : scene.materials) m.emission = glm::vec3(0.0f);
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
