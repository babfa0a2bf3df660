// Presents rendered frames in a GLFW window: owns the window's surface and a FIFO swapchain,
// copies (blits) the renderer's output image into each acquired swapchain image and presents
// it. Recreates the swapchain when the window is resized or the surface goes out of date.
#pragma once

#include <vulkan/vulkan.h>

#include <vector>

#include "gi/vk/context.h"

struct GLFWwindow;  // keeps GLFW out of this header

namespace gi::vk {

class Swapchain {
 public:
  // The context must have been created with the instance extensions GLFW asks for
  // (glfwGetRequiredInstanceExtensions) and swapchain = true. Throws gi::Error(Vulkan) when
  // the context's queue cannot present to the window. The window must outlive the swapchain.
  Swapchain(Context& ctx, GLFWwindow* window);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // Shows `source` (RGBA8, VK_IMAGE_LAYOUT_GENERAL, all writes submitted before this call),
  // scaled to the window. Leaves `source` in GENERAL; later submissions on the queue wait for
  // the copy. Returns false when nothing was shown (a minimised window has no image to show).
  bool present(VkImage source, VkExtent2D sourceExtent);

  VkFormat format() const { return format_; }
  VkExtent2D extent() const { return extent_; }

 private:
  void init();
  void destroy();
  void create();
  void releaseImages();
  void record(VkImage source, VkExtent2D sourceExtent, uint32_t imageIndex);

  Context& ctx_;
  GLFWwindow* window_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{};
  VkExtent2D windowSize_{};  // framebuffer size the swapchain was made for (resize detection)
  std::vector<VkImage> images_;
  bool outOfDate_ = false;
  bool linearFilter_ = false;  // whether the source format may be blitted with VK_FILTER_LINEAR

  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence inFlight_ = VK_NULL_HANDLE;  // the last present submission
  VkSemaphore imageAcquired_ = VK_NULL_HANDLE;
  std::vector<VkSemaphore> renderFinished_;  // one per swapchain image (waited by present)
};

}  // namespace gi::vk
