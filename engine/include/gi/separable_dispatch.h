// A separable filter as two dispatches inside one pass: along x from the input into a
// half-filtered image, then along y from that into the output. The frame graph orders passes,
// not the dispatches inside one, so the barrier between them is here: the y dispatch reads what
// the x dispatch wrote (the image stays GENERAL, as storage images are).
#pragma once

#include <functional>
#include <string>

#include "gi/graph/frame_graph.h"
#include "gi/vk/pipeline.h"

namespace gi {

struct SeparableDispatch {
  // The two axes' pipelines. Without `x` (a filter turned off) only `y` runs, from the input
  // straight into the output.
  const vk::Pipeline* x = nullptr;
  const vk::Pipeline* y = nullptr;
  std::string input;   // the shaders' sampled texture (read with `sampler`)
  std::string output;  // and storage image
  VkSampler sampler = VK_NULL_HANDLE;
  // The resources both dispatches share (frame, parameter blocks) and push constants
  // (pipeline.push), called with each dispatch's pipeline.
  std::function<void(vk::DescriptorWriter&, const vk::Pipeline&)> bind;
  uint32_t groupX = 32, groupY = 16;  // the shaders' local_size_x/y
};

// Records the dispatches over the output's extent; `half` is unused without `x`.
void dispatchSeparable(PassContext& pc, const SeparableDispatch& d, TextureHandle in,
                       TextureHandle half, TextureHandle out);

}  // namespace gi
