// Small Vulkan helpers shared by the engine: result checking that throws gi::Error.
#pragma once

#include <vulkan/vulkan.h>

#include <string>

namespace gi::vk {

const char* resultName(VkResult result);
// Throws gi::Error(ErrorKind::Vulkan) naming the call when result is not VK_SUCCESS.
void check(VkResult result, const char* what);

}  // namespace gi::vk
