#include "render/target_readback.h"

#include <cmath>
#include <cstring>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/resources.h"

namespace gi {

std::vector<uint8_t> readTexels(vk::Context& ctx, const FrameGraph::TextureState& t) {
  if (t.layout == VK_IMAGE_LAYOUT_UNDEFINED)
    throw Error(ErrorKind::Usage, "",
                "target read before any frame wrote it: render a frame after changing the "
                "effects, view, preset or size, then read");
  const bool depth = vk::isDepthFormat(t.format);
  const VkImageAspectFlags aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  const size_t bytes = size_t(t.extent.width) * t.extent.height * vk::formatBytesPerPixel(t.format);
  vk::Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  ctx.submitAndWait([&](VkCommandBuffer c) {
    vk::imageBarrier(c, t.image, aspect, t.layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {aspect, 0, 0, 1};
    copy.imageExtent = {t.extent.width, t.extent.height, 1};
    vkCmdCopyImageToBuffer(c, t.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(), 1,
                           &copy);
    vk::imageBarrier(c, t.image, aspect, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, t.layout,
                     VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0);
  });
  const auto* p = static_cast<const uint8_t*>(staging.mapped());
  return {p, p + bytes};
}

bool canDecode(VkFormat format) {
  switch (format) {
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R16G16B16A16_SFLOAT:
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R16_SFLOAT:
    case VK_FORMAT_R8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_R8G8B8A8_UNORM:
      return true;
    default:
      return false;
  }
}

ImageRGBA32F texelsToFloat(const std::vector<uint8_t>& raw, const FrameGraph::TextureState& t,
                           const std::string& name) {
  ImageRGBA32F img;
  img.width = int(t.extent.width);
  img.height = int(t.extent.height);
  const size_t n = size_t(t.extent.width) * t.extent.height;
  img.pixels.assign(n * 4, 0.0f);
  auto srgbToLinear = [](float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  };
  auto half = [&](size_t offset) {
    uint16_t h;
    std::memcpy(&h, &raw[offset], 2);
    return halfToFloat(h);
  };
  for (size_t i = 0; i < n; ++i) {
    float* o = &img.pixels[i * 4];
    switch (t.format) {
      case VK_FORMAT_D32_SFLOAT:
      case VK_FORMAT_R32_SFLOAT:
        std::memcpy(&o[0], &raw[i * 4], 4);
        o[3] = 1.0f;
        break;
      case VK_FORMAT_R32G32_SFLOAT:
        std::memcpy(o, &raw[i * 8], 8);
        o[3] = 1.0f;
        break;
      case VK_FORMAT_R32G32B32A32_SFLOAT:
        std::memcpy(o, &raw[i * 16], 16);
        break;
      case VK_FORMAT_R16G16B16A16_SFLOAT:
        for (size_t c = 0; c < 4; ++c) o[c] = half(i * 8 + c * 2);
        break;
      case VK_FORMAT_R16G16_SFLOAT:
        o[0] = half(i * 4);
        o[1] = half(i * 4 + 2);
        o[3] = 1.0f;
        break;
      case VK_FORMAT_R16_SFLOAT:
        o[0] = half(i * 2);
        o[3] = 1.0f;
        break;
      case VK_FORMAT_R8_UNORM:
        o[0] = raw[i] / 255.0f;
        o[3] = 1.0f;
        break;
      case VK_FORMAT_R8G8B8A8_SRGB:
        for (int c = 0; c < 4; ++c)
          o[c] = c < 3 ? srgbToLinear(raw[i * 4 + c] / 255.0f) : raw[i * 4 + c] / 255.0f;
        break;
      case VK_FORMAT_R8G8B8A8_UNORM:
        for (int c = 0; c < 4; ++c) o[c] = raw[i * 4 + c] / 255.0f;
        break;
      default:
        throw Error(ErrorKind::Unsupported, "",
                    "cannot read back '" + name + "': unsupported format");
    }
  }
  return img;
}

}  // namespace gi
