// gi-demo's presenter: a FIFO swapchain for the GLFW window whose frames are the renderer's
// image (blitted, scaled to the window) with the Dear ImGui panel drawn over it in a render
// pass. Owns the ImGui Vulkan backend and times its pass with GPU timestamps. Recreates the
// swapchain when the window is resized or the surface goes out of date.
#pragma once

#include <vulkan/vulkan.h>

#include <vector>

#include "gi/vk/context.h"

struct GLFWwindow;
struct ImDrawData;

namespace demo {

class Presenter {
 public:
  // The context needs GLFW's instance extensions and swapchain = true. Initialises the ImGui
  // Vulkan backend (ImGui's context and GLFW backend must exist already).
  Presenter(gi::vk::Context& ctx, GLFWwindow* window);
  ~Presenter();
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  // Shows `source` (RGBA8 in `layout`, all writes submitted before) with `ui` on top. Leaves
  // `source` in `layout`. False when nothing was shown (minimised or out-of-date surface).
  bool present(VkImage source, VkExtent2D extent, VkImageLayout layout, ImDrawData* ui);
  // GPU time of the ImGui pass of the last finished frame (ms), -1 before the first one.
  double uiGpuMs() const { return uiGpuMs_; }
  // CPU time of recording the ImGui draw lists (vertex upload included), last frame (ms).
  double uiRecordMs() const { return uiRecordMs_; }
  VkExtent2D extent() const { return extent_; }

 private:
  void createSwapchain();
  void releaseSwapchain();
  void record(VkImage source, VkExtent2D extent, VkImageLayout layout, ImDrawData* ui,
              uint32_t index);
  void readUiTime();

  gi::vk::Context& ctx_;
  GLFWwindow* window_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSurfaceFormatKHR format_{};
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkExtent2D extent_{}, windowSize_{};
  uint32_t minImageCount_ = 2;
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  std::vector<VkSemaphore> renderFinished_;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  VkDescriptorPool imguiPool_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence inFlight_ = VK_NULL_HANDLE;
  VkSemaphore imageAcquired_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  bool queriesPending_ = false, outOfDate_ = false, imguiReady_ = false;
  double uiGpuMs_ = -1.0, uiRecordMs_ = 0.0;
};

}  // namespace demo
