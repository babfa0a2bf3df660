// Engine services on the plugin API (gi/gpu_scene.h, gi/lights.h, EffectContext): an effect
// draws the scene from an extra view (depth only, G-buffer), from a light (reflective shadow
// map), as a paraboloid hemisphere (also from view records in a buffer) and as cube faces, and
// the results match the main G-buffer and closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/gbuffer.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "gi/vk/resources.h"
#include "process.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

// What the probe draws and how.
struct ProbeConfig {
  enum class Mode {
    CameraDepth,
    CameraGBuffer,
    Rsm,
    Paraboloid,
    ParaboloidBuffer,
    Cube,
    Peel
  } mode;
  float scale = 1.0f;  // extent of the probe's targets relative to the output
  uint32_t size = 0;   // absolute square size (Rsm, Paraboloid, Cube face) when non-zero
  std::function<SceneView(EffectContext&)> view;  // Rsm/Paraboloid/Cube: the view(s) to draw
};

// An effect that only uses the public services: draws the scene into its own targets and
// publishes them as "probe_<attachment>".
class Probe : public Effect {
 public:
  explicit Probe(ProbeConfig c) : c_(std::move(c)) {}
  EffectInfo info() const override {
    EffectInfo i{"probe", "1", "draws the scene through GpuScene (test)"};
    i.stage = EffectStage::AfterLighting;
    i.writes = outputs();
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    if (!view_) view_ = ctx.createView();
    if (c_.mode == ProbeConfig::Mode::ParaboloidBuffer && !records_)
      records_ =
          vk::Buffer(ctx.vulkan(), 2 * kDrawViewStride, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
  }
  void update(EffectContext& ctx, const SettingValues&) override {
    const VkExtent2D e = ctx.outputExtent();
    view_->setCamera(ctx.camera(), {uint32_t(std::lround(e.width * c_.scale)),
                                    uint32_t(std::lround(e.height * c_.scale))});
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    const SceneOutputs outputsKind =
        c_.mode == ProbeConfig::Mode::CameraGBuffer ? SceneOutputs::GBuffer
        : c_.mode == ProbeConfig::Mode::Rsm         ? SceneOutputs::ReflectiveShadowMap
                                                    : SceneOutputs::Depth;
    const std::vector<VkFormat> formats = sceneColorFormats(outputsKind);
    const std::vector<std::string> names = outputs();
    auto handles = std::make_shared<std::vector<TextureHandle>>();
    auto desc = [&](VkFormat f) {
      TextureDesc d{f};
      d.scale = c_.scale;
      if (c_.size) {
        d.sizeClass = SizeClass::Absolute;
        d.width = c_.mode == ProbeConfig::Mode::Cube               ? 3 * c_.size
                  : c_.mode == ProbeConfig::Mode::ParaboloidBuffer ? 2 * c_.size
                                                                   : c_.size;
        d.height = c_.mode == ProbeConfig::Mode::Cube ? 2 * c_.size : c_.size;
      }
      return d;
    };
    GpuScene& scene = ctx.scene();
    graph.addPass(
        "probe",
        [&](PassBuilder& b) {
          scene.declareRead(b);
          handles->push_back(
              b.write(b.create(names[0], desc(kSceneDepthFormat)), TextureUsage::DepthAttachment));
          for (size_t i = 0; i < formats.size(); ++i)
            handles->push_back(
                b.write(b.create(names[1 + i], desc(formats[i])), TextureUsage::ColorAttachment));
        },
        [this, handles, &scene, &ctx, colorCount = formats.size()](PassContext& pc) {
          SceneTargets t;
          t.depth = pc.view((*handles)[0]);
          for (size_t i = 1; i <= colorCount; ++i) t.colors.push_back(pc.view((*handles)[i]));
          t.extent = pc.extent((*handles)[0]);
          switch (c_.mode) {
            case ProbeConfig::Mode::Peel:  // layer 0: the plain depth
            case ProbeConfig::Mode::CameraDepth: {
              const SceneView v = SceneView::fromCamera(ctx.camera());
              scene.drawDepth(pc, t, {&v, 1});
              break;
            }
            case ProbeConfig::Mode::CameraGBuffer:
              scene.drawGBuffer(pc, t, view_->buffer());
              break;
            case ProbeConfig::Mode::Rsm:
              scene.drawRsm(pc, t, c_.view(ctx), ctx.lights().at(0));
              break;
            case ProbeConfig::Mode::Paraboloid: {
              const SceneView v = c_.view(ctx);
              scene.drawDepth(pc, t, {&v, 1});
              break;
            }
            case ProbeConfig::Mode::ParaboloidBuffer: {
              // Two DrawView records (scene_view.glsl) written on the host: the view, drawn
              // into the left square, and one that clips every vertex (all points at view
              // position (0, 0, 1), behind the hemisphere), into the right one.
              const SceneView v = c_.view(ctx);
              struct Record {
                glm::mat4 view, proj;
                glm::vec4 params, light[4], viewport;
              };
              std::array<Record, 2> rec{};
              rec[0].view = v.view;
              rec[1].view = glm::mat4(0.0f);
              rec[1].view[3] = glm::vec4(0, 0, 1, 1);
              for (Record& r : rec) r.params = glm::vec4(2.0f, v.znear, v.zfar, 0.0f);
              for (uint32_t i = 0; i < 2; ++i)
                records_.write(&rec[i], sizeof(Record), i * kDrawViewStride);
              const std::array<VkRect2D, 2> tiles = {
                  VkRect2D{{0, 0}, {c_.size, c_.size}},
                  VkRect2D{{int32_t(c_.size), 0}, {c_.size, c_.size}}};
              scene.drawDepthFromBuffer(pc, t, records_.handle(), tiles);
              break;
            }
            case ProbeConfig::Mode::Cube: {
              std::array<SceneView, 6> faces = SceneView::cube(c_.view(ctx).view[3], 0.05f, 50.0f);
              for (uint32_t f = 0; f < 6; ++f)
                faces[f].viewport = {{int32_t((f % 3) * c_.size), int32_t((f / 3) * c_.size)},
                                     {c_.size, c_.size}};
              scene.drawDepth(pc, t, faces);
              break;
            }
          }
        });
    if (c_.mode == ProbeConfig::Mode::Peel)
      // Layer 1: the nearest surfaces strictly behind layer 0 (depth peeling).
      graph.addPass(
          "probe_peel",
          [&](PassBuilder& b) {
            scene.declareRead(b);
            (*handles)[0] = b.read((*handles)[0]);
            handles->push_back(b.write(b.create(names[1], desc(kSceneDepthFormat)),
                                       TextureUsage::DepthAttachment));
          },
          [handles, &scene, &ctx](PassContext& pc) {
            const SceneView v = SceneView::fromCamera(ctx.camera());
            const SceneTargets t{pc.view((*handles)[1]), {}, pc.extent((*handles)[1])};
            scene.drawDepthPeeled(pc, t, {&v, 1}, pc.view((*handles)[0]));
          });
    for (size_t i = 0; i < names.size(); ++i) graph.blackboard().put(names[i], (*handles)[i]);
  }

 private:
  std::vector<std::string> outputs() const {
    switch (c_.mode) {
      case ProbeConfig::Mode::CameraGBuffer:
        return {"probe_depth", "probe_gbuffer", "probe_motion"};
      case ProbeConfig::Mode::Rsm:
        return {"probe_depth", "probe_position", "probe_rsm_normal", "probe_flux"};
      case ProbeConfig::Mode::Peel:
        return {"probe_depth", "probe_layer1"};
      default:
        return {"probe_depth"};
    }
  }
  ProbeConfig c_;
  std::shared_ptr<ViewUniforms> view_;
  vk::Buffer records_;  // ParaboloidBuffer: the view records
};

Scene sceneFromJson(const std::string& json) {
  const std::string dir = test::makeTempDir("services-scene");
  const std::string path = dir + "/scene.json";
  std::ofstream(path) << json;
  return loadScene(path);
}

struct Rendered {
  std::unique_ptr<Renderer> renderer;
};

std::unique_ptr<Renderer> render(vk::Context& ctx, const Scene& scene, EffectRegistry& reg,
                                 const ProbeConfig& config, uint32_t w = 160, uint32_t h = 120) {
  reg.add([config] { return std::make_unique<Probe>(config); }, "test");
  RenderSettings rs;
  rs.width = w;
  rs.height = h;
  rs.view = "probe_depth";
  rs.effects = {{"probe", reg.defaultSettings("probe")}};
  auto r = std::make_unique<Renderer>(ctx, scene, rs, &reg);
  r->renderFrame();
  return r;
}

class EngineServicesTest : public VulkanTest {};

TEST_F(EngineServicesTest, ExtraViewDepthAndGBufferEqualTheMainGBufferWhereViewsCoincide) {
  const Scene scene = loadScene("default");
  for (auto mode : {ProbeConfig::Mode::CameraDepth, ProbeConfig::Mode::CameraGBuffer}) {
    EffectRegistry reg;
    auto r = render(ctx(), scene, reg, {mode});
    r->setView("depth");
    r->renderFrame();
    const ImageRGBA32F mainDepth = r->readTarget("depth");
    r->setView("probe_depth");
    r->renderFrame();
    const ImageRGBA32F probeDepth = r->readTarget("probe_depth");
    ASSERT_EQ(mainDepth.pixels.size(), probeDepth.pixels.size());
    size_t geometry = 0;
    double worst = 0.0;
    for (size_t i = 0; i < mainDepth.pixels.size(); i += 4) {
      geometry += mainDepth.pixels[i] > 0.0f;
      worst = std::max(worst, double(std::abs(mainDepth.pixels[i] - probeDepth.pixels[i])));
    }
    EXPECT_GT(geometry, mainDepth.pixels.size() / 8);
    // Same transforms in the same order: equal to float rounding (1e-6 of the depth range).
    EXPECT_LE(worst, 1e-6) << "mode " << int(mode);
    if (mode == ProbeConfig::Mode::CameraGBuffer) {
      // The packed texels of both views, unpacked the same way: every channel equal.
      RenderSettings keep = r->settings();
      keep.keepForReadback = {"gbuffer", "probe_gbuffer"};
      r->applySettings(keep);
      r->renderFrame();
      const std::vector<uint8_t> main = r->readTargetBytes("gbuffer"),
                                 probe = r->readTargetBytes("probe_gbuffer");
      ASSERT_EQ(main.size(), probe.size());
      for (size_t c = 0; c < gbuffer::kChannels.size(); ++c) {
        const ImageRGBA32F a = gbuffer::unpackChannel(main, 160, 120, c),
                           b = gbuffer::unpackChannel(probe, 160, 120, c);
        double worstC = 0.0;
        for (size_t i = 0; i < a.pixels.size(); ++i)
          worstC = std::max(worstC, double(std::abs(a.pixels[i] - b.pixels[i])));
        EXPECT_LE(worstC, 1e-3) << gbuffer::kChannels[c]
                                << " of the extra view differs from the main G-buffer's";
      }
    }
  }
}

// Depth peeling (GpuScene::drawDepthPeeled): a unit box seen along its axis from distance 3
// has its front face at view distance 2.5 in layer 0 and its back face at 3.5 in layer 1; every
// layer-1 texel lies strictly behind layer 0, and where layer 0 is empty so is layer 1.
TEST_F(EngineServicesTest, PeeledLayerIsTheNearestSurfaceBehindTheFirst) {
  const Scene scene = sceneFromJson(R"({
      "models": [ { "primitive": "box", "size": 1 } ],
      "camera": { "position": [0, 0, 3], "target": [0, 0, 0] } })");
  EffectRegistry reg;
  auto r = render(ctx(), scene, reg, {ProbeConfig::Mode::Peel});
  const ImageRGBA32F l0 = r->readTarget("probe_depth");
  r->setView("probe_layer1");
  r->renderFrame();
  const ImageRGBA32F l1 = r->readTarget("probe_layer1");
  ASSERT_EQ(l0.pixels.size(), l1.pixels.size());
  size_t both = 0;
  for (size_t i = 0; i < l0.pixels.size(); i += 4) {
    if (l0.pixels[i] <= 0.0f) {
      ASSERT_EQ(l1.pixels[i], 0.0f) << "texel " << i / 4;
    }
    if (l1.pixels[i] > 0.0f) {
      ASSERT_LT(l1.pixels[i], l0.pixels[i]) << "texel " << i / 4;
      ++both;
    }
  }
  EXPECT_GT(both, l0.pixels.size() / 4 / 20);
  // View distance at the image centre from each layer's reverse-Z depth.
  const CameraView cam = r->camera();
  const glm::mat4 invProj = glm::inverse(cam.proj);
  auto distanceAt = [&](const ImageRGBA32F& img) {
    const int x = img.width / 2, y = img.height / 2;
    const float d = img.pixels[(size_t(y) * img.width + x) * 4];
    const glm::vec4 v = invProj * glm::vec4((x + 0.5f) / img.width * 2 - 1,
                                            (y + 0.5f) / img.height * 2 - 1, d, 1.0f);
    return -v.z / v.w;
  };
  EXPECT_NEAR(distanceAt(l0), 2.5f, 1e-3f);
  EXPECT_NEAR(distanceAt(l1), 3.5f, 1e-3f);
}

TEST_F(EngineServicesTest, QuarterResolutionExtraView) {
  const Scene scene = loadScene("default");
  EffectRegistry reg;
  auto r = render(ctx(), scene, reg, {ProbeConfig::Mode::CameraGBuffer, 0.5f});
  const ImageRGBA32F d = r->readTarget("probe_depth");
  EXPECT_EQ(d.width, 80);
  EXPECT_EQ(d.height, 60);
  size_t geometry = 0;
  for (size_t i = 0; i < d.pixels.size(); i += 4) geometry += d.pixels[i] > 0.0f;
  EXPECT_GT(geometry, d.pixels.size() / 16) << "the quarter-size view sees the room";
}

// The flux a white surface reflects, summed over a reflective shadow map that sees all the
// light's output, is the light's power into that solid angle (spot) or E x area (directional).
TEST_F(EngineServicesTest, ReflectiveShadowMapFluxIntegratesToTheLightsPower) {
  // Spot straight down over a large white plane: sum = I x integral of the cone falloff.
  const Scene spot = sceneFromJson(R"({
    "models": [{"primitive": "plane", "size": 40, "material": {"base_color": [1, 1, 1]}}],
    "camera": {"position": [0, 5, 3], "target": [0, 0, 0]},
    "lights": [{"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0],
                "outer_cone_deg": 30, "inner_cone_deg": 20, "intensity": 10}]})");
  ProbeConfig c{ProbeConfig::Mode::Rsm};
  c.size = 256;
  c.view = [](EffectContext& ctx) {
    const LightInfo& l = ctx.lights().at(0);
    return SceneView::perspective(l.position, l.direction, glm::radians(64.0f), 1.0f, 0.05f, 50.0f);
  };
  EffectRegistry reg;
  auto r = render(ctx(), spot, reg, c);
  const ImageRGBA32F flux = r->readTarget("probe_flux");
  double sum = 0.0;
  for (size_t i = 0; i < flux.pixels.size(); i += 4) sum += flux.pixels[i];
  const double cosOuter = std::cos(glm::radians(30.0)), cosInner = std::cos(glm::radians(20.0));
  double expected = 0.0;  // 2 pi I integral over cos of smoothstep(cosOuter, cosInner, cos)
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double c0 = cosOuter + (1.0 - cosOuter) * (i + 0.5) / n;
    const double t = std::clamp((c0 - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
    expected += t * t * (3.0 - 2.0 * t) * (1.0 - cosOuter) / n;
  }
  expected *= 2.0 * M_PI * 10.0;
  EXPECT_NEAR(sum, expected, 0.01 * expected) << "spot power into its cone";
  // Positions are on the plane, normals face up.
  const ImageRGBA32F pos = r->readTarget("probe_position"), nrm = r->readTarget("probe_rsm_normal");
  const size_t centre = (size_t(128) * 256 + 128) * 4;
  EXPECT_NEAR(pos.pixels[centre + 1], 0.0f, 1e-4f);
  EXPECT_EQ(pos.pixels[centre + 3], 1.0f);
  EXPECT_NEAR(nrm.pixels[centre + 1], 1.0f, 1e-3f);

  // Directional light E = 3 straight down, orthographic 2 x 2 window: sum = E x 4.
  const Scene sun = sceneFromJson(R"({
    "models": [{"primitive": "plane", "size": 40, "material": {"base_color": [1, 1, 1]}}],
    "camera": {"position": [0, 5, 3], "target": [0, 0, 0]},
    "lights": [{"type": "directional", "direction": [0, -1, 0], "intensity": 3}]})");
  c.view = [](EffectContext&) {
    return SceneView::orthographic({0.3f, 5.0f, -0.2f}, {0, -1, 0}, 1.0f, 1.0f, 0.1f, 20.0f);
  };
  EffectRegistry reg2;
  r = render(ctx(), sun, reg2, c);
  const ImageRGBA32F flux2 = r->readTarget("probe_flux");
  double sum2 = 0.0;
  for (size_t i = 0; i < flux2.pixels.size(); i += 4) sum2 += flux2.pixels[i];
  EXPECT_NEAR(sum2, 12.0, 1e-3 * 12.0) << "irradiance x the window's area";
}

// Paraboloid hemisphere looking down (-y) from 2 above the centre of a sphere of radius 5 seen
// from inside: the radial depth of the texel at disk position p is the distance to the sphere
// along the direction whose cosine to the axis is (1 - |p|^2) / (1 + |p|^2).
TEST_F(EngineServicesTest, ParaboloidViewStoresRadialDistance) {
  const Scene scene = sceneFromJson(R"({
    "models": [{"primitive": "sphere", "radius": 5, "segments": 256, "rings": 128}],
    "camera": {"position": [0, 1, 3], "target": [0, 0, 0]}})");
  ProbeConfig c{ProbeConfig::Mode::Paraboloid};
  c.size = 128;
  const float h = 2.0f, radius = 5.0f, znear = 0.1f, zfar = 20.0f;
  c.view = [&](EffectContext&) {
    return SceneView::paraboloid({0, h, 0}, {0, -1, 0}, znear, zfar);
  };
  EffectRegistry reg;
  auto r = render(ctx(), scene, reg, c);
  const ImageRGBA32F d = r->readTarget("probe_depth");
  int checked = 0;
  for (int y = 4; y < 128; y += 12)
    for (int x = 4; x < 128; x += 12) {
      const glm::vec2 p((x + 0.5f) / 64.0f - 1.0f, (y + 0.5f) / 64.0f - 1.0f);
      const float r2 = glm::dot(p, p);
      if (r2 > 0.95f) continue;  // the rim: triangles there bend the most
      const float cosTheta = (1.0f - r2) / (1.0f + r2);
      // |(0, h, 0) + t u| = radius with u.y = -cosTheta.
      const float expected =
          h * cosTheta + std::sqrt(h * h * cosTheta * cosTheta - h * h + radius * radius);
      const float depth = d.pixels[(size_t(y) * 128 + x) * 4];
      const float distance = znear + (1.0f - depth) * (zfar - znear);
      EXPECT_NEAR(distance, expected, 0.01f * expected) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 40);
  // Outside the disk nothing is drawn.
  EXPECT_EQ(d.pixels[0], 0.0f);
}

// GpuScene::drawDepthFromBuffer: the paraboloid view of the test above, as a DrawView record in
// a buffer, draws the same depth bit for bit as drawDepth into its viewport (the left square),
// and a record that clips everything leaves its viewport (the right square) cleared.
TEST_F(EngineServicesTest, ViewRecordsFromABufferDrawAsDrawDepth) {
  const Scene scene = sceneFromJson(R"({
    "models": [{"primitive": "sphere", "radius": 5, "segments": 64, "rings": 32},
               {"primitive": "box", "size": [1, 1, 1], "translation": [0.5, -1, 0]}],
    "camera": {"position": [0, 1, 3], "target": [0, 0, 0]}})");
  auto view = [](EffectContext&) {
    return SceneView::paraboloid({0, 2, 0}, glm::normalize(glm::vec3(0.2f, -1, 0.1f)), 0.1f, 20);
  };
  ProbeConfig direct{ProbeConfig::Mode::Paraboloid}, buffered{ProbeConfig::Mode::ParaboloidBuffer};
  direct.size = buffered.size = 64;
  direct.view = buffered.view = view;
  EffectRegistry a, b;
  const ImageRGBA32F expected = render(ctx(), scene, a, direct)->readTarget("probe_depth");
  const ImageRGBA32F got = render(ctx(), scene, b, buffered)->readTarget("probe_depth");
  ASSERT_EQ(got.width, 128);
  int drawn = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float e = expected.pixels[(size_t(y) * 64 + x) * 4];
      ASSERT_EQ(got.pixels[(size_t(y) * 128 + x) * 4], e) << x << "," << y;
      ASSERT_EQ(got.pixels[(size_t(y) * 128 + 64 + x) * 4], 0.0f) << x << "," << y;
      drawn += e > 0.0f;
    }
  EXPECT_GT(drawn, 64 * 64 / 2);  // the disk (pi / 4 of the square) sees the sphere
}

// Cube faces from a point whose six walls are at six different distances (+x 1, -x 2, +y 3,
// -y 4, +z 5, -z 6): the depth at each face's centre is that face's wall, so the face order
// and the 3x2 layout are checked, not only coverage.
TEST_F(EngineServicesTest, CubeFacesSeeTheirOwnWalls) {
  const float distances[6] = {1, 2, 3, 4, 5, 6};
  std::string models;
  const char* axes[6] = {"[%f, 0, 0]",  "[-%f, 0, 0]", "[0, %f, 0]",
                         "[0, -%f, 0]", "[0, 0, %f]",  "[0, 0, -%f]"};
  const char* sizes[6] = {"[0.1, 30, 30]", "[0.1, 30, 30]", "[30, 0.1, 30]",
                          "[30, 0.1, 30]", "[30, 30, 0.1]", "[30, 30, 0.1]"};
  for (int f = 0; f < 6; ++f) {
    char at[64];
    std::snprintf(at, sizeof at, axes[f], double(distances[f]) + 0.05);
    models += std::string(f ? "," : "") + R"({"primitive": "box", "size": )" + sizes[f] +
              R"(, "translation": )" + at + "}";
  }
  const Scene scene =
      sceneFromJson(R"({"models": [)" + models +
                    R"(], "camera": {"position": [0.3, 0.2, 0.1], "target": [0, 0, -1]}})");
  ProbeConfig c{ProbeConfig::Mode::Cube};
  c.size = 32;
  c.view = [](EffectContext&) {
    SceneView v;
    v.view[3] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);  // the probe reads the cube's centre here
    return v;
  };
  EffectRegistry reg;
  auto r = render(ctx(), scene, reg, c);
  const ImageRGBA32F d = r->readTarget("probe_depth");
  ASSERT_EQ(d.width, 96);
  ASSERT_EQ(d.height, 64);
  const float znear = 0.05f, zfar = 50.0f;  // SceneView::cube in the probe
  for (int f = 0; f < 6; ++f) {
    // Mean over the face's central 4x4 texels (all straight ahead to within 4 degrees).
    double sum = 0.0;
    for (int y = 14; y < 18; ++y)
      for (int x = 14; x < 18; ++x)
        sum += d.pixels[(size_t((f / 3) * 32 + y) * 96 + size_t((f % 3) * 32 + x)) * 4];
    const float depth = float(sum / 16.0);
    // perspectiveReverseZ: depth = near (far - z) / ((far - near) z).
    const float z = znear * zfar / (depth * (zfar - znear) + znear);
    EXPECT_NEAR(z, distances[f], 0.01f * distances[f]) << "face " << f;
  }
}

}  // namespace
}  // namespace gi
