// Per-pass GPU time from Vulkan timestamp queries: begin()/end() around each pass while
// recording, collect() after the frame's fence, medians over many frames in the caller.
#pragma once

#include <vulkan/vulkan.h>

#include <string>
#include <utility>
#include <vector>

#include "gi/vk/context.h"

namespace gi::vk {

class GpuTimer {
 public:
  GpuTimer(Context& ctx, uint32_t maxScopes = 64);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  // Resets the queries for a new frame (recorded into `cmd`).
  void beginFrame(VkCommandBuffer cmd);
  void begin(VkCommandBuffer cmd, const std::string& name);
  void end(VkCommandBuffer cmd);
  // After the frame's work completed: (name, milliseconds) in recording order.
  std::vector<std::pair<std::string, double>> collect();

 private:
  Context& ctx_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t maxScopes_;
  std::vector<std::string> names_;
  bool open_ = false;
};

}  // namespace gi::vk
