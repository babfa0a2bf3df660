// "gbuffer": the main camera's packed G-buffer (gi/gbuffer.h, gbuffer.glsl), drawn through the
// public GpuScene service exactly as an effect would draw it from another view; and, for views
// and read-backs, one small pass per unpacked channel ("gbuffer_normal", ...), which the frame
// graph culls unless that channel is asked for.
#include <array>

#include "gi/gbuffer.h"
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

namespace res = resources;

class GBufferPass final : public Effect {
 public:
  explicit GBufferPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"gbuffer", "2",
                 "depth, the packed G-buffer (normal, albedo, material, emission) and motion of "
                 "the main view"};
    i.writes = {res::kDepth, res::kGBuffer, res::kMotion};
    for (const char* channel : gbuffer::kChannels) i.writes.push_back(channel);
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext&, const SettingValues&) override {}
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    struct Io {
      TextureHandle depth, packed, motion;
    };
    auto io = std::make_shared<Io>();
    GpuScene& scene = ctx.scene();
    const VkBuffer frame = ctx.frameUniforms();
    graph.addPass(
        "gbuffer",
        [&](PassBuilder& b) {
          scene.declareRead(b);
          io->depth = b.write(b.create(res::kDepth, TextureDesc{kSceneDepthFormat}),
                              TextureUsage::DepthAttachment);
          io->packed = b.write(b.create(res::kGBuffer, TextureDesc{gbuffer::kPackedFormat}),
                               TextureUsage::ColorAttachment);
          io->motion = b.write(b.create(res::kMotion, TextureDesc{gbuffer::kMotionFormat}),
                               TextureUsage::ColorAttachment);
        },
        [io, &scene, frame, c = &ctx](PassContext& pc) {
          SceneTargets t;
          t.depth = pc.view(io->depth);
          t.colors = {pc.view(io->packed), pc.view(io->motion)};  // sceneColorFormats order
          t.extent = pc.extent(io->depth);
          const glm::mat4 worldToClip = c->frame().viewProj;  // culls what the camera cannot see
          scene.drawGBuffer(pc, t, frame, &worldToClip);
        });
    Blackboard& bb = graph.blackboard();
    bb.put(res::kDepth, io->depth);
    bb.put(res::kGBuffer, io->packed);
    bb.put(res::kMotion, io->motion);
    for (size_t c = 0; c < gbuffer::kChannels.size(); ++c) {
      const char* channel = gbuffer::kChannels[c];
      auto out = std::make_shared<std::pair<TextureHandle, TextureHandle>>();
      graph.addPass(
          std::string("gbuffer_") + channel,
          [&](PassBuilder& b) {
            out->first = b.read(io->packed);
            out->second = b.write(b.create(channel, TextureDesc{VK_FORMAT_R32G32B32A32_SFLOAT}),
                                  TextureUsage::StorageWrite);
          },
          [this, out, c, frame](PassContext& pc) {
            recordImageFilter(pc, decoder(uint32_t(c)), frame, s_.nearest, out->first, out->second,
                              kScreenGroupX, kScreenGroupY);
          });
      bb.put(channel, out->second);
    }
  }

 private:
  // Built when a channel is first unpacked: most frames unpack none.
  const vk::Pipeline& decoder(uint32_t channel) {
    if (!decode_[channel].handle())
      decode_[channel] = makeImageFilterPipeline(s_.ctx, "gbuffer_decode.comp", {channel});
    return decode_[channel];
  }

  EngineState& s_;
  std::array<vk::Pipeline, gbuffer::kChannels.size()> decode_;
};

}  // namespace

std::unique_ptr<Effect> makeGBufferPass(EngineState& state) {
  return std::make_unique<GBufferPass>(state);
}

}  // namespace gi
