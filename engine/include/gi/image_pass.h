// The most common pass: a compute shader run once per pixel of a new texture, reading a few
// blackboard textures. The pass declares its reads and its write (so the graph orders, culls
// and aliases it like any other), binds the frame uniforms as the shader's "Frame" block, each
// input under the name its shader gives it (nearest sampler) and the output as a storage image,
// then lets `bind` add the pass's own resources and push constants before it dispatches.
// For anything else (several outputs, buffers, several dispatches) write the pass with
// FrameGraph::addPass.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "gi/effect.h"
#include "gi/vk/pipeline.h"

namespace gi {

struct ImagePass {
  std::string name;  // the pass (gi-render --timings, --print-graph)
  const vk::Pipeline* pipeline = nullptr;
  // Blackboard texture -> the shader's sampler name, e.g. {resources::kLit, "litColor"}.
  std::vector<std::pair<std::string, std::string>> inputs;
  std::string output;               // the new texture's name (publish it yourself)
  TextureDesc outputDesc;           // its format and size (default: the frame's)
  std::string outputBinding;        // the shader's storage image it is bound to
  uint32_t groupX = 8, groupY = 8;  // the shader's local_size_x/y
  // Called while the pass records: bind further resources, push constants (pipeline.push).
  // Read uniform-only settings here (the effect's SettingValues outlive the graph).
  std::function<void(vk::DescriptorWriter&, PassContext&)> bind;
  // Blackboard names the output is published under once the pass is added (e.g. its own name
  // for --view and resources::kLit for the passes after it); empty: publish it yourself.
  std::vector<std::string> publish;
};

// Adds the pass and returns the output texture.
TextureHandle addImagePass(FrameGraph& graph, EffectContext& ctx, ImagePass pass);

// The shape of an effect that filters the lit colour (tone, colour grading, vignette, ...): it
// runs after lighting, reads "lit" and publishes a new "lit", which is also its debug view under
// the effect's name.
EffectInfo litFilterInfo(std::string name, std::string version, std::string description);
// Its pass, named `effect`: an ImagePass whose shader reads "lit" as `litColor` and writes
// `outColor` (RGBA16F, 8x8 groups), published as `effect` and "lit".
TextureHandle addLitFilterPass(FrameGraph& graph, EffectContext& ctx, const std::string& effect,
                               const vk::Pipeline& pipeline,
                               std::function<void(vk::DescriptorWriter&, PassContext&)> bind = {});

}  // namespace gi
