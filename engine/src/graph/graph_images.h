// Frame-graph image helpers: resolved texture shapes, image and view creation, and per-
// subresource barriers coalesced into as few ranges as possible.
#pragma once

#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "gi/graph/handles.h"
#include "gi/vk/context.h"

namespace gi::graph_detail {

// A texture's shape once its size class is resolved.
struct TextureDims {
  VkFormat format = VK_FORMAT_UNDEFINED;
  TextureType type = TextureType::Tex2D;
  VkExtent2D extent{};  // mip 0
  uint32_t depth = 1, mips = 1, layers = 1;
  bool operator==(const TextureDims& o) const {
    return format == o.format && type == o.type && extent.width == o.extent.width &&
           extent.height == o.extent.height && depth == o.depth && mips == o.mips &&
           layers == o.layers;
  }
  uint32_t subresources() const { return mips * layers; }
  VkExtent2D mipExtent(uint32_t mip) const {
    return {std::max(1u, extent.width >> mip), std::max(1u, extent.height >> mip)};
  }
};

// Checks `desc` against its type and resolves layers and mips for a mip-0 size `extent`.
// Throws gi::Error naming `name` when the description is inconsistent.
TextureDims resolveDims(const std::string& name, const TextureDesc& desc, VkExtent2D extent);

// A range within dims: kAll counts resolved; throws naming the texture when out of range.
struct Range {
  uint32_t mip = 0, mipCount = 1, layer = 0, layerCount = 1;
  bool covers(const TextureDims& d) const {
    return mip == 0 && mipCount == d.mips && layer == 0 && layerCount == d.layers;
  }
};
Range resolveRange(const std::string& name, const Subresource& sub, const TextureDims& dims);
// "" for the whole texture, else "[mip 1]", "[layer 2]", "[mips 1-3, layer 0]", ...
std::string describeSubresource(const Subresource& sub);

VkImageAspectFlags aspectOf(VkFormat format);
VkImageViewType naturalViewType(TextureType type);
// Usage flags `format` supports with optimal tiling (for images whose later use is unknown).
VkImageUsageFlags supportedUsage(VkPhysicalDevice physical, VkFormat format);
VkImage createImage(vk::Context& ctx, const TextureDims& dims, VkImageUsageFlags usage);

// The views of one image, created on first request and destroyed with this object (views
// handed in from outside, e.g. an imported image's, are not owned).
class ImageViews {
 public:
  ImageViews(vk::Context& ctx, VkImage image, const TextureDims& dims)
      : ctx_(&ctx), image_(image), dims_(dims) {}
  ~ImageViews();
  ImageViews(const ImageViews&) = delete;
  ImageViews& operator=(const ImageViews&) = delete;
  VkImageView get(const Range& r, VkImageViewType type);
  VkImageView natural() {
    return get({0, dims_.mips, 0, dims_.layers}, naturalViewType(dims_.type));
  }
  // A range's own view: 2-D for one layer, 2-D array for several, 3-D for 3-D textures.
  VkImageView ofRange(const Range& r);

 private:
  vk::Context* ctx_;
  VkImage image_;
  TextureDims dims_;
  std::map<std::array<uint32_t, 5>, VkImageView> views_;
};

// What one subresource needs before a pass (needed = false: nothing).
struct SubBarrier {
  bool needed = false;
  VkPipelineStageFlags2 srcStage = 0, dstStage = 0;
  VkAccessFlags2 srcAccess = 0, dstAccess = 0;
  VkImageLayout oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, newLayout = VK_IMAGE_LAYOUT_UNDEFINED;
};
// One barrier per subresource (index mip * layers + layer), coalesced: consecutive layers of a
// mip, then consecutive mips over the same layers, join when their barriers are identical.
void appendBarriers(const std::vector<SubBarrier>& subs, const TextureDims& dims, VkImage image,
                    std::vector<VkImageMemoryBarrier2>& out);

}  // namespace gi::graph_detail
