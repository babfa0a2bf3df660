#include "presenter.h"

#include <imgui.h>
#include <imgui_impl_vulkan.h>

#include <algorithm>
#include <array>
#include <chrono>

#include "gi/errors.h"
#include "gi/vk/common.h"

namespace demo {

using gi::vk::check;

namespace {

void checkImgui(VkResult r) {
  check(r, "Dear ImGui Vulkan backend");
}

// The panel is drawn over the blitted image (LOAD), which the swapchain hands over and takes
// back in COLOR_ATTACHMENT_OPTIMAL (its barriers order the blit before this pass).
VkRenderPass createRenderPass(VkDevice device, VkFormat format) {
  VkAttachmentDescription color{};
  color.format = format;
  color.samples = VK_SAMPLE_COUNT_1_BIT;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &ref;
  VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rp.attachmentCount = 1;
  rp.pAttachments = &color;
  rp.subpassCount = 1;
  rp.pSubpasses = &subpass;
  VkRenderPass pass = VK_NULL_HANDLE;
  check(vkCreateRenderPass(device, &rp, nullptr, &pass), "vkCreateRenderPass");
  return pass;
}

}  // namespace

Presenter::Presenter(gi::vk::Context& ctx, GLFWwindow* window) : ctx_(ctx) {
  VkDevice device = ctx_.device();
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

  // Its first images come through imagesChanged(), which makes the render pass.
  swapchain_ = std::make_unique<gi::vk::Swapchain>(ctx_, window, this);
  if (!renderPass_)  // minimised at start: the panel's pass needs the surface's format
    throw gi::Error(gi::ErrorKind::Vulkan, "", "the window has no size to present to");
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = ctx_.instance();
  info.PhysicalDevice = ctx_.physicalDevice();
  info.Device = device;
  info.QueueFamily = ctx_.queueFamily();
  info.Queue = ctx_.queue();
  info.PipelineCache = ctx_.pipelineCache();
  info.DescriptorPool = imguiPool_;
  info.MinImageCount = std::max(minImageCount_, 2u);
  info.ImageCount = std::max(imageCount_, info.MinImageCount);
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
  swapchain_.reset();
  if (imguiReady_) ImGui_ImplVulkan_Shutdown();
  releaseFramebuffers();
  vkDestroyDescriptorPool(device, imguiPool_, nullptr);
  vkDestroyQueryPool(device, queries_, nullptr);
  vkDestroyRenderPass(device, renderPass_, nullptr);
}

void Presenter::releaseFramebuffers() {
  for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(ctx_.device(), f, nullptr);
  framebuffers_.clear();
}

void Presenter::imagesChanged(const std::vector<VkImageView>& views, VkFormat format,
                              VkExtent2D extent, uint32_t minImageCount) {
  VkDevice device = ctx_.device();
  if (!renderPass_) renderPass_ = createRenderPass(device, format);  // one surface, one format
  releaseFramebuffers();
  extent_ = extent;
  for (VkImageView view : views) {
    VkFramebufferCreateInfo f{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    f.renderPass = renderPass_;
    f.attachmentCount = 1;
    f.pAttachments = &view;
    f.width = extent.width;
    f.height = extent.height;
    f.layers = 1;
    VkFramebuffer fb = VK_NULL_HANDLE;
    check(vkCreateFramebuffer(device, &f, nullptr, &fb), "vkCreateFramebuffer");
    framebuffers_.push_back(fb);
  }
  minImageCount_ = minImageCount;
  imageCount_ = uint32_t(views.size());
  if (imguiReady_) ImGui_ImplVulkan_SetMinImageCount(std::max(minImageCount_, 2u));
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
  ui_ = ui;
  const bool shown = swapchain_->present(source, extent, layout);
  ui_ = nullptr;
  return shown;
}

void Presenter::record(VkCommandBuffer cmd, uint32_t index) {
  readUiTime();  // the swapchain waited for the previous frame, whose queries are done
  vkCmdResetQueryPool(cmd, queries_, 0, 2);
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_BLIT_BIT, queries_, 0);
  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = renderPass_;
  rp.framebuffer = framebuffers_[index];
  rp.renderArea.extent = extent_;
  vkCmdBeginRenderPass(cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
  const auto start = std::chrono::steady_clock::now();
  if (ui_) ImGui_ImplVulkan_RenderDrawData(ui_, cmd);
  uiRecordMs_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  vkCmdEndRenderPass(cmd);
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, queries_, 1);
  queriesPending_ = true;
}

}  // namespace demo
