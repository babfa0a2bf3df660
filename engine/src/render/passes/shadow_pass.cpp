// One "shadow_<light>" pass per shadow-casting light, each drawing the scene depth-only
// through GpuScene into its own layer of "shadow_maps" (D32 reverse-Z 2-D array; a point light's
// six faces share its layer as a 3x2 atlas). Without shadowed lights "shadow_maps" is the
// engine's 1x1 array cleared to "no occluder". Only readers keep these passes alive.
#include "gi/vk/common.h"
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

namespace res = resources;

// "shadow_maps" when no light casts shadows: one 1x1 layer cleared to 0 (reverse-Z: nothing).
vk::Image makeNoShadowsImage(vk::Context& ctx) {
  vk::ImageDesc d;
  d.format = VK_FORMAT_D32_SFLOAT;
  d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
            VK_IMAGE_USAGE_TRANSFER_SRC_BIT;  // readTarget("shadow_maps") copies from it
  d.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  vk::Image img(ctx, d);
  ctx.submitAndWait([&](VkCommandBuffer c) {
    vk::imageBarrier(c, img.handle(), VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                     VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkClearDepthStencilValue zero{0.0f, 0};
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    vkCmdClearDepthStencilImage(c, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1,
                                &range);
    vk::imageBarrier(c, img.handle(), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
  });
  return img;
}

class ShadowPass final : public Effect {
 public:
  explicit ShadowPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"shadows", "1", "shadow maps of the shadow-casting lights, one array layer each"};
    i.writes = {res::kShadowMaps};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    if (!noShadows_) noShadows_ = makeNoShadowsImage(ctx.vulkan());
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    const LightSetup& setup = s_.lights;
    if (setup.maps.empty()) {
      TextureDesc desc{kSceneDepthFormat, SizeClass::Absolute, 1.0f, 1, 1};
      desc.type = TextureType::Tex2DArray;
      graph.blackboard().put(
          res::kShadowMaps,
          graph.importTexture(res::kShadowMaps, noShadows_.handle(), noShadows_.view(), desc,
                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL));
      return;
    }
    TextureDesc desc{kSceneDepthFormat, SizeClass::Absolute, 1.0f, setup.layerWidth(),
                     setup.layerHeight()};
    desc.type = TextureType::Tex2DArray;
    desc.layers = uint32_t(setup.maps.size());
    TextureHandle maps;
    GpuScene& scene = ctx.scene();
    for (uint32_t slot = 0; slot < setup.maps.size(); ++slot) {
      auto io = std::make_shared<TextureHandle>();
      graph.addPass(
          "shadow_" + std::to_string(setup.maps[slot].light),
          [&](PassBuilder& b) {
            scene.declareRead(b);
            if (!maps.valid()) maps = b.create(res::kShadowMaps, desc);
            *io = maps = b.write(maps, TextureUsage::DepthAttachment, Subresource::layerOf(slot));
          },
          [this, io, slot, &scene](PassContext& pc) {
            const ShadowMap& map = s_.lights.maps[slot];
            std::vector<SceneView> views;
            for (const ShadowMap::View& v : map.views) {
              SceneView sv;
              sv.proj = v.viewProj;  // world -> clip as one matrix
              sv.viewport = v.rect;
              views.push_back(sv);
            }
            SceneTargets t;
            t.depth = pc.view(*io, Subresource::layerOf(slot));
            t.extent = pc.extent(*io);
            scene.drawDepth(pc, t, views);
          });
    }
    graph.blackboard().put(res::kShadowMaps, maps);
  }

 private:
  EngineState& s_;
  vk::Image noShadows_;  // 1x1 one-layer D32 array cleared to 0: "shadow_maps" without shadows
};

}  // namespace

std::unique_ptr<Effect> makeShadowPass(EngineState& state) {
  return std::make_unique<ShadowPass>(state);
}

}  // namespace gi
