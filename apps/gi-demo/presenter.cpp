#include "presenter.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_vulkan.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/resources.h"

namespace demo {

using gi::vk::check;

namespace {

// The renderer's output holds sRGB-encoded values: a UNORM format shows them as they are.
VkSurfaceFormatKHR pickFormat(VkPhysicalDevice physical, VkSurfaceKHR surface) {
  uint32_t count = 0;
  check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr),
        "vkGetPhysicalDeviceSurfaceFormatsKHR");
  std::vector<VkSurfaceFormatKHR> formats(count);
  check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()),
        "vkGetPhysicalDeviceSurfaceFormatsKHR");
  if (formats.empty())
    throw gi::Error(gi::ErrorKind::Vulkan, "", "the window surface offers no formats");
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == wanted && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
  return formats[0];
}

VkSemaphore createSemaphore(VkDevice device) {
  VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkSemaphore s;
  check(vkCreateSemaphore(device, &info, nullptr, &s), "vkCreateSemaphore");
  return s;
}

void checkImgui(VkResult r) {
  check(r, "Dear ImGui Vulkan backend");
}

}  // namespace

Presenter::Presenter(gi::vk::Context& ctx, GLFWwindow* window) : ctx_(ctx), window_(window) {
  VkDevice device = ctx_.device();
  check(glfwCreateWindowSurface(ctx_.instance(), window_, nullptr, &surface_),
        "glfwCreateWindowSurface");
  VkBool32 supported = VK_FALSE;
  check(vkGetPhysicalDeviceSurfaceSupportKHR(ctx_.physicalDevice(), ctx_.queueFamily(), surface_,
                                             &supported),
        "vkGetPhysicalDeviceSurfaceSupportKHR");
  if (!supported)
    throw gi::Error(gi::ErrorKind::Vulkan, "", "the device's queue cannot present to the window");
  format_ = pickFormat(ctx_.physicalDevice(), surface_);

  // After the blit (TRANSFER_DST) the UI is drawn over the image (LOAD) and it is presented.
  VkAttachmentDescription color{};
  color.format = format_.format;
  color.samples = VK_SAMPLE_COUNT_1_BIT;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  color.initialLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  color.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &ref;
  VkSubpassDependency dep{};
  dep.srcSubpass = VK_SUBPASS_EXTERNAL;
  dep.dstSubpass = 0;
  dep.srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dep.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  dep.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dep.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rp.attachmentCount = 1;
  rp.pAttachments = &color;
  rp.subpassCount = 1;
  rp.pSubpasses = &subpass;
  rp.dependencyCount = 1;
  rp.pDependencies = &dep;
  check(vkCreateRenderPass(device, &rp, nullptr, &renderPass_), "vkCreateRenderPass");

  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = ctx_.queueFamily();
  check(vkCreateCommandPool(device, &pool, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(device, &alloc, &cmd_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  check(vkCreateFence(device, &fence, nullptr, &inFlight_), "vkCreateFence");
  imageAcquired_ = createSemaphore(device);
  VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  q.queryType = VK_QUERY_TYPE_TIMESTAMP;
  q.queryCount = 2;
  check(vkCreateQueryPool(device, &q, nullptr, &queries_), "vkCreateQueryPool");

  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16};
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  dp.maxSets = 16;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &size;
  check(vkCreateDescriptorPool(device, &dp, nullptr, &imguiPool_), "vkCreateDescriptorPool");

  createSwapchain();
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = ctx_.instance();
  info.PhysicalDevice = ctx_.physicalDevice();
  info.Device = device;
  info.QueueFamily = ctx_.queueFamily();
  info.Queue = ctx_.queue();
  info.PipelineCache = ctx_.pipelineCache();
  info.DescriptorPool = imguiPool_;
  info.MinImageCount = std::max(minImageCount_, 2u);
  info.ImageCount = std::max(uint32_t(images_.size()), info.MinImageCount);
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  info.CheckVkResultFn = checkImgui;
  if (!ImGui_ImplVulkan_Init(&info, renderPass_))
    throw gi::Error(gi::ErrorKind::Vulkan, "", "Dear ImGui's Vulkan backend failed to start");
  imguiReady_ = true;
  ctx_.submitAndWait([](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
  ImGui_ImplVulkan_DestroyFontUploadObjects();
}

Presenter::~Presenter() {
  VkDevice device = ctx_.device();
  vkDeviceWaitIdle(device);
  if (imguiReady_) ImGui_ImplVulkan_Shutdown();
  releaseSwapchain();
  vkDestroySwapchainKHR(device, swapchain_, nullptr);
  vkDestroyDescriptorPool(device, imguiPool_, nullptr);
  vkDestroyQueryPool(device, queries_, nullptr);
  vkDestroySemaphore(device, imageAcquired_, nullptr);
  vkDestroyFence(device, inFlight_, nullptr);
  vkDestroyCommandPool(device, pool_, nullptr);
  vkDestroyRenderPass(device, renderPass_, nullptr);
  vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
}

void Presenter::releaseSwapchain() {
  VkDevice device = ctx_.device();
  for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(device, f, nullptr);
  for (VkImageView v : views_) vkDestroyImageView(device, v, nullptr);
  for (VkSemaphore s : renderFinished_) vkDestroySemaphore(device, s, nullptr);
  framebuffers_.clear();
  views_.clear();
  renderFinished_.clear();
  images_.clear();
}

void Presenter::createSwapchain() {
  VkPhysicalDevice physical = ctx_.physicalDevice();
  VkDevice device = ctx_.device();
  VkSurfaceCapabilitiesKHR caps;
  check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface_, &caps),
        "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  windowSize_ = {uint32_t(w), uint32_t(h)};
  extent_ = caps.currentExtent;
  if (extent_.width == std::numeric_limits<uint32_t>::max())
    extent_ = {std::clamp(uint32_t(w), caps.minImageExtent.width, caps.maxImageExtent.width),
               std::clamp(uint32_t(h), caps.minImageExtent.height, caps.maxImageExtent.height)};
  if (extent_.width == 0 || extent_.height == 0) return;  // minimised
  const VkImageUsageFlags usage =
      VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if ((caps.supportedUsageFlags & usage) != usage)
    throw gi::Error(gi::ErrorKind::Vulkan, "", "swapchain images cannot be blitted and drawn to");

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  minImageCount_ = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) minImageCount_ = std::min(minImageCount_, caps.maxImageCount);
  info.minImageCount = minImageCount_;
  info.imageFormat = format_.format;
  info.imageColorSpace = format_.colorSpace;
  info.imageExtent = extent_;
  info.imageArrayLayers = 1;
  info.imageUsage = usage;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  if (!(caps.supportedCompositeAlpha & info.compositeAlpha))
    info.compositeAlpha = VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha &
                                                      ~(caps.supportedCompositeAlpha - 1));
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  check(vkCreateSwapchainKHR(device, &info, nullptr, &created), "vkCreateSwapchainKHR");
  vkDestroySwapchainKHR(device, swapchain_, nullptr);
  swapchain_ = created;

  uint32_t count = 0;
  check(vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr), "vkGetSwapchainImagesKHR");
  images_.resize(count);
  check(vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data()),
        "vkGetSwapchainImagesKHR");
  for (VkImage image : images_) {
    VkImageViewCreateInfo v{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    v.image = image;
    v.viewType = VK_IMAGE_VIEW_TYPE_2D;
    v.format = format_.format;
    v.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view;
    check(vkCreateImageView(device, &v, nullptr, &view), "vkCreateImageView");
    views_.push_back(view);
    VkFramebufferCreateInfo f{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    f.renderPass = renderPass_;
    f.attachmentCount = 1;
    f.pAttachments = &view;
    f.width = extent_.width;
    f.height = extent_.height;
    f.layers = 1;
    VkFramebuffer fb;
    check(vkCreateFramebuffer(device, &f, nullptr, &fb), "vkCreateFramebuffer");
    framebuffers_.push_back(fb);
    renderFinished_.push_back(createSemaphore(device));
  }
  if (imguiReady_) ImGui_ImplVulkan_SetMinImageCount(std::max(minImageCount_, 2u));
  outOfDate_ = false;
}

void Presenter::readUiTime() {
  if (!queriesPending_) return;
  std::array<uint64_t, 2> t{};
  if (vkGetQueryPoolResults(ctx_.device(), queries_, 0, 2, sizeof(t), t.data(), sizeof(uint64_t),
                            VK_QUERY_RESULT_64_BIT) == VK_SUCCESS)
    uiGpuMs_ = double(t[1] - t[0]) * ctx_.properties().limits.timestampPeriod * 1e-6;
  queriesPending_ = false;
}

bool Presenter::present(VkImage source, VkExtent2D extent, VkImageLayout layout, ImDrawData* ui) {
  VkDevice device = ctx_.device();
  check(vkWaitForFences(device, 1, &inFlight_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  readUiTime();
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  if (w == 0 || h == 0) return false;
  if (outOfDate_ || images_.empty() || windowSize_.width != uint32_t(w) ||
      windowSize_.height != uint32_t(h)) {
    vkDeviceWaitIdle(device);
    releaseSwapchain();
    createSwapchain();
    if (images_.empty()) return false;
  }
  uint32_t index = 0;
  VkResult r =
      vkAcquireNextImageKHR(device, swapchain_, UINT64_MAX, imageAcquired_, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    outOfDate_ = true;
    return false;
  }
  if (r == VK_SUBOPTIMAL_KHR)
    outOfDate_ = true;
  else
    check(r, "vkAcquireNextImageKHR");

  record(source, extent, layout, ui, index);
  VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  wait.semaphore = imageAcquired_;
  wait.stageMask = VK_PIPELINE_STAGE_2_BLIT_BIT;
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
  queriesPending_ = true;

  VkPresentInfoKHR presentInfo{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  presentInfo.waitSemaphoreCount = 1;
  presentInfo.pWaitSemaphores = &renderFinished_[index];
  presentInfo.swapchainCount = 1;
  presentInfo.pSwapchains = &swapchain_;
  presentInfo.pImageIndices = &index;
  r = vkQueuePresentKHR(ctx_.queue(), &presentInfo);
  if (r == VK_SUBOPTIMAL_KHR || r == VK_ERROR_OUT_OF_DATE_KHR)
    outOfDate_ = true;
  else
    check(r, "vkQueuePresentKHR");
  return r != VK_ERROR_OUT_OF_DATE_KHR;
}

void Presenter::record(VkImage source, VkExtent2D extent, VkImageLayout layout, ImDrawData* ui,
                       uint32_t index) {
  using gi::vk::imageBarrier;
  check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd_, &begin), "vkBeginCommandBuffer");
  vkCmdResetQueryPool(cmd_, queries_, 0, 2);

  VkImage target = images_[index];
  const VkImageAspectFlags color = VK_IMAGE_ASPECT_COLOR_BIT;
  imageBarrier(cmd_, source, color, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
               VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  imageBarrier(cmd_, target, color, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
               VK_PIPELINE_STAGE_2_BLIT_BIT, 0, VK_PIPELINE_STAGE_2_BLIT_BIT,
               VK_ACCESS_2_TRANSFER_WRITE_BIT);
  VkImageBlit region{};
  region.srcSubresource = {color, 0, 0, 1};
  region.srcOffsets[1] = {int32_t(extent.width), int32_t(extent.height), 1};
  region.dstSubresource = {color, 0, 0, 1};
  region.dstOffsets[1] = {int32_t(extent_.width), int32_t(extent_.height), 1};
  const bool sameSize = extent.width == extent_.width && extent.height == extent_.height;
  vkCmdBlitImage(cmd_, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region,
                 sameSize ? VK_FILTER_NEAREST : VK_FILTER_LINEAR);
  imageBarrier(cmd_, source, color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout,
               VK_PIPELINE_STAGE_2_BLIT_BIT, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0);

  // The UI pass, timed; the render pass's dependency orders it after the blit.
  vkCmdWriteTimestamp2(cmd_, VK_PIPELINE_STAGE_2_BLIT_BIT, queries_, 0);
  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = renderPass_;
  rp.framebuffer = framebuffers_[index];
  rp.renderArea.extent = extent_;
  vkCmdBeginRenderPass(cmd_, &rp, VK_SUBPASS_CONTENTS_INLINE);
  const auto start = std::chrono::steady_clock::now();
  if (ui) ImGui_ImplVulkan_RenderDrawData(ui, cmd_);
  uiRecordMs_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  vkCmdEndRenderPass(cmd_);
  vkCmdWriteTimestamp2(cmd_, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, queries_, 1);
  check(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
}

}  // namespace demo
