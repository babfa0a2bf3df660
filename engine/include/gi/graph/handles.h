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

enum class TextureType { Tex2D, Tex2DArray, Cube, CubeArray, Tex3D };

// Existing members first, new ones appended, so aggregate initialisation stays valid.
struct TextureDesc {
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  SizeClass sizeClass = SizeClass::OutputRelative;
  float scale = 1.0f;
  uint32_t width = 0, height = 0;  // Absolute
  TextureHandle relativeTo;        // InputRelative
  TextureType type = TextureType::Tex2D;
  uint32_t layers = 1;  // array layers; Cube: 6 (forced), CubeArray: a multiple of 6
  uint32_t mips = 1;    // mip levels; 0 = the full chain down to 1x1
  uint32_t depth = 1;   // Tex3D only (not scaled by the size class)
};

// A range of mips and layers of a texture; the defaults name the whole texture. kAll counts
// run to the last mip / layer.
struct Subresource {
  static constexpr uint32_t kAll = ~0u;
  uint32_t mip = 0, mipCount = kAll, layer = 0, layerCount = kAll;
  static Subresource all() { return {}; }
  static Subresource one(uint32_t mip, uint32_t layer) { return {mip, 1, layer, 1}; }
  static Subresource mipLevel(uint32_t m) { return {m, 1, 0, kAll}; }
  static Subresource layerOf(uint32_t l) { return {0, kAll, l, 1}; }
  bool operator==(const Subresource&) const = default;
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
