#include "gi/vk/context.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/guard_counters.h"

namespace gi::vk {

const char* resultName(VkResult r) {
  switch (r) {
    case VK_SUCCESS:
      return "VK_SUCCESS";
    case VK_NOT_READY:
      return "VK_NOT_READY";
    case VK_TIMEOUT:
      return "VK_TIMEOUT";
    case VK_INCOMPLETE:
      return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED:
      return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
      return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_FORMAT_NOT_SUPPORTED:
      return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_OUT_OF_DATE_KHR:
      return "VK_ERROR_OUT_OF_DATE_KHR";
    case VK_SUBOPTIMAL_KHR:
      return "VK_SUBOPTIMAL_KHR";
    case VK_ERROR_SURFACE_LOST_KHR:
      return "VK_ERROR_SURFACE_LOST_KHR";
    default:
      return "VkResult(unknown)";
  }
}

void check(VkResult result, const char* what) {
  if (result != VK_SUCCESS)
    throw Error(ErrorKind::Vulkan, "", std::string(what) + " failed: " + resultName(result));
}

ContextOptions ContextOptions::fromEnvironment() {
  ContextOptions o;
  if (const char* v = std::getenv("GI_VALIDATION")) o.validation = std::strcmp(v, "0") != 0;
  if (const char* d = std::getenv("GI_DEVICE")) o.device = d;
  return o;
}

namespace {

// A CPU driver (lavapipe) mallocs and frees its per-frame working memory (binned triangles,
// per-draw state) on every submission. glibc gives freed memory above its trim and mmap
// thresholds back to the system and moves the mmap threshold as it goes, so in some processes
// every frame faulted megabytes of pages back in: the demo's G-buffer pass measured 12 or 65 ms
// from one run to the next, with a fifth of the time in the page-fault handler (perf). Fixed
// thresholds keep that memory in the process (it stays at its peak; a GPU driver is left alone).
void keepFreedMemoryForACpuDriver() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest: blocks below it come from the heap
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace

Context::Context(const ContextOptions& options) : validation_(options.validation) {
  createInstance(options);
  pickPhysicalDevice(options.device);
  if (properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) keepFreedMemoryForACpuDriver();
  createDevice(options.swapchain);
  allocator_ = std::make_unique<MemoryAllocator>(physical_, device_);
  pipelineCachePath_ = options.pipelineCachePath;
  loadPipelineCache();
}

GuardCounters& Context::guards() {
  if (!guards_) guards_ = std::make_unique<GuardCounters>(*this);
  return *guards_;
}

Context::~Context() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    savePipelineCache();
    vkDestroyPipelineCache(device_, pipelineCache_, nullptr);
    vkDestroyCommandPool(device_, commandPool_, nullptr);
    guards_.reset();
    allocator_.reset();
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

VKAPI_ATTR VkBool32 VKAPI_CALL Context::debugCallback(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<Context*>(user);
  const char* level = "info";
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    self->errors_++;
    level = "error";
  } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    self->warnings_++;
    level = "warning";
  } else {
    return VK_FALSE;
  }
  std::string msg =
      std::string("[validation ") + level + "] " + (data->pMessage ? data->pMessage : "");
  std::fprintf(stderr, "%s\n", msg.c_str());
  std::lock_guard lock(self->messagesMutex_);
  self->messages_.push_back(std::move(msg));
  return VK_FALSE;
}

std::vector<std::string> Context::validationMessages() const {
  std::lock_guard lock(messagesMutex_);
  return messages_;
}

void Context::createInstance(const ContextOptions& options) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "gi";
  app.pEngineName = "gi";
  app.apiVersion = VK_API_VERSION_1_3;

  std::vector<const char*> extensions;
  for (const std::string& e : options.instanceExtensions) extensions.push_back(e.c_str());
  std::vector<const char*> layers;
  if (validation_) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> available(count);
    vkEnumerateInstanceLayerProperties(&count, available.data());
    bool found = false;
    for (auto& l : available) found |= std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0;
    if (!found)
      throw Error(ErrorKind::Vulkan, "",
                  "validation requested but VK_LAYER_KHRONOS_validation is not installed "
                  "(Debian package vulkan-validationlayers)");
    layers.push_back("VK_LAYER_KHRONOS_validation");
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }

  VkDebugUtilsMessengerCreateInfoEXT dbg{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  dbg.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  dbg.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  dbg.pfnUserCallback = &Context::debugCallback;
  dbg.pUserData = this;

  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  // Synchronization validation too: missing or wrong barriers (the frame graph derives them)
  // are errors like any other. Provided by the validation layer itself.
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  features.pNext = &dbg;
  if (validation_) info.pNext = &features;  // dbg also catches messages from instance creation
  check(vkCreateInstance(&info, nullptr, &instance_), "vkCreateInstance");

  if (validation_) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    check(create(instance_, &dbg, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
}

void Context::pickPhysicalDevice(const std::string& wanted) {
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  if (devices.empty())
    throw Error(ErrorKind::Vulkan, "",
                "no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");

  auto rank = [](VkPhysicalDeviceType t) {
    switch (t) {
      case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        return 0;
      case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        return 1;
      case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        return 2;
      case VK_PHYSICAL_DEVICE_TYPE_CPU:
        return 3;
      default:
        return 4;
    }
  };
  int best = -1;
  std::string names;
  for (uint32_t i = 0; i < count; ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(devices[i], &p);
    names += std::string(names.empty() ? "" : ", ") + std::to_string(i) + ": " + p.deviceName;
    if (p.apiVersion < VK_API_VERSION_1_3) continue;
    if (!wanted.empty()) {
      if (wanted == std::to_string(i) || std::strstr(p.deviceName, wanted.c_str()))
        best = static_cast<int>(i);
      continue;
    }
    if (best < 0) {
      best = static_cast<int>(i);
      continue;
    }
    VkPhysicalDeviceProperties b;
    vkGetPhysicalDeviceProperties(devices[best], &b);
    if (rank(p.deviceType) < rank(b.deviceType)) best = static_cast<int>(i);
  }
  if (best < 0)
    throw Error(ErrorKind::Vulkan, "",
                (wanted.empty() ? std::string("no Vulkan 1.3 device")
                                : "no Vulkan 1.3 device matches '" + wanted + "'") +
                    " (devices: " + names + ")");
  physical_ = devices[best];
  vkGetPhysicalDeviceProperties(physical_, &properties_);
}

void Context::createDevice(bool swapchain) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &count, families.data());
  queueFamily_ = UINT32_MAX;
  for (uint32_t i = 0; i < count; ++i) {
    const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    if ((families[i].queueFlags & need) == need && families[i].timestampValidBits > 0) {
      queueFamily_ = i;
      break;
    }
  }
  if (queueFamily_ == UINT32_MAX)
    throw Error(ErrorKind::Vulkan, "", "no graphics+compute queue with timestamps");

  float priority = 1.0f;
  VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  q.queueFamilyIndex = queueFamily_;
  q.queueCount = 1;
  q.pQueuePriorities = &priority;

  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  f13.dynamicRendering = VK_TRUE;
  f13.synchronization2 = VK_TRUE;
  f13.maintenance4 = VK_TRUE;  // SPIR-V 1.6 compute shaders use LocalSizeId
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12.pNext = &f13;
  f12.hostQueryReset = VK_TRUE;
  f12.scalarBlockLayout = VK_TRUE;
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features.pNext = &f12;
  VkPhysicalDeviceFeatures supported;
  vkGetPhysicalDeviceFeatures(physical_, &supported);
  features.features.samplerAnisotropy = supported.samplerAnisotropy;
  features.features.shaderStorageImageWriteWithoutFormat =
      supported.shaderStorageImageWriteWithoutFormat;
  features.features.geometryShader = supported.geometryShader;
  // GpuScene's paraboloid views clip the back hemisphere with gl_ClipDistance.
  if (!supported.shaderClipDistance)
    throw Error(ErrorKind::Unsupported, "", "the Vulkan device lacks shaderClipDistance");
  features.features.shaderClipDistance = VK_TRUE;
  features.features.fragmentStoresAndAtomics = supported.fragmentStoresAndAtomics;
  features.features.imageCubeArray = supported.imageCubeArray;  // frame-graph cube arrays

  std::vector<const char*> extensions;
  if (swapchain) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);

  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &features;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &q;
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  check(vkCreateDevice(physical_, &info, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = queueFamily_;
  check(vkCreateCommandPool(device_, &pool, nullptr, &commandPool_), "vkCreateCommandPool");
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = commandPool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd;
  check(vkAllocateCommandBuffers(device_, &alloc, &cmd), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &begin);
  record(cmd);
  vkEndCommandBuffer(cmd);

  VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence;
  check(vkCreateFence(device_, &fenceInfo, nullptr, &fence), "vkCreateFence");
  VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cmdInfo.commandBuffer = cmd;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cmdInfo;
  VkResult r = vkQueueSubmit2(queue_, 1, &submit, fence);
  if (r == VK_SUCCESS) r = vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX);
  vkDestroyFence(device_, fence, nullptr);
  vkFreeCommandBuffers(device_, commandPool_, 1, &cmd);
  check(r, "vkQueueSubmit2/vkWaitForFences");
}

namespace {
std::string defaultCachePath(const VkPhysicalDeviceProperties& p) {
  std::filesystem::path dir;
  if (const char* env = std::getenv("GI_PIPELINE_CACHE")) return env;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    dir = std::filesystem::path(xdg) / "gi";
  else if (const char* home = std::getenv("HOME"); home && *home)
    dir = std::filesystem::path(home) / ".cache" / "gi";
  else
    return {};
  char name[64];
  std::snprintf(name, sizeof name, "pipeline-cache-%04x-%04x.bin", p.vendorID, p.deviceID);
  return (dir / name).string();
}
}  // namespace

void Context::loadPipelineCache() {
  if (pipelineCachePath_.empty()) pipelineCachePath_ = defaultCachePath(properties_);
  std::vector<char> data;
  if (!pipelineCachePath_.empty()) {
    std::ifstream in(pipelineCachePath_, std::ios::binary);
    if (in) data.assign(std::istreambuf_iterator<char>(in), {});
  }
  // Only reuse data written by this exact device and driver (header holds the cache UUID).
  VkPipelineCacheHeaderVersionOne header{};
  if (data.size() < sizeof header) {
    data.clear();
  } else {
    std::memcpy(&header, data.data(), sizeof header);
    if (header.vendorID != properties_.vendorID || header.deviceID != properties_.deviceID ||
        std::memcmp(header.pipelineCacheUUID, properties_.pipelineCacheUUID, VK_UUID_SIZE) != 0)
      data.clear();
  }
  VkPipelineCacheCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  info.initialDataSize = data.size();
  info.pInitialData = data.empty() ? nullptr : data.data();
  check(vkCreatePipelineCache(device_, &info, nullptr, &pipelineCache_), "vkCreatePipelineCache");
}

void Context::savePipelineCache() const {
  if (pipelineCachePath_.empty() || !pipelineCache_) return;
  size_t size = 0;
  if (vkGetPipelineCacheData(device_, pipelineCache_, &size, nullptr) != VK_SUCCESS || size == 0)
    return;
  std::vector<char> data(size);
  if (vkGetPipelineCacheData(device_, pipelineCache_, &size, data.data()) != VK_SUCCESS) return;
  std::error_code ec;
  std::filesystem::path path(pipelineCachePath_);
  std::filesystem::create_directories(path.parent_path(), ec);
  // Write to a temporary file and rename, so a crash never leaves a torn cache behind.
  const std::string tmp = pipelineCachePath_ + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) return;
    out.write(data.data(), static_cast<std::streamsize>(size));
    if (!out) return;
  }
  std::filesystem::rename(tmp, path, ec);
}

void Context::requireWorkgroup(uint32_t x, uint32_t y, const std::string& who) const {
  const VkPhysicalDeviceLimits& l = properties_.limits;
  if (x * y <= l.maxComputeWorkGroupInvocations && x <= l.maxComputeWorkGroupSize[0] &&
      y <= l.maxComputeWorkGroupSize[1])
    return;
  throw Error(ErrorKind::Unsupported, "",
              who + " needs compute workgroups of " + std::to_string(x) + "x" + std::to_string(y) +
                  " invocations; " + deviceName() + " allows " +
                  std::to_string(l.maxComputeWorkGroupInvocations) + " (" +
                  std::to_string(l.maxComputeWorkGroupSize[0]) + "x" +
                  std::to_string(l.maxComputeWorkGroupSize[1]) + ")");
}

}  // namespace gi::vk
