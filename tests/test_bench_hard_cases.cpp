// The hard-case sweep (apps/gi-bench/hard_cases.h, ctest label `hardcases`): every registered
// effect and the engine alone on every hard case, every texture of the frame read back: no
// NaN/Inf, outputs in their documented ranges; static frames repeat (no flicker). Also: the
// checks themselves catch what they claim to, and the debug readback sees the transients.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gi/effect.h"
#include "gi/effect_config.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "hard_cases.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

class HardCasesTest : public test::VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    registry.scanDirectory(test::binPath("plugins"));
    ASSERT_FALSE(registry.names().empty()) << "no effect in " << test::binPath("plugins");
  }
  // Runs the sweep, prints one line per run, fails with every problem found.
  void sweep(const bench::HardCaseOptions& o) {
    const auto runs = bench::runHardCases(ctx(), registry, o, [](const bench::HardCaseRun& r) {
      std::printf(
          "%-20s %-11s %2d textures (%d packed), sky %.2f, %zu NaN/Inf, flicker %.3g, "
          "%.2f s\n",
          r.scene.c_str(), r.effect.c_str(), r.textures, r.undecoded, r.skyFraction, r.nonFinite,
          r.flicker, r.seconds);
    });
    const size_t effects = o.effects.empty() ? registry.names().size() + 1 : o.effects.size();
    const size_t cases = o.cases.empty() ? bench::hardCases().size() : o.cases.size();
    ASSERT_EQ(runs.size(), effects * cases);
    for (const bench::HardCaseRun& r : runs) {
      EXPECT_GE(r.textures, 5) << r.scene << " x " << r.effect;  // at least the G-buffer
      // Each camera sees what its case claims.
      if (r.scene == "sky_only")
        EXPECT_EQ(r.skyFraction, 1.0) << r.effect;
      else if (r.scene == "closed_box" || r.scene == "near_orthographic")
        EXPECT_EQ(r.skyFraction, 0.0) << r.scene << " x " << r.effect;
      else
        EXPECT_LT(r.skyFraction, 0.9) << r.scene << " x " << r.effect;
      for (const std::string& p : r.problems)
        ADD_FAILURE() << r.scene << " x " << r.effect << ": " << p;
    }
  }
  EffectRegistry registry;
};

TEST_F(HardCasesTest, EveryEffectStaysFiniteAndInRangeOnEveryHardCase) {
  bench::HardCaseOptions o;
  o.flickerFrames = 0;
  sweep(o);
}

// 64 static frames on the cases most likely to expose instability (grazing taps; a closed white
// box, where bounces feed on bounces), every effect. gi-bench --hard-cases checks every case.
TEST_F(HardCasesTest, StaticCameraDoesNotFlickerOver64Frames) {
  bench::HardCaseOptions o;
  o.width = 64;
  o.height = 48;
  o.flickerFrames = 64;
  o.cases = {"grazing_plane", "closed_box"};
  sweep(o);
}

// The ISM's environment VPLs (off by default) on every hard case, glossy receivers included
// (a sky-only view, grazing planes, albedo 1, a closed box the environment cannot reach, ...),
// 8 static frames each.
TEST_F(HardCasesTest, IsmEnvironmentVplsStayFiniteAndInRangeOnEveryHardCase) {
  bench::HardCaseOptions o;
  o.effects = {"ism"};
  o.sets = {"ism.environment_vpls=64", "ism.glossy=true"};
  o.flickerFrames = 8;
  sweep(o);
}

// SSDO's optional passes (off by default) on every hard case, 8 static frames each: two depth
// layers, two additional cameras and contact shadows, with the bounce (contact shadows applied
// to the published direct light) and without it (published as `contact_shadow`).
TEST_F(HardCasesTest, SsdoPeelingCamerasAndContactShadowsStayFiniteOnEveryHardCase) {
  for (const char* bounce : {"ssdo.bounce=true", "ssdo.bounce=false"}) {
    bench::HardCaseOptions o;
    o.effects = {"ssdo"};
    o.sets = {"ssdo.layers=2", "ssdo.cameras=2", "ssdo.contact_shadows=true", bounce};
    o.flickerFrames = 8;
    sweep(o);
  }
}

// Under an equirect map with a small bright sun (assets/environments/small_sun.hdr) in place of
// every case's environment: SSDO reading the map per direction (`map`) and by multiple
// importance sampling with the engine's tables (`mis`, the high and ultra presets' mode), with
// two layers and the bounce; and the ISM's environment VPLs from the same tables. 8 static
// frames each: the map paths' guards (zero pdf, below-horizon samples, black texels) on every
// case.
TEST_F(HardCasesTest, EnvironmentMapPathsStayFiniteOnEveryHardCase) {
  for (const char* mode : {"ssdo.environment_sampling=map", "ssdo.environment_sampling=mis",
                           "ism.environment_vpls=64"}) {
    bench::HardCaseOptions o;
    const std::string effect = std::string(mode).substr(0, std::string(mode).find('.'));
    o.effects = {effect};
    o.sets = {mode};
    if (effect == "ssdo") o.sets.insert(o.sets.end(), {"ssdo.layers=2", "ssdo.bounce=true"});
    o.environmentMap = std::string(GI_SOURCE_DIR) + "/assets/environments/small_sun.hdr";
    o.flickerFrames = 8;
    sweep(o);
  }
}

// Obscurance's transfer modes (off by default) on every hard case, 8 static frames each: the
// albedo transfer (albedo 1 under full occlusion: the guard) and the radiance transfer (its
// "ambient" and "direct_light", lit neighbours in colour, W above 1), two points per ray.
TEST_F(HardCasesTest, ObscuranceTransferModesStayFiniteOnEveryHardCase) {
  for (const char* transfer : {"obscurance.transfer=albedo", "obscurance.transfer=radiance"}) {
    bench::HardCaseOptions o;
    o.effects = {"obscurance"};
    o.sets = {transfer, "obscurance.points_per_ray=2"};
    o.flickerFrames = 8;
    sweep(o);
  }
}

// Every effect joins: the sweep covers the registry, not a list.
// Guard counting (gi/vk/guard_counters.h, engine/shaders/guards.glsl): the sweep counts, per
// pipeline, the guards that changed a value. SSDO's distance clamp fires next to the contact
// occluder, the engine alone's guards do not; outside the sweep counting is compiled out.
TEST_F(HardCasesTest, GuardsCountWhereTheyFireAndAreCompiledOutOtherwise) {
  bench::HardCaseOptions o;
  o.effects = {"none", "ssdo"};
  o.cases = {"contact_occluder"};
  o.flickerFrames = 0;
  const auto runs = bench::runHardCases(ctx(), registry, o);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_TRUE(runs[0].guards.empty()) << bench::guardSummary(runs[0].guards);
  uint64_t distance = 0;
  for (const vk::GuardCounters::Count& c : runs[1].guards)
    if (c.pipeline.rfind("ssdo:", 0) == 0) distance += c.fired[2];
  EXPECT_GT(distance, 0u) << bench::guardSummary(runs[1].guards);
  std::printf("contact_occluder x ssdo: %s\n", bench::guardSummary(runs[1].guards).c_str());
  EXPECT_FALSE(ctx().guards().enabled());  // the sweep restored the setting

  // The same frame outside the sweep: counting compiled out, nothing counted.
  Scene scene;
  for (const bench::HardCase& c : bench::hardCases())
    if (c.name == "contact_occluder") scene = c.build();
  RenderSettings base;
  base.width = 160;
  base.height = 120;
  RenderRequest request;
  request.overrides.effects = {"ssdo"};
  ctx().guards().reset();
  Renderer r(ctx(), scene, configureRender(scene, registry, request, base), &registry);
  r.renderFrame();
  r.readTarget("lit");
  EXPECT_TRUE(ctx().guards().read().empty()) << bench::guardSummary(ctx().guards().read());
}

// On an ordinary scene (the built-in room), which guards fire is a finding, not a failure:
// printed, and bounded where the guard must stay silent (the lighting pass sees no non-finite
// value, no radiance beyond half-float range and no zero view vector).
TEST_F(HardCasesTest, GuardsOnTheOrdinaryRoom) {
  const Scene scene = loadScene("default");
  ctx().guards().setEnabled(true);
  for (const std::string& effect : registry.names()) {
    RenderSettings base;
    base.width = 160;
    base.height = 120;
    RenderRequest request;
    request.overrides.effects = {effect};
    ctx().guards().reset();
    {
      Renderer r(ctx(), scene, configureRender(scene, registry, request, base), &registry);
      r.renderFrame();
      r.readTarget("lit");
    }
    const auto counts = ctx().guards().read();
    std::printf("room x %-10s guards fired: %s\n", effect.c_str(),
                bench::guardSummary(counts).c_str());
    for (const vk::GuardCounters::Count& c : counts)
      if (c.pipeline.find("lighting") != std::string::npos ||
          c.pipeline.find("tonemap") != std::string::npos)
        ADD_FAILURE() << effect << ": " << bench::guardSummary({c});
  }
  ctx().guards().setEnabled(false);
}

TEST_F(HardCasesTest, SweepCoversEveryRegisteredEffect) {
  bench::HardCaseOptions o;
  o.width = 32;
  o.height = 24;
  o.flickerFrames = 0;
  o.cases = {"albedo_1"};
  std::vector<std::string> seen;
  bench::runHardCases(ctx(), registry, o,
                      [&](const bench::HardCaseRun& r) { seen.push_back(r.effect); });
  std::vector<std::string> expected = registry.names();
  expected.push_back("none");
  EXPECT_EQ(seen, expected);
}

// The checks fail where they should: a NaN, an Inf, AO above 1, negative radiance.
TEST(HardCaseChecks, FlagNonFiniteValuesAndOutOfRangeOutputs) {
  ImageRGBA32F img;
  img.width = 2;
  img.height = 1;
  img.pixels = {0.5f, 0.5f, 0.5f, 1.0f, 0.25f, 0.25f, 0.25f, 1.0f};
  auto check = [&](const std::string& name) {
    bench::HardCaseRun run;
    bench::checkTexture(name, img, run);
    return run;
  };
  EXPECT_TRUE(check("ao").problems.empty());
  EXPECT_TRUE(check("lit").problems.empty());
  img.pixels[5] = NAN;
  img.pixels[2] = INFINITY;
  bench::HardCaseRun r = check("some_transient");
  EXPECT_EQ(r.nonFinite, 2u);
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_NE(r.problems[0].find("2 NaN/Inf values (first at pixel 0,0 channel 2)"),
            std::string::npos)
      << r.problems[0];
  img.pixels = {1.5f, 0, 0, 1, -0.25f, 0, 0, 1};
  r = check("ao");
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_NE(r.problems[0].find("2 values outside [0, 1] (worst 1.5)"), std::string::npos)
      << r.problems[0];
  r = check("lit");
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_NE(r.problems[0].find("1 values outside [0, inf] (worst -0.25)"), std::string::npos)
      << r.problems[0];
  EXPECT_TRUE(check("normal").problems.empty());  // no documented range: finite only
}

// With aliasing off, every transient keeps its own memory: the readback sees an effect's
// internal textures beside the blackboard's, each holding what its own pass wrote.
TEST_F(HardCasesTest, ReadAllTexturesSeesTransientsWithAliasingOff) {
  const std::string effect = registry.has("ssao") ? "ssao" : registry.names().front();
  const Scene scene = bench::hardCases().front().build();
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  rs.effects = {EffectConfig{effect, registry.defaultSettings(effect)}};
  Renderer aliased(ctx(), scene, rs, &registry);
  aliased.renderFrame();
  rs.aliasTransients = false;
  Renderer separate(ctx(), scene, rs, &registry);
  separate.renderFrame();
  const auto all = separate.readAllTextures();
  const std::vector<std::string> published = separate.viewNames();
  int internal = 0;
  for (const auto& t : all) {
    internal += std::count(published.begin(), published.end(), t.name) == 0;
    if (t.name == "depth" || t.name == "lit") {
      ASSERT_TRUE(t.decoded) << t.name;
      // The same frame as the aliased renderer's (aliasing changes memory, not results).
      EXPECT_EQ(t.image.pixels, aliased.readTarget(t.name).pixels) << t.name;
    }
  }
  EXPECT_GT(internal, 0) << effect << " has no internal transient texture";
  EXPECT_GE(all.size(), 6u);
}

}  // namespace
}  // namespace gi
