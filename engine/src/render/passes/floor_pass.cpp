// "floor": the cost floor (one G-buffer read and one 8-bit write per pixel); gi-bench reports
// other passes' times as ratios to it measured in the same run.
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

namespace res = resources;

// The floor keeps its original 8x8 workgroups (floor.comp): it is the cost unit other passes are
// measured in, so it must stay the same work from version to version.
constexpr uint32_t kFloorGroup = 8;

class FloorPass final : public Effect {
 public:
  explicit FloorPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"floor", "1", "cost floor: one G-buffer read and one 8-bit write per pixel"};
    i.reads = {res::kGBuffer};
    i.writes = {res::kFloor};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    if (pipeline_.handle()) return;
    pipeline_ = makeImageFilterPipeline(ctx.vulkan(), "floor.comp");
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    auto io = std::make_shared<std::pair<TextureHandle, TextureHandle>>();
    graph.addPass(
        "floor",
        [&](PassBuilder& b) {
          io->first = b.read(graph.blackboard().texture(res::kGBuffer));
          io->second = b.write(b.create(res::kFloor, TextureDesc{VK_FORMAT_R8G8B8A8_UNORM}),
                               TextureUsage::StorageWrite);
        },
        [this, io, frame = ctx.frameUniforms()](PassContext& pc) {
          recordImageFilter(pc, pipeline_, frame, s_.nearest, io->first, io->second, kFloorGroup,
                            kFloorGroup);
        });
    graph.blackboard().put(res::kFloor, io->second);
  }

 private:
  EngineState& s_;
  vk::Pipeline pipeline_;
};

}  // namespace

std::unique_ptr<Effect> makeFloorPass(EngineState& state) {
  return std::make_unique<FloorPass>(state);
}

}  // namespace gi
