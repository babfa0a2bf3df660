#include "gi/vk/swapchain.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <limits>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/resources.h"

namespace gi::vk {

namespace {

// The renderer's output already holds sRGB-encoded values, so a UNORM swapchain format shows
// them as they are; an _SRGB format would encode them a second time (too bright).
VkSurfaceFormatKHR pickFormat(VkPhysicalDevice physical, VkSurfaceKHR surface) {
  uint32_t count = 0;
  check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr),
        "vkGetPhysicalDeviceSurfaceFormatsKHR");
  std::vector<VkSurfaceFormatKHR> formats(count);
  check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()),
        "vkGetPhysicalDeviceSurfaceFormatsKHR");
  if (formats.empty()) throw Error(ErrorKind::Vulkan, "", "the window surface offers no formats");
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == wanted && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
  return formats[0];
}

bool hasFeature(VkPhysicalDevice physical, VkFormat format, VkFormatFeatureFlags feature) {
  VkFormatProperties props;
  vkGetPhysicalDeviceFormatProperties(physical, format, &props);
  return (props.optimalTilingFeatures & feature) == feature;
}

VkSemaphore createSemaphore(VkDevice device) {
  VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkSemaphore s;
  check(vkCreateSemaphore(device, &info, nullptr, &s), "vkCreateSemaphore");
  return s;
}

}  // namespace

Swapchain::Swapchain(Context& ctx, GLFWwindow* window, SwapchainOverlay* overlay)
    : ctx_(ctx), window_(window), overlay_(overlay) {
  try {
    init();
  } catch (...) {
    destroy();  // the destructor does not run for a half-built object
    throw;
  }
}

Swapchain::~Swapchain() {
  destroy();
}

void Swapchain::init() {
  check(glfwCreateWindowSurface(ctx_.instance(), window_, nullptr, &surface_),
        "glfwCreateWindowSurface");
  VkBool32 supported = VK_FALSE;
  check(vkGetPhysicalDeviceSurfaceSupportKHR(ctx_.physicalDevice(), ctx_.queueFamily(), surface_,
                                             &supported),
        "vkGetPhysicalDeviceSurfaceSupportKHR");
  if (!supported)
    throw Error(ErrorKind::Vulkan, "",
                "queue family " + std::to_string(ctx_.queueFamily()) + " of device '" +
                    ctx_.deviceName() + "' cannot present to the window surface");
  linearFilter_ = hasFeature(
      ctx_.physicalDevice(), VK_FORMAT_R8G8B8A8_UNORM,
      VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT);

  VkDevice device = ctx_.device();
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags =
      VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT | VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool.queueFamilyIndex = ctx_.queueFamily();
  check(vkCreateCommandPool(device, &pool, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(device, &alloc, &cmd_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;  // the first present() has nothing to wait for
  check(vkCreateFence(device, &fence, nullptr, &inFlight_), "vkCreateFence");
  imageAcquired_ = createSemaphore(device);
  create();
}

void Swapchain::destroy() {
  VkDevice device = ctx_.device();
  vkDeviceWaitIdle(device);
  releaseImages();
  vkDestroySwapchainKHR(device, swapchain_, nullptr);
  vkDestroySemaphore(device, imageAcquired_, nullptr);
  vkDestroyFence(device, inFlight_, nullptr);
  vkDestroyCommandPool(device, pool_, nullptr);  // frees cmd_
  vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
}

// Frees what belongs to the current images; the swapchain itself stays so that create() can
// hand it over as oldSwapchain.
void Swapchain::releaseImages() {
  for (VkSemaphore s : renderFinished_) vkDestroySemaphore(ctx_.device(), s, nullptr);
  for (VkImageView v : views_) vkDestroyImageView(ctx_.device(), v, nullptr);
  renderFinished_.clear();
  views_.clear();
  images_.clear();
}

void Swapchain::create() {
  VkPhysicalDevice physical = ctx_.physicalDevice();
  VkDevice device = ctx_.device();
  VkSurfaceCapabilitiesKHR caps;
  check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface_, &caps),
        "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  windowSize_ = {uint32_t(w), uint32_t(h)};
  if (caps.currentExtent.width != std::numeric_limits<uint32_t>::max()) {
    extent_ = caps.currentExtent;
  } else {
    extent_.width = std::clamp(uint32_t(w), caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height =
        std::clamp(uint32_t(h), caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent_.width == 0 || extent_.height == 0) return;  // minimised: create when visible again

  const VkSurfaceFormatKHR surfaceFormat = pickFormat(physical, surface_);
  format_ = surfaceFormat.format;
  VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (overlay_) usage |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if ((caps.supportedUsageFlags & usage) != usage ||
      !hasFeature(physical, format_, VK_FORMAT_FEATURE_BLIT_DST_BIT))
    throw Error(ErrorKind::Vulkan, "",
                overlay_ ? "swapchain images cannot be blitted into and drawn to on this device"
                         : "swapchain images cannot be blitted into on this device");

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  info.minImageCount = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) info.minImageCount = std::min(info.minImageCount, caps.maxImageCount);
  info.imageFormat = format_;
  info.imageColorSpace = surfaceFormat.colorSpace;
  info.imageExtent = extent_;
  info.imageArrayLayers = 1;
  info.imageUsage = usage;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  if (!(caps.supportedCompositeAlpha & info.compositeAlpha))  // some compositors only inherit
    info.compositeAlpha = VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha &
                                                      ~(caps.supportedCompositeAlpha - 1));
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always supported; paces frames to the display
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;

  VkSwapchainKHR created = VK_NULL_HANDLE;
  check(vkCreateSwapchainKHR(device, &info, nullptr, &created), "vkCreateSwapchainKHR");
  vkDestroySwapchainKHR(device, swapchain_, nullptr);  // retired; present() waited for the GPU
  swapchain_ = created;

  uint32_t count = 0;
  check(vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr), "vkGetSwapchainImagesKHR");
  images_.resize(count);
  check(vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data()),
        "vkGetSwapchainImagesKHR");
  for (uint32_t i = 0; i < count; ++i) renderFinished_.push_back(createSemaphore(device));
  if (overlay_) {
    for (VkImage image : images_) {
      VkImageViewCreateInfo v{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      v.image = image;
      v.viewType = VK_IMAGE_VIEW_TYPE_2D;
      v.format = format_;
      v.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
      VkImageView view = VK_NULL_HANDLE;
      check(vkCreateImageView(device, &v, nullptr, &view), "vkCreateImageView");
      views_.push_back(view);
    }
    overlay_->imagesChanged(views_, format_, extent_, info.minImageCount);
  }
  outOfDate_ = false;
}

bool Swapchain::present(VkImage source, VkExtent2D sourceExtent, VkImageLayout layout) {
  VkDevice device = ctx_.device();
  // One frame in flight: the command buffer and the acquire semaphore are free again once the
  // previous submission finished.
  check(vkWaitForFences(device, 1, &inFlight_, VK_TRUE, UINT64_MAX), "vkWaitForFences");

  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  if (w == 0 || h == 0) return false;
  if (outOfDate_ || images_.empty() || windowSize_.width != uint32_t(w) ||
      windowSize_.height != uint32_t(h)) {
    vkDeviceWaitIdle(device);
    releaseImages();
    create();
    if (images_.empty()) return false;
  }
  uint32_t index = 0;
  VkResult r =
      vkAcquireNextImageKHR(device, swapchain_, UINT64_MAX, imageAcquired_, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    outOfDate_ = true;  // the semaphore was not signalled; skip this frame, recreate on the next
    return false;
  }
  if (r == VK_SUBOPTIMAL_KHR)
    outOfDate_ = true;  // still usable (the semaphore is signalled); recreate next frame
  else
    check(r, "vkAcquireNextImageKHR");

  record(source, sourceExtent, layout, index);
  VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  wait.semaphore = imageAcquired_;
  wait.stageMask =
      VK_PIPELINE_STAGE_2_BLIT_BIT;  // the layout transition before the blit chains to this
  VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  signal.semaphore = renderFinished_[index];
  signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cmdInfo.commandBuffer = cmd_;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.waitSemaphoreInfoCount = 1;
  submit.pWaitSemaphoreInfos = &wait;
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cmdInfo;
  submit.signalSemaphoreInfoCount = 1;
  submit.pSignalSemaphoreInfos = &signal;
  check(vkResetFences(device, 1, &inFlight_), "vkResetFences");
  check(vkQueueSubmit2(ctx_.queue(), 1, &submit, inFlight_), "vkQueueSubmit2");

  VkPresentInfoKHR presentInfo{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  presentInfo.waitSemaphoreCount = 1;
  presentInfo.pWaitSemaphores = &renderFinished_[index];
  presentInfo.swapchainCount = 1;
  presentInfo.pSwapchains = &swapchain_;
  presentInfo.pImageIndices = &index;
  r = vkQueuePresentKHR(ctx_.queue(), &presentInfo);
  if (r == VK_SUBOPTIMAL_KHR || r == VK_ERROR_OUT_OF_DATE_KHR)
    outOfDate_ = true;  // recreate before the next frame
  else
    check(r, "vkQueuePresentKHR");
  return r != VK_ERROR_OUT_OF_DATE_KHR;
}

void Swapchain::record(VkImage source, VkExtent2D sourceExtent, VkImageLayout layout,
                       uint32_t imageIndex) {
  check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd_, &begin), "vkBeginCommandBuffer");

  VkImage target = images_[imageIndex];
  const VkImageAspectFlags color = VK_IMAGE_ASPECT_COLOR_BIT;
  // The renderer's writes were submitted earlier on this queue: make them visible to the blit.
  imageBarrier(cmd_, source, color, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
               VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  // Old contents are not needed; srcStage BLIT waits for the acquire semaphore (same stage).
  imageBarrier(cmd_, target, color, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
               VK_PIPELINE_STAGE_2_BLIT_BIT, 0, VK_PIPELINE_STAGE_2_BLIT_BIT,
               VK_ACCESS_2_TRANSFER_WRITE_BIT);

  // Blit scales to the window and converts RGBA <-> BGRA channel order as needed.
  VkImageBlit region{};
  region.srcSubresource = {color, 0, 0, 1};
  region.srcOffsets[1] = {int32_t(sourceExtent.width), int32_t(sourceExtent.height), 1};
  region.dstSubresource = {color, 0, 0, 1};
  region.dstOffsets[1] = {int32_t(extent_.width), int32_t(extent_.height), 1};
  const bool sameSize =
      sourceExtent.width == extent_.width && sourceExtent.height == extent_.height;
  vkCmdBlitImage(cmd_, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region,
                 linearFilter_ && !sameSize ? VK_FILTER_LINEAR : VK_FILTER_NEAREST);

  // Back to the layout the renderer left it in; later submissions (the next frame overwrites
  // the source) wait for the blit's read.
  imageBarrier(cmd_, source, color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout,
               VK_PIPELINE_STAGE_2_BLIT_BIT, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0);
  if (overlay_) {
    imageBarrier(cmd_, target, color, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_BLIT_BIT,
                 VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    overlay_->record(cmd_, imageIndex);
    imageBarrier(cmd_, target, color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                 VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_NONE, 0);
  } else {
    imageBarrier(cmd_, target, color, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                 VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_2_BLIT_BIT,
                 VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_NONE, 0);
  }
  check(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
}

}  // namespace gi::vk
