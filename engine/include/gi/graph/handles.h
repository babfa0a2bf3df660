// Typed, versioned resource handles and resource descriptions of the frame graph.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <limits>

namespace gi {

template <class Tag>
struct Handle {
  static constexpr uint32_t kInvalid = std::numeric_limits<uint32_t>::max();
  uint32_t id = kInvalid;
  uint32_t version = 0;  // bumped by every write; a handle of an older version is stale
  bool valid() const { return id != kInvalid; }
  bool operator==(const Handle&) const = default;
};

struct TextureTag {};
struct BufferTag {};
using TextureHandle = Handle<TextureTag>;
using BufferHandle = Handle<BufferTag>;

enum class SizeClass {
  Absolute,        // width x height
  OutputRelative,  // scale x the graph's output size (half-resolution work: 0.5)
  InputRelative,   // scale x the size of another texture (`relativeTo`), e.g. atlases
};

struct TextureDesc {
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  SizeClass sizeClass = SizeClass::OutputRelative;
  float scale = 1.0f;
  uint32_t width = 0, height = 0;  // Absolute
  TextureHandle relativeTo;        // InputRelative
};

struct BufferDesc {
  VkDeviceSize size = 0;
};

enum class TextureUsage {
  Sampled,          // read in a fragment or compute shader through a sampler
  StorageRead,      // imageLoad in compute
  StorageWrite,     // imageStore in compute
  ColorAttachment,  // rendered to
  DepthAttachment,  // depth test + write
  DepthRead,        // depth test without write
  TransferSrc,
  TransferDst,
};

enum class BufferUsage {
  Uniform,
  StorageRead,
  StorageWrite,
  Vertex,
  Index,
  Indirect,
  TransferSrc,
  TransferDst
};

}  // namespace gi
