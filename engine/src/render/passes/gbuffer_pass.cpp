// "gbuffer": the main camera's G-buffer, drawn through the public GpuScene service exactly as
// an effect would draw it from another view.
#include <array>

#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

namespace res = resources;

class GBufferPass final : public Effect {
 public:
  EffectInfo info() const override {
    EffectInfo i{"gbuffer", "1",
                 "depth, normal, albedo, material, emission and motion of the main view"};
    i.writes = {res::kDepth,    res::kNormal,   res::kAlbedo,
                res::kMaterial, res::kEmission, res::kMotion};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext&, const SettingValues&) override {}
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    // Order of the attachments = sceneColorFormats(SceneOutputs::GBuffer).
    static constexpr std::array<const char*, 5> kColors = {
        res::kNormal, res::kAlbedo, res::kMaterial, res::kEmission, res::kMotion};
    struct Io {
      TextureHandle depth;
      std::array<TextureHandle, 5> colors;
    };
    auto io = std::make_shared<Io>();
    GpuScene& scene = ctx.scene();
    const VkBuffer frame = ctx.frameUniforms();
    const std::vector<VkFormat> formats = sceneColorFormats(SceneOutputs::GBuffer);
    graph.addPass(
        "gbuffer",
        [&](PassBuilder& b) {
          scene.declareRead(b);
          io->depth = b.write(b.create(res::kDepth, TextureDesc{kSceneDepthFormat}),
                              TextureUsage::DepthAttachment);
          for (size_t i = 0; i < kColors.size(); ++i)
            io->colors[i] = b.write(b.create(kColors[i], TextureDesc{formats[i]}),
                                    TextureUsage::ColorAttachment);
        },
        [io, &scene, frame](PassContext& pc) {
          SceneTargets t;
          t.depth = pc.view(io->depth);
          for (TextureHandle h : io->colors) t.colors.push_back(pc.view(h));
          t.extent = pc.extent(io->depth);
          scene.drawGBuffer(pc, t, frame);
        });
    graph.blackboard().put(res::kDepth, io->depth);
    for (size_t i = 0; i < kColors.size(); ++i) graph.blackboard().put(kColors[i], io->colors[i]);
  }
};

}  // namespace

std::unique_ptr<Effect> makeGBufferPass() {
  return std::make_unique<GBufferPass>();
}

}  // namespace gi
