// "lighting": composes the lit image from the G-buffer, the lights and shadow maps, the
// environment and the optional inputs effects publish (ao, ambient, indirect; neutral when
// absent: the fallbacks are declared once, in the renderer's buildGraph()).
#include "gi/vk/pipeline.h"
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

namespace res = resources;

class LightingPass final : public Effect {
 public:
  explicit LightingPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"lighting", "2",
                 "direct light with shadows + environment x ambient visibility + indirect"};
    i.reads = {res::kDepth,    res::kNormal,  res::kAlbedo,      res::kMaterial,
               res::kEmission, res::kLights,  res::kShadowViews, res::kShadowMaps,
               res::kAO,       res::kAmbient, res::kIndirect,    res::kEnvironmentMap};
    i.writes = {res::kLit};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    if (pipeline_.handle()) return;
    ctx.vulkan().requireWorkgroup(kScreenGroupX, kScreenGroupY, "lighting");
    const auto ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
               tex = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
               img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    pipeline_ = vk::Pipeline::compute(ctx.vulkan(), vk::loadSpirv("lighting.comp"),
                                      {{0, ubo},
                                       {1, tex},
                                       {2, tex},
                                       {3, tex},
                                       {4, tex},
                                       {5, tex},
                                       {6, ssbo},
                                       {7, ssbo},
                                       {8, tex},
                                       {9, img},
                                       {10, tex},
                                       {11, tex},
                                       {12, tex},
                                       {13, tex}},
                                      sizeof(uint32_t));  // which optional inputs exist
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    struct Io {
      TextureHandle gbuffer[5], shadowMaps, ao, ambient, indirect, environment, lit;
      BufferHandle lights, shadowViews;
      uint32_t present = 0;  // bit 0 ao, 1 ambient, 2 indirect published (not the fallback)
    };
    auto io = std::make_shared<Io>();
    Blackboard& bb = graph.blackboard();
    const char* gbuffer[5] = {res::kDepth, res::kNormal, res::kAlbedo, res::kMaterial,
                              res::kEmission};
    graph.addPass(
        "lighting",
        [&](PassBuilder& b) {
          for (int i = 0; i < 5; ++i) io->gbuffer[i] = b.read(bb.texture(gbuffer[i]));
          io->lights = b.read(bb.buffer(res::kLights));
          io->shadowViews = b.read(bb.buffer(res::kShadowViews));
          io->shadowMaps = b.read(bb.texture(res::kShadowMaps));
          io->ao = b.readOptional(res::kAO);
          io->ambient = b.readOptional(res::kAmbient);
          io->indirect = b.readOptional(res::kIndirect);
          io->present = (b.isFallback(io->ao) ? 0u : 1u) | (b.isFallback(io->ambient) ? 0u : 2u) |
                        (b.isFallback(io->indirect) ? 0u : 4u);
          io->environment = b.read(bb.texture(res::kEnvironmentMap));
          io->lit = b.write(b.create(res::kLit, TextureDesc{VK_FORMAT_R16G16B16A16_SFLOAT}),
                            TextureUsage::StorageWrite);
        },
        [this, io, frame = ctx.frameUniforms()](PassContext& pc) {
          const VkSampler nearest = s_.nearest, linear = s_.linear;
          vk::DescriptorWriter w;
          w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frame);
          for (uint32_t i = 0; i < 5; ++i) w.sampled(1 + i, pc.view(io->gbuffer[i]), nearest);
          w.buffer(6, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(io->lights))
              .buffer(7, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(io->shadowViews))
              .sampled(8, pc.view(io->shadowMaps), nearest)
              .storageImage(9, pc.view(io->lit))
              .sampled(10, pc.view(io->ao), linear)
              .sampled(11, pc.view(io->ambient), linear)
              .sampled(12, pc.view(io->indirect), linear)
              .sampled(13, pc.view(io->environment), s_.scene.linearRepeat());
          pc.descriptors().bind(pc.cmd(), pipeline_, w);
          vkCmdPushConstants(pc.cmd(), pipeline_.layout(), VK_SHADER_STAGE_ALL, 0,
                             sizeof io->present, &io->present);
          const VkExtent2D e = pc.extent(io->lit);
          vkCmdDispatch(pc.cmd(), screenGroups(e.width, kScreenGroupX),
                        screenGroups(e.height, kScreenGroupY), 1);
        });
    bb.put(res::kLit, io->lit);
  }

 private:
  EngineState& s_;
  vk::Pipeline pipeline_;
};

}  // namespace

std::unique_ptr<Effect> makeLightingPass(EngineState& state) {
  return std::make_unique<LightingPass>(state);
}

}  // namespace gi
