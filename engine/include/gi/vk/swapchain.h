// Presents rendered frames in a GLFW window: owns the window's surface and a FIFO swapchain,
// copies (blits) the renderer's output image into each acquired swapchain image, lets an
// optional overlay draw over it (a UI panel) and presents it. Recreates the swapchain when the
// window is resized or the surface goes out of date.
#pragma once

#include <vulkan/vulkan.h>

#include <vector>

#include "gi/vk/context.h"

struct GLFWwindow;  // keeps GLFW out of this header

namespace gi::vk {

// Drawing over each presented image (gi-demo's panel). The swapchain calls it from present(),
// after waiting for the previous frame, with the image blitted and in
// VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL (blit writes visible to colour-attachment access);
// record() must leave it in that layout. With an overlay the images are also colour attachments.
class SwapchainOverlay {
 public:
  virtual ~SwapchainOverlay() = default;
  // The swapchain (re)made its images: one view per image (valid until the next call or the
  // swapchain's end), their format and extent, and the image count asked for.
  virtual void imagesChanged(const std::vector<VkImageView>& views, VkFormat format,
                             VkExtent2D extent, uint32_t minImageCount) = 0;
  // Records the drawing over image `index` into `cmd`.
  virtual void record(VkCommandBuffer cmd, uint32_t index) = 0;
};

class Swapchain {
 public:
  // The context must have been created with the instance extensions GLFW asks for
  // (glfwGetRequiredInstanceExtensions) and swapchain = true. Throws gi::Error(Vulkan) when
  // the context's queue cannot present to the window. The window (and `overlay`, when given)
  // must outlive the swapchain.
  Swapchain(Context& ctx, GLFWwindow* window, SwapchainOverlay* overlay = nullptr);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // Shows `source` (RGBA8 in `layout`, all writes submitted before this call), scaled to the
  // window, with the overlay drawn over it. Leaves `source` in `layout`; later submissions on
  // the queue wait for the copy. Returns false when nothing was shown (a minimised window has
  // no image to show, or the surface went out of date).
  bool present(VkImage source, VkExtent2D sourceExtent,
               VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL);

  VkFormat format() const { return format_; }
  VkExtent2D extent() const { return extent_; }

 private:
  void init();
  void destroy();
  void create();
  void releaseImages();
  void record(VkImage source, VkExtent2D sourceExtent, VkImageLayout layout, uint32_t imageIndex);

  Context& ctx_;
  GLFWwindow* window_;
  SwapchainOverlay* overlay_;
  std::vector<VkImageView> views_;  // with an overlay: one per image
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
