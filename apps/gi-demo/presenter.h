// gi-demo's presenter: the engine's swapchain (gi/vk/swapchain.h) shows the renderer's image
// with the Dear ImGui panel drawn over it as the swapchain's overlay, in a render pass over
// each swapchain image. Owns the ImGui Vulkan backend and times its pass with GPU timestamps.
#pragma once

#include <vulkan/vulkan.h>

#include <memory>
#include <vector>

#include "gi/vk/context.h"
#include "gi/vk/swapchain.h"

struct GLFWwindow;
struct ImDrawData;

namespace demo {

class Presenter final : public gi::vk::SwapchainOverlay {
 public:
  // The context needs GLFW's instance extensions and swapchain = true. Initialises the ImGui
  // Vulkan backend (ImGui's context and GLFW backend must exist already).
  Presenter(gi::vk::Context& ctx, GLFWwindow* window);
  ~Presenter() override;
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  // Shows `source` (RGBA8 in `layout`, all writes submitted before) with `ui` on top. Leaves
  // `source` in `layout`. False when nothing was shown (minimised or out-of-date surface).
  bool present(VkImage source, VkExtent2D extent, VkImageLayout layout, ImDrawData* ui);
  // GPU time of the ImGui pass of the last finished frame (ms), -1 before the first one.
  double uiGpuMs() const { return uiGpuMs_; }
  // CPU time of recording the ImGui draw lists (vertex upload included), last frame (ms).
  double uiRecordMs() const { return uiRecordMs_; }

 private:
  void imagesChanged(const std::vector<VkImageView>& views, VkFormat format, VkExtent2D extent,
                     uint32_t minImageCount) override;
  void record(VkCommandBuffer cmd, uint32_t index) override;
  void releaseFramebuffers();
  void readUiTime();

  gi::vk::Context& ctx_;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;  // made for the swapchain's format
  std::vector<VkFramebuffer> framebuffers_;
  VkExtent2D extent_{};
  uint32_t minImageCount_ = 2, imageCount_ = 2;
  VkDescriptorPool imguiPool_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::unique_ptr<gi::vk::Swapchain> swapchain_;
  ImDrawData* ui_ = nullptr;  // the panel of the frame being presented
  bool queriesPending_ = false, imguiReady_ = false;
  double uiGpuMs_ = -1.0, uiRecordMs_ = 0.0;
};

}  // namespace demo
