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
    const auto ssbo = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    pipeline_ =
        vk::Pipeline::compute(ctx.vulkan(), vk::loadSpirv("skinning.comp"),
                              {{0, ssbo}, {1, ssbo}, {2, ssbo}, {3, ssbo}, {4, ssbo}}, 5 * 4);
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
    vk::DescriptorWriter w;
    w.buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, sc.restBuffer().handle())
        .buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, sc.jointIndexBuffer().handle())
        .buffer(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, sc.jointWeightBuffer().handle())
        .buffer(3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, sc.jointBuffer().handle())
        .buffer(4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, sc.vertexBuffer().handle());
    pc.descriptors().bind(pc.cmd(), pipeline_, w);
    s_.skinnedThisFrame = 0;
    for (SceneGpu::Deformed& d : sc.deformed()) {
      if (!d.dirty) continue;
      const uint32_t push[5] = {d.srcFirst, d.dstFirst, d.count, d.jointFirst, d.jointCount};
      vkCmdPushConstants(pc.cmd(), pipeline_.layout(), VK_SHADER_STAGE_ALL, 0, sizeof(push), push);
      vkCmdDispatch(pc.cmd(), (d.count + 255) / 256, 1, 1);  // local_size_x 256
      d.dirty = false;
      s_.skinnedThisFrame += d.count;
    }
  }
  EngineState& s_;
  vk::Pipeline pipeline_;
};

}  // namespace

std::unique_ptr<Effect> makeSkinningPass(EngineState& state) {
  return std::make_unique<SkinningPass>(state);
}

}  // namespace gi
