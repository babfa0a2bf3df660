// Draws the scene from a second view through the engine's GpuScene service, out of the
// engine's tree (built against the installed package, like the vignette): a depth-only view and
// a G-buffer through its own ViewUniforms, both with the main camera (so they must equal the
// main G-buffer's depth), and a reflective shadow map of the first light seen from above.
// A second pass computes the irradiance from the engine's lights, shadow maps and environment
// with lights.glsl and environment.glsl ("second_view_irradiance").
// Publishes "second_view_depth", "second_view_gdepth", "second_view_gbuffer",
// "second_view_flux" and "second_view_irradiance"; run_test.sh compares them with the main
// G-buffer. Settings pick what is drawn and the views' size relative to the output
// (tools/bench-core times a quarter-size G-buffer with it; the engine's build also has it in
// <build>/example_plugins).
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/vk/pipeline.h"
#include "second_view_light.comp.h"  // const uint32_t second_view_light_comp[]

namespace {

class SecondViewEffect : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    gi::EffectInfo i;
    i.name = "second_view";
    i.version = "1.0";
    i.description = "the scene drawn again from an extra view and a light (engine services)";
    i.stage = gi::EffectStage::BeforeLighting;
    i.reads = {gi::resources::kDepth,
               gi::resources::kGBuffer,
               gi::resources::kLights,
               gi::resources::kShadowViews,
               gi::resources::kShadowMaps,
               gi::resources::kEnvironmentMap,
               gi::resources::kEnvironmentSampling};
    i.writes = {"second_view_depth", "second_view_gdepth", "second_view_gbuffer",
                "second_view_flux", "second_view_irradiance"};
    i.debugView = "second_view_depth";
    return i;
  }
  std::vector<gi::SettingDesc> settings() const override {
    gi::SettingDesc scale{"scale", gi::SettingType::Float,
                          1.0,     0.125,
                          1.0,     "size of the camera views relative to the output",
                          true};
    scale.step = 0.125;
    return {gi::SettingDesc::enumeration("draw", {"all", "depth", "gbuffer", "rsm"}, 0,
                                         "what the pass draws (for timing one kind alone)"),
            scale};
  }
  void prepare(gi::EffectContext& ctx, const gi::SettingValues&) override {
    if (!view_) view_ = ctx.createView();
    if (!light_.handle()) {
      light_ = gi::vk::Pipeline::compute(
          ctx.vulkan(), {"second_view: second_view_light.comp",
                         {std::begin(second_view_light_comp), std::end(second_view_light_comp)}});
    }
  }
  void update(gi::EffectContext& ctx, const gi::SettingValues& settings) override {
    const VkExtent2D e = ctx.outputExtent();
    const double scale = settings.number("scale");
    // The same rounding as the frame graph's output-relative size.
    view_->setCamera(ctx.camera(), {std::max(1u, uint32_t(std::lround(e.width * scale))),
                                    std::max(1u, uint32_t(std::lround(e.height * scale)))});
  }
  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle depth, gdepth, flux, rsmDepth;
      std::vector<gi::TextureHandle> gbuffer;  // sceneColorFormats(GBuffer) order
      std::array<gi::TextureHandle, 2> rsm;
    };
    auto io = std::make_shared<Io>();
    gi::GpuScene& scene = ctx.scene();
    const auto gformats = gi::sceneColorFormats(gi::SceneOutputs::GBuffer);
    const auto rformats = gi::sceneColorFormats(gi::SceneOutputs::ReflectiveShadowMap);
    gi::TextureDesc rsmDesc{gi::kSceneDepthFormat, gi::SizeClass::Absolute, 1.0f, 128, 128};
    const float scale = float(settings.number("scale"));
    const gi::SettingValues* values = &settings;  // read when recording: uniform-only changes
    graph.addPass(
        "second_view",
        [&](gi::PassBuilder& b) {
          scene.declareRead(b);
          auto target = [&](const char* name, VkFormat f, gi::TextureUsage u) {
            gi::TextureDesc d{f};
            d.scale = scale;
            return b.write(b.create(name, d), u);
          };
          io->depth =
              target("second_view_depth", gi::kSceneDepthFormat, gi::TextureUsage::DepthAttachment);
          io->gdepth = target("second_view_gdepth", gi::kSceneDepthFormat,
                              gi::TextureUsage::DepthAttachment);
          io->gbuffer.push_back(
              target("second_view_gbuffer", gformats[0], gi::TextureUsage::ColorAttachment));
          for (size_t i = 1; i < gformats.size(); ++i)
            io->gbuffer.push_back(target(("second_view_g" + std::to_string(i)).c_str(), gformats[i],
                                         gi::TextureUsage::ColorAttachment));
          rsmDesc.format = gi::kSceneDepthFormat;
          io->rsmDepth = b.write(b.create("second_view_rsm_depth", rsmDesc),
                                 gi::TextureUsage::DepthAttachment);
          for (size_t i = 0; i < 2; ++i) {
            gi::TextureDesc d = rsmDesc;
            d.format = rformats[i];
            io->rsm[i] = b.write(b.create("second_view_rsm" + std::to_string(i), d),
                                 gi::TextureUsage::ColorAttachment);
          }
          gi::TextureDesc d = rsmDesc;
          d.format = rformats[2];
          io->flux = b.write(b.create("second_view_flux", d), gi::TextureUsage::ColorAttachment);
        },
        [this, io, &scene, &ctx, values](gi::PassContext& pc) {
          const std::string& draw = values->option("draw");
          if (draw == "all" || draw == "depth") {
            gi::SceneTargets depthOnly{pc.view(io->depth), {}, pc.extent(io->depth)};
            const gi::SceneView camera = gi::SceneView::fromCamera(ctx.camera());
            scene.drawDepth(pc, depthOnly, {&camera, 1});
          }
          if (draw == "all" || draw == "gbuffer") {
            gi::SceneTargets g{pc.view(io->gdepth), {}, pc.extent(io->gdepth)};
            for (gi::TextureHandle h : io->gbuffer) g.colors.push_back(pc.view(h));
            scene.drawGBuffer(pc, g, view_->buffer());
          }
          if (ctx.lights().empty() || (draw != "all" && draw != "rsm")) return;
          const gi::LightInfo& light = ctx.lights()[0];
          gi::SceneTargets r{pc.view(io->rsmDepth),
                             {pc.view(io->rsm[0]), pc.view(io->rsm[1]), pc.view(io->flux)},
                             pc.extent(io->flux)};
          const gi::SceneView fromLight = gi::SceneView::perspective(
              light.position, {0.0f, -1.0f, 0.0f}, 1.6f, 1.0f, 0.01f, 100.0f);
          scene.drawRsm(pc, r, fromLight, light);
        });
    gi::Blackboard& bb = graph.blackboard();
    bb.put("second_view_depth", io->depth);
    bb.put("second_view_gdepth", io->gdepth);
    bb.put("second_view_gbuffer", io->gbuffer[0]);
    bb.put("second_view_flux", io->flux);
    addIrradiancePass(graph, ctx);
  }

 private:
  // Irradiance from the published lights, shadow maps and environment at each main-view pixel.
  void addIrradiancePass(gi::FrameGraph& graph, gi::EffectContext& ctx) {
    namespace res = gi::resources;
    struct Io {
      gi::TextureHandle depth, gbuffer, shadowMaps, environment, out;
      gi::BufferHandle lights, shadowViews, sampling;
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    graph.addPass(
        "second_view_irradiance",
        [&](gi::PassBuilder& b) {
          io->depth = b.read(bb.texture(res::kDepth));
          io->gbuffer = b.read(bb.texture(res::kGBuffer));
          io->lights = b.read(bb.buffer(res::kLights));
          io->shadowViews = b.read(bb.buffer(res::kShadowViews));
          io->shadowMaps = b.read(bb.texture(res::kShadowMaps));
          io->environment = b.read(bb.texture(res::kEnvironmentMap));
          io->sampling = b.read(bb.buffer(res::kEnvironmentSampling));
          io->out = b.write(
              b.create("second_view_irradiance", gi::TextureDesc{VK_FORMAT_R16G16B16A16_SFLOAT}),
              gi::TextureUsage::StorageWrite);
        },
        [this, io, frame = ctx.frameUniforms(),
         nearest = ctx.nearestSampler()](gi::PassContext& pc) {
          gi::vk::DescriptorWriter w(light_);
          w.buffer("Frame", frame)
              .texture("gDepth", pc.view(io->depth), nearest)
              .texture("giGBuffer", pc.view(io->gbuffer), nearest)
              .buffer("Lights", pc.buffer(io->lights))
              .buffer("ShadowViews", pc.buffer(io->shadowViews))
              .texture("shadowMaps", pc.view(io->shadowMaps), nearest)
              .texture("giEnvironmentMap", pc.view(io->environment), nearest)
              .buffer("giEnvironment", pc.buffer(io->sampling))
              .image("outIrradiance", pc.view(io->out));
          pc.dispatch(light_, w, pc.extent(io->out), 16, 16);
        });
    bb.put("second_view_irradiance", io->out);
  }

  gi::vk::Pipeline light_;
  std::shared_ptr<gi::ViewUniforms> view_;
};

}  // namespace

GI_EFFECT_MODULE(SecondViewEffect)
