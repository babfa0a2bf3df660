// RAII buffers, images and samplers whose memory comes from the context's sub-allocator.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstring>
#include <span>

#include "gi/vk/context.h"

namespace gi::vk {

class Buffer {
 public:
  Buffer() = default;
  // Host-visible buffers stay mapped (mapped() != nullptr).
  Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, bool hostVisible);
  ~Buffer() { reset(); }
  Buffer(Buffer&& o) noexcept { *this = std::move(o); }
  Buffer& operator=(Buffer&& o) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  void* mapped() const { return alloc_.mapped; }
  explicit operator bool() const { return buffer_ != VK_NULL_HANDLE; }
  void write(const void* data, size_t bytes, size_t offset = 0) {
    std::memcpy(static_cast<char*>(alloc_.mapped) + offset, data, bytes);
  }
  void reset();

 private:
  Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  Allocation alloc_;
};

// Device-local buffer filled through a staging copy.
Buffer createDeviceBuffer(Context& ctx, const void* data, VkDeviceSize size,
                          VkBufferUsageFlags usage);

struct ImageDesc {
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  uint32_t width = 1, height = 1, mipLevels = 1, layers = 1;
  VkImageUsageFlags usage = VK_IMAGE_USAGE_SAMPLED_BIT;
  VkImageCreateFlags flags = 0;
  VkImageViewType viewType = VK_IMAGE_VIEW_TYPE_2D;
};

class Image {
 public:
  Image() = default;
  Image(Context& ctx, const ImageDesc& desc);
  ~Image() { reset(); }
  Image(Image&& o) noexcept { *this = std::move(o); }
  Image& operator=(Image&& o) noexcept;
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;

  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }
  const ImageDesc& desc() const { return desc_; }
  VkImageAspectFlags aspect() const;
  explicit operator bool() const { return image_ != VK_NULL_HANDLE; }
  void reset();

 private:
  Context* ctx_ = nullptr;
  ImageDesc desc_;
  VkImage image_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  Allocation alloc_;
};

bool isDepthFormat(VkFormat format);
uint32_t formatBytesPerPixel(VkFormat format);

// Uploads tightly packed pixels into mip 0 of `image` and leaves it SHADER_READ_ONLY_OPTIMAL.
void uploadImage(Context& ctx, Image& image, const void* pixels, size_t bytes);

// One image memory barrier (synchronization2) for the whole image.
void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                  VkImageLayout oldLayout, VkImageLayout newLayout, VkPipelineStageFlags2 srcStage,
                  VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess);
// The same for a range of its mips and layers.
void imageBarrier(VkCommandBuffer cmd, VkImage image, const VkImageSubresourceRange& range,
                  VkImageLayout oldLayout, VkImageLayout newLayout, VkPipelineStageFlags2 srcStage,
                  VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess);

// A compute shader's storage writes to a GENERAL colour image made visible to a later compute
// dispatch that samples it (two dispatches inside one frame-graph pass: the graph orders
// passes, not the dispatches inside one).
void storageWriteToSampledRead(VkCommandBuffer cmd, VkImage image);

class Sampler {
 public:
  Sampler() = default;
  Sampler(Context& ctx, VkFilter filter, VkSamplerAddressMode address);
  ~Sampler() { reset(); }
  Sampler(Sampler&& o) noexcept { *this = std::move(o); }
  Sampler& operator=(Sampler&& o) noexcept;
  Sampler(const Sampler&) = delete;
  Sampler& operator=(const Sampler&) = delete;
  VkSampler handle() const { return sampler_; }
  void reset();

 private:
  Context* ctx_ = nullptr;
  VkSampler sampler_ = VK_NULL_HANDLE;
};

}  // namespace gi::vk
