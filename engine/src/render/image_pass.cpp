#include "gi/image_pass.h"

#include <memory>
#include <utility>

namespace gi {

TextureHandle addImagePass(FrameGraph& graph, EffectContext& ctx, ImagePass pass) {
  struct Io {
    std::vector<TextureHandle> inputs;
    TextureHandle out;
  };
  auto io = std::make_shared<Io>();
  // Shared by both callbacks (setup runs inside addPass, after the execute callback is made).
  auto p = std::make_shared<const ImagePass>(std::move(pass));
  Blackboard& bb = graph.blackboard();
  graph.addPass(
      p->name,
      [&](PassBuilder& b) {
        for (const auto& input : p->inputs) io->inputs.push_back(b.read(bb.texture(input.first)));
        io->out = b.write(b.create(p->output, p->outputDesc), TextureUsage::StorageWrite);
      },
      [io, p, frame = ctx.frameUniforms(), nearest = ctx.nearestSampler()](PassContext& pc) {
        vk::DescriptorWriter w(*p->pipeline);
        w.buffer("Frame", frame);
        for (size_t i = 0; i < p->inputs.size(); ++i)
          w.texture(p->inputs[i].second, pc.view(io->inputs[i]), nearest);
        w.image(p->outputBinding, pc.view(io->out));
        if (p->bind) p->bind(w, pc);
        pc.dispatch(*p->pipeline, w, pc.extent(io->out), p->groupX, p->groupY);
      });
  for (const std::string& name : p->publish) bb.put(name, io->out);
  return io->out;
}

EffectInfo litFilterInfo(std::string name, std::string version, std::string description) {
  EffectInfo info{.name = std::move(name),
                  .version = std::move(version),
                  .description = std::move(description),
                  .stage = EffectStage::AfterLighting,
                  .reads = {resources::kLit}};
  info.writes = {resources::kLit, info.name};
  info.debugView = info.name;
  return info;
}

TextureHandle addLitFilterPass(FrameGraph& graph, EffectContext& ctx, const std::string& effect,
                               const vk::Pipeline& pipeline,
                               std::function<void(vk::DescriptorWriter&, PassContext&)> bind) {
  return addImagePass(graph, ctx,
                      {.name = effect,
                       .pipeline = &pipeline,
                       .inputs = {{resources::kLit, "litColor"}},
                       .output = effect,
                       .outputDesc = {VK_FORMAT_R16G16B16A16_SFLOAT},
                       .outputBinding = "outColor",
                       .bind = std::move(bind),
                       .publish = {effect, resources::kLit}});
}

}  // namespace gi
