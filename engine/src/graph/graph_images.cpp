#include "graph_images.h"

#include <bit>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/resources.h"

namespace gi::graph_detail {

namespace {

Error shapeError(const std::string& name, const std::string& problem) {
  return Error(ErrorKind::Usage, "", "frame graph: texture '" + name + "': " + problem);
}

}  // namespace

TextureDims resolveDims(const std::string& name, const TextureDesc& desc, VkExtent2D extent) {
  TextureDims d;
  d.format = desc.format;
  d.type = desc.type;
  d.extent = extent;
  d.layers = desc.layers;
  d.depth = 1;
  switch (desc.type) {
    case TextureType::Tex2D:
      if (desc.layers != 1) throw shapeError(name, "Tex2D has 1 layer (use Tex2DArray)");
      break;
    case TextureType::Tex2DArray:
      if (desc.layers == 0) throw shapeError(name, "an array needs at least 1 layer");
      break;
    case TextureType::Cube:
      d.layers = 6;  // forced: the six faces
      break;
    case TextureType::CubeArray:
      if (desc.layers == 0 || desc.layers % 6 != 0)
        throw shapeError(name, "a cube array's layers must be a positive multiple of 6, not " +
                                   std::to_string(desc.layers));
      break;
    case TextureType::Tex3D:
      if (desc.layers != 1) throw shapeError(name, "a 3-D texture has 1 layer (use depth)");
      d.depth = std::max(1u, desc.depth);
      break;
  }
  if (desc.type != TextureType::Tex3D && desc.depth != 1)
    throw shapeError(name, "depth is for 3-D textures only");
  if ((desc.type == TextureType::Cube || desc.type == TextureType::CubeArray) &&
      extent.width != extent.height)
    throw shapeError(name, "cube faces must be square, not " + std::to_string(extent.width) + "x" +
                               std::to_string(extent.height));
  const uint32_t largest = std::max({extent.width, extent.height, d.depth});
  const uint32_t chain = uint32_t(std::bit_width(largest));  // mips down to 1x1
  d.mips = desc.mips == 0 ? chain : desc.mips;
  if (d.mips > chain)
    throw shapeError(name, std::to_string(desc.mips) + " mips requested, but a " +
                               std::to_string(largest) + "-texel texture has at most " +
                               std::to_string(chain));
  return d;
}

Range resolveRange(const std::string& name, const Subresource& sub, const TextureDims& dims) {
  Range r;
  r.mip = sub.mip;
  r.layer = sub.layer;
  r.mipCount =
      sub.mipCount == Subresource::kAll ? dims.mips - std::min(sub.mip, dims.mips) : sub.mipCount;
  r.layerCount = sub.layerCount == Subresource::kAll
                     ? dims.layers - std::min(sub.layer, dims.layers)
                     : sub.layerCount;
  if (r.mipCount == 0 || r.layerCount == 0 || uint64_t(r.mip) + r.mipCount > dims.mips ||
      uint64_t(r.layer) + r.layerCount > dims.layers)
    throw shapeError(name, "subresource " + describeSubresource(sub) + " is outside its " +
                               std::to_string(dims.mips) + " mip(s) and " +
                               std::to_string(dims.layers) + " layer(s)");
  return r;
}

std::string describeSubresource(const Subresource& s) {
  auto part = [](const char* one, const char* many, uint32_t first, uint32_t count) {
    if (first == 0 && count == Subresource::kAll) return std::string();
    if (count == 1) return std::string(one) + " " + std::to_string(first);
    if (count == Subresource::kAll) return std::string(many) + " " + std::to_string(first) + "+";
    return std::string(many) + " " + std::to_string(first) + "-" +
           std::to_string(first + count - 1);
  };
  const std::string mips = part("mip", "mips", s.mip, s.mipCount);
  const std::string layers = part("layer", "layers", s.layer, s.layerCount);
  if (mips.empty() && layers.empty()) return "";
  return "[" + mips + (mips.empty() || layers.empty() ? "" : ", ") + layers + "]";
}

VkImageAspectFlags aspectOf(VkFormat format) {
  return vk::isDepthFormat(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

VkImageViewType naturalViewType(TextureType type) {
  switch (type) {
    case TextureType::Tex2D:
      return VK_IMAGE_VIEW_TYPE_2D;
    case TextureType::Tex2DArray:
      return VK_IMAGE_VIEW_TYPE_2D_ARRAY;
    case TextureType::Cube:
      return VK_IMAGE_VIEW_TYPE_CUBE;
    case TextureType::CubeArray:
      return VK_IMAGE_VIEW_TYPE_CUBE_ARRAY;
    case TextureType::Tex3D:
      return VK_IMAGE_VIEW_TYPE_3D;
  }
  return VK_IMAGE_VIEW_TYPE_2D;
}

VkImageUsageFlags supportedUsage(VkPhysicalDevice physical, VkFormat format) {
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(physical, format, &props);
  const VkFormatFeatureFlags f = props.optimalTilingFeatures;
  VkImageUsageFlags usage = 0;
  if (f & VK_FORMAT_FEATURE_TRANSFER_SRC_BIT) usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (f & VK_FORMAT_FEATURE_TRANSFER_DST_BIT) usage |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (f & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
  if (f & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT) usage |= VK_IMAGE_USAGE_STORAGE_BIT;
  if (f & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT) usage |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if (f & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)
    usage |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  return usage;
}

VkImage createImage(vk::Context& ctx, const TextureDims& d, VkImageUsageFlags usage) {
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = d.type == TextureType::Tex3D ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
  if (d.type == TextureType::Cube || d.type == TextureType::CubeArray)
    info.flags = VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT;
  info.format = d.format;
  info.extent = {d.extent.width, d.extent.height, d.depth};
  info.mipLevels = d.mips;
  info.arrayLayers = d.layers;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  VkImage image = VK_NULL_HANDLE;
  vk::check(vkCreateImage(ctx.device(), &info, nullptr, &image), "vkCreateImage (frame graph)");
  return image;
}

ImageViews::~ImageViews() {
  for (auto& [key, view] : views_) vkDestroyImageView(ctx_->device(), view, nullptr);
}

VkImageView ImageViews::get(const Range& r, VkImageViewType type) {
  const std::array<uint32_t, 5> key{r.mip, r.mipCount, r.layer, r.layerCount, uint32_t(type)};
  if (auto it = views_.find(key); it != views_.end()) return it->second;
  VkImageViewCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  info.image = image_;
  info.viewType = type;
  info.format = dims_.format;
  info.subresourceRange = {aspectOf(dims_.format), r.mip, r.mipCount, r.layer, r.layerCount};
  VkImageView view = VK_NULL_HANDLE;
  vk::check(vkCreateImageView(ctx_->device(), &info, nullptr, &view),
            "vkCreateImageView (frame graph)");
  views_.emplace(key, view);
  return view;
}

VkImageView ImageViews::ofRange(const Range& r) {
  if (dims_.type == TextureType::Tex3D) return get(r, VK_IMAGE_VIEW_TYPE_3D);
  return get(r, r.layerCount == 1 ? VK_IMAGE_VIEW_TYPE_2D : VK_IMAGE_VIEW_TYPE_2D_ARRAY);
}

namespace {

bool sameBarrier(const VkImageMemoryBarrier2& b, const SubBarrier& s) {
  return b.srcStageMask == s.srcStage && b.srcAccessMask == s.srcAccess &&
         b.dstStageMask == s.dstStage && b.dstAccessMask == s.dstAccess &&
         b.oldLayout == s.oldLayout && b.newLayout == s.newLayout;
}

bool sameSub(const SubBarrier& a, const SubBarrier& b) {
  return a.needed == b.needed && a.srcStage == b.srcStage && a.srcAccess == b.srcAccess &&
         a.dstStage == b.dstStage && a.dstAccess == b.dstAccess && a.oldLayout == b.oldLayout &&
         a.newLayout == b.newLayout;
}

}  // namespace

void appendBarriers(const std::vector<SubBarrier>& subs, const TextureDims& dims, VkImage image,
                    std::vector<VkImageMemoryBarrier2>& out) {
  const size_t first = out.size();
  const uint32_t L = dims.layers;
  for (uint32_t m = 0; m < dims.mips; ++m) {
    for (uint32_t l = 0; l < L;) {
      const SubBarrier& s = subs[m * L + l];
      if (!s.needed) {
        ++l;
        continue;
      }
      uint32_t end = l + 1;
      while (end < L && sameSub(subs[m * L + end], s)) ++end;
      bool merged = false;
      for (size_t k = first; k < out.size() && !merged; ++k) {
        VkImageSubresourceRange& r = out[k].subresourceRange;
        if (r.baseArrayLayer == l && r.layerCount == end - l &&
            r.baseMipLevel + r.levelCount == m && sameBarrier(out[k], s)) {
          ++r.levelCount;
          merged = true;
        }
      }
      if (!merged) {
        VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
        b.srcStageMask = s.srcStage;
        b.srcAccessMask = s.srcAccess;
        b.dstStageMask = s.dstStage;
        b.dstAccessMask = s.dstAccess;
        b.oldLayout = s.oldLayout;
        b.newLayout = s.newLayout;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.image = image;
        b.subresourceRange = {aspectOf(dims.format), m, 1, l, end - l};
        out.push_back(b);
      }
      l = end;
    }
  }
}

}  // namespace gi::graph_detail
