// The Vulkan instance, device and queue the engine renders with, plus the services every pass
// needs: memory sub-allocation, one-shot command submission, the on-disk pipeline cache and the
// validation-message counter that tests turn into failures.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "gi/vk/memory.h"

namespace gi::vk {

class GuardCounters;  // gi/vk/guard_counters.h

struct ContextOptions {
  // Enables VK_LAYER_KHRONOS_validation and the debug messenger. Default: GI_VALIDATION=1.
  bool validation = false;
  // Picks a device whose name contains this text, or whose index it is ("0", "1").
  // Default: GI_DEVICE; empty: a discrete GPU if present, else the first other device.
  std::string device;
  // Instance extensions for a window surface (from glfwGetRequiredInstanceExtensions).
  std::vector<std::string> instanceExtensions;
  bool swapchain = false;  // enable VK_KHR_swapchain on the device
  // Pipeline cache file; default: $GI_PIPELINE_CACHE, else $XDG_CACHE_HOME or ~/.cache/gi/.
  std::string pipelineCachePath;

  static ContextOptions fromEnvironment();
};

class Context {
 public:
  explicit Context(const ContextOptions& options = ContextOptions::fromEnvironment());
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queueFamily_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  // Throws a clear Unsupported error when the device cannot run compute workgroups of x * y
  // invocations (Vulkan only guarantees 128); `who` names the shader in the message.
  void requireWorkgroup(uint32_t x, uint32_t y, const std::string& who) const;
  std::string deviceName() const { return properties_.deviceName; }
  MemoryAllocator& allocator() { return *allocator_; }
  VkPipelineCache pipelineCache() const { return pipelineCache_; }
  VkCommandPool commandPool() const { return commandPool_; }
  bool validationEnabled() const { return validation_; }

  // Records with `record` into a fresh command buffer, submits it and waits.
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record);

  // Validation messages of severity error / warning seen so far (all threads).
  uint32_t validationErrors() const { return errors_.load(); }
  uint32_t validationWarnings() const { return warnings_.load(); }
  std::vector<std::string> validationMessages() const;
  void savePipelineCache() const;
  // The shaders' guard counters (made on first use).
  GuardCounters& guards();

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(
      VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
  void createInstance(const ContextOptions& options);
  void pickPhysicalDevice(const std::string& wanted);
  void createDevice(bool swapchain);
  void loadPipelineCache();

  bool validation_ = false;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  VkCommandPool commandPool_ = VK_NULL_HANDLE;
  VkPipelineCache pipelineCache_ = VK_NULL_HANDLE;
  std::string pipelineCachePath_;
  std::unique_ptr<MemoryAllocator> allocator_;
  std::unique_ptr<GuardCounters> guards_;
  std::atomic<uint32_t> errors_{0}, warnings_{0};
  mutable std::mutex messagesMutex_;
  std::vector<std::string> messages_;
};

}  // namespace gi::vk
