// A vignette: an AfterLighting effect that reads the lit colour, writes a darkened copy and
// publishes it as the new "lit" so tonemapping (and every later effect) uses it. Built out of
// the engine's tree against the installed package (find_package(gi)); see CMakeLists.txt.
#include <memory>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/vk/pipeline.h"
#include "vignette.comp.h"  // const uint32_t vignette_comp[] (SPIR-V, made by gi_add_effect)

namespace {

class VignetteEffect : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    gi::EffectInfo i;
    i.name = "vignette";
    i.version = "1.0";
    i.description = "darkens the lit colour towards the image corners";
    i.stage = gi::EffectStage::AfterLighting;
    i.reads = {gi::resources::kLit};
    i.writes = {gi::resources::kLit, "vignette"};
    i.debugView = "vignette";
    return i;
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {{"strength", gi::SettingType::Float, 0.8, 0.0, 1.0,
             "how much the corners are darkened (0: off, 1: black)", false},
            {"radius", gi::SettingType::Float, 0.3, 0.0, 1.0,
             "distance from the centre (1 = corner) where darkening starts", false}};
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues&) override {
    gi::vk::ComputeDesc desc{"vignette: vignette.comp",
                             {std::begin(vignette_comp), std::end(vignette_comp)}};
    desc.blocks.pushConstants = GI_CPP_BLOCK(Params, strength, radius);
    pipeline_ = gi::vk::Pipeline::compute(ctx.vulkan(), desc);
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle in, out;
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    graph.addPass(
        "vignette",
        [&](gi::PassBuilder& b) {
          io->in = b.read(bb.texture(gi::resources::kLit));
          io->out = b.write(b.create("vignette", gi::TextureDesc{VK_FORMAT_R16G16B16A16_SFLOAT}),
                            gi::TextureUsage::StorageWrite);
        },
        // `settings` lives as long as the graph; reading it here (not in addPasses) makes
        // uniform-only changes apply without a graph rebuild.
        [this, io, values = &settings, frame = ctx.frameUniforms(),
         sampler = ctx.nearestSampler()](gi::PassContext& pc) {
          gi::vk::DescriptorWriter writer(pipeline_);
          writer.buffer("Frame", frame)
              .texture("litColor", pc.view(io->in), sampler)
              .image("outColor", pc.view(io->out));
          const Params params{float(values->number("strength")), float(values->number("radius"))};
          pc.dispatch(pipeline_, writer, pc.extent(io->out), 8, 8, params);
        });
    bb.put("vignette", io->out);           // the debug view (--view vignette)
    bb.put(gi::resources::kLit, io->out);  // what tonemapping reads from now on
  }

 private:
  struct Params {
    float strength, radius;
  };
  gi::vk::Pipeline pipeline_;
};

}  // namespace

GI_EFFECT_MODULE(VignetteEffect)
