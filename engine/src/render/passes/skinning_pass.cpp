// "skinning": rewrites the vertex-buffer regions of skinned/morphed instances whose joint
// matrices or morph weights changed (GPU linear blend skinning of the rest vertices).
#include "gi/vk/pipeline.h"
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

class SkinningPass final : public Effect {
 public:
  explicit SkinningPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"skinning", "1", "GPU skinning and morph targets of the deformed mesh instances"};
    i.writes = {kVerticesResource};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    if (s_.scene.deformed().empty() || pipeline_.handle()) return;
    vk::ComputeDesc d{"skinning: skinning.comp", vk::loadSpirv("skinning.comp")};
    d.blocks.pushConstants = GI_CPP_BLOCK(Push, srcFirst, dstFirst, count, jointFirst, jointCount);
    pipeline_ = vk::Pipeline::compute(ctx.vulkan(), d);
  }
  void addPasses(FrameGraph& graph, EffectContext&, const SettingValues&) override {
    if (s_.scene.deformed().empty()) return;
    const vk::Buffer& vb = s_.scene.vertexBuffer();
    auto io = std::make_shared<BufferHandle>(
        graph.importBuffer(kVerticesResource, vb.handle(), vb.size()));
    graph.addPass(
        "skinning", [&](PassBuilder& b) { *io = b.write(*io, BufferUsage::StorageWrite); },
        [this](PassContext& pc) { record(pc); });
    graph.blackboard().put(kVerticesResource, *io);
    s_.scene.setVertices(*io);
  }

 private:
  void record(PassContext& pc) {
    SceneGpu& sc = s_.scene;
    vk::DescriptorWriter w(pipeline_);
    w.buffer("Rest", sc.restBuffer().handle())
        .buffer("Skin", sc.jointIndexBuffer().handle())
        .buffer("Weights", sc.jointWeightBuffer().handle())
        .buffer("Joints", sc.jointBuffer().handle())
        .buffer("Out", sc.vertexBuffer().handle());
    pc.descriptors().bind(pc.cmd(), pipeline_, w);
    s_.skinnedThisFrame = 0;
    for (SceneGpu::Deformed& d : sc.deformed()) {
      if (!d.dirty) continue;
      pipeline_.push(pc.cmd(), Push{d.srcFirst, d.dstFirst, d.count, d.jointFirst, d.jointCount});
      vkCmdDispatch(pc.cmd(), (d.count + 255) / 256, 1, 1);  // local_size_x 256
      d.dirty = false;
      s_.skinnedThisFrame += d.count;
    }
  }
  struct Push {  // skinning.comp's push constants
    uint32_t srcFirst, dstFirst, count, jointFirst, jointCount;
  };
  EngineState& s_;
  vk::Pipeline pipeline_;
};

}  // namespace

std::unique_ptr<Effect> makeSkinningPass(EngineState& state) {
  return std::make_unique<SkinningPass>(state);
}

}  // namespace gi
