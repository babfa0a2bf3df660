#include "render/frame_submission.h"

#include <cstdint>
#include <ctime>

#include "gi/vk/common.h"

namespace gi {
namespace {

// CPU time of the whole process (every thread, a CPU driver's workers included), ms.
double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

}  // namespace

FrameSubmission::FrameSubmission(vk::Context& ctx) : ctx_(ctx) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = ctx.commandPool();
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  vk::check(vkAllocateCommandBuffers(ctx.device(), &alloc, &cmd_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  if (VkResult r = vkCreateFence(ctx.device(), &fenceInfo, nullptr, &fence_); r != VK_SUCCESS) {
    vkFreeCommandBuffers(ctx.device(), ctx.commandPool(), 1, &cmd_);
    vk::check(r, "vkCreateFence");
  }
}

FrameSubmission::~FrameSubmission() {
  vkDestroyFence(ctx_.device(), fence_, nullptr);
  vkFreeCommandBuffers(ctx_.device(), ctx_.commandPool(), 1, &cmd_);
}

// Ends `c`, submits it and waits for it to complete.
void FrameSubmission::submitAndWait(VkCommandBuffer c) {
  vk::check(vkEndCommandBuffer(c), "vkEndCommandBuffer");
  VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cmdInfo.commandBuffer = c;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cmdInfo;
  vk::check(vkResetFences(ctx_.device(), 1, &fence_), "vkResetFences");
  vk::check(vkQueueSubmit2(ctx_.queue(), 1, &submit, fence_), "vkQueueSubmit2");
  vk::check(vkWaitForFences(ctx_.device(), 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

std::vector<PassTiming> FrameSubmission::run(FrameGraph& graph, vk::DescriptorArena& descriptors,
                                             vk::GpuTimer& timer, bool isolatePasses) {
  vk::check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vk::check(vkBeginCommandBuffer(cmd_, &begin), "vkBeginCommandBuffer");
  timer.beginFrame(cmd_);
  FrameGraph::PassBoundary isolate;
  std::vector<double> cpuMarks;  // process CPU time before the first pass and after each
  if (isolatePasses) {
    cpuMarks.push_back(processCpuMs());
    isolate = [this, &begin, &cpuMarks](VkCommandBuffer c) {
      submitAndWait(c);
      cpuMarks.push_back(processCpuMs());
      vk::check(vkResetCommandBuffer(c, 0), "vkResetCommandBuffer");
      vk::check(vkBeginCommandBuffer(c, &begin), "vkBeginCommandBuffer");
      return c;
    };
  }
  graph.execute(cmd_, descriptors, &timer, isolate);
  submitAndWait(cmd_);
  std::vector<PassTiming> timings;
  for (auto& [name, ms] : timer.collect()) timings.push_back({name, ms, -1.0});
  // One boundary per executed pass, in the order the timer saw them.
  if (cpuMarks.size() == timings.size() + 1)
    for (size_t i = 0; i < timings.size(); ++i) timings[i].cpuMs = cpuMarks[i + 1] - cpuMarks[i];
  return timings;
}

}  // namespace gi
