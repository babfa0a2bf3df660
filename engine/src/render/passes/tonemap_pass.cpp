// "tonemap": exposure, ACES filmic curve and sRGB encoding of "lit" into the 8-bit output
// image (imported: it outlives the graph, presenters copy it).
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

namespace res = resources;

class TonemapPass final : public Effect {
 public:
  explicit TonemapPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"tonemap", "1", "exposure, ACES filmic tone curve, sRGB encoding"};
    i.reads = {res::kLit};
    i.writes = {res::kOutput};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    if (pipeline_.handle()) return;
    pipeline_ = makeImageFilterPipeline(ctx.vulkan(), "tonemap.comp");
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    // GENERAL at the end of every frame: presenters and read-back expect it.
    TextureHandle output = graph.importTexture(res::kOutput, s_.output.handle(), s_.output.view(),
                                               TextureDesc{VK_FORMAT_R8G8B8A8_UNORM},
                                               VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    auto io = std::make_shared<std::pair<TextureHandle, TextureHandle>>();
    graph.addPass(
        "tonemap",
        [&](PassBuilder& b) {
          io->first = b.read(graph.blackboard().texture(res::kLit));
          io->second = b.write(output, TextureUsage::StorageWrite);
        },
        [this, io, frame = ctx.frameUniforms()](PassContext& pc) {
          recordImageFilter(pc, pipeline_, frame, s_.nearest, io->first, io->second, kScreenGroupX,
                            kScreenGroupY);
        });
    graph.blackboard().put(res::kOutput, io->second);
  }

 private:
  EngineState& s_;
  vk::Pipeline pipeline_;
};

}  // namespace

std::unique_ptr<Effect> makeTonemapPass(EngineState& state) {
  return std::make_unique<TonemapPass>(state);
}

}  // namespace gi
