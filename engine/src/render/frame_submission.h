// Records a compiled frame graph into one command buffer, submits it, waits, and collects each
// pass's GPU time (timestamp queries) and, when passes are isolated, its process CPU time.
#pragma once

#include <vulkan/vulkan.h>

#include <vector>

#include "gi/graph/frame_graph.h"
#include "gi/render_settings.h"
#include "gi/renderer.h"
#include "gi/vk/context.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"

namespace gi {

class FrameSubmission {
 public:
  explicit FrameSubmission(vk::Context& ctx);
  ~FrameSubmission();
  FrameSubmission(const FrameSubmission&) = delete;
  FrameSubmission& operator=(const FrameSubmission&) = delete;

  // Executes `graph` and waits for it. `isolatePasses`: each pass is submitted alone and waited
  // for (RenderSettings::isolatePasses), and its process CPU time is measured around it.
  std::vector<PassTiming> run(FrameGraph& graph, vk::DescriptorArena& descriptors,
                              vk::GpuTimer& timer, bool isolatePasses);

 private:
  void submitAndWait(VkCommandBuffer c);
  vk::Context& ctx_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

}  // namespace gi
