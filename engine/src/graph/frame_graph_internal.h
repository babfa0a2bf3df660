// The frame graph's private data (shared by frame_graph.cpp: setup, culling, allocation, and
// frame_graph_execute.cpp: barriers and recording). Not installed.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "gi/errors.h"
#include "gi/graph/frame_graph.h"
#include "gi/vk/common.h"
#include "gi/vk/resources.h"
#include "graph_images.h"

namespace gi {
namespace graph_detail {

struct SyncState {
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
};

constexpr VkAccessFlags2 kWriteAccess =
    VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
    VK_ACCESS_2_MEMORY_WRITE_BIT;
constexpr VkPipelineStageFlags2 kShaderStages = VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                                                VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;

inline SyncState required(TextureUsage u, bool depthFormat) {
  switch (u) {
    case TextureUsage::Sampled:
      return {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kShaderStages,
              VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
    case TextureUsage::StorageRead:
      return {VK_IMAGE_LAYOUT_GENERAL, kShaderStages, VK_ACCESS_2_SHADER_STORAGE_READ_BIT};
    case TextureUsage::StorageWrite:
      return {VK_IMAGE_LAYOUT_GENERAL, kShaderStages,
              VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT};
    case TextureUsage::ColorAttachment:
      return {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
              VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
              VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT};
    case TextureUsage::DepthAttachment:
      return {VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                  VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                  VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT};
    case TextureUsage::DepthRead:
      return {VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL,
              VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                  VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT};
    case TextureUsage::TransferSrc:
      return {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
              VK_ACCESS_2_TRANSFER_READ_BIT};
    case TextureUsage::TransferDst:
      return {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
              VK_ACCESS_2_TRANSFER_WRITE_BIT};
  }
  (void)depthFormat;
  return {};
}

inline SyncState required(BufferUsage u) {
  switch (u) {
    case BufferUsage::Uniform:
      return {{}, kShaderStages, VK_ACCESS_2_UNIFORM_READ_BIT};
    case BufferUsage::StorageRead:
      return {{}, kShaderStages, VK_ACCESS_2_SHADER_STORAGE_READ_BIT};
    case BufferUsage::StorageWrite:
      return {{},
              kShaderStages,
              VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT};
    case BufferUsage::Vertex:
      return {{},
              VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT,
              VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT};
    case BufferUsage::Index:
      return {{}, VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT, VK_ACCESS_2_INDEX_READ_BIT};
    case BufferUsage::Indirect:
      return {{}, VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT};
    case BufferUsage::TransferSrc:
      return {{}, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT};
    case BufferUsage::TransferDst:
      return {{}, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
  }
  return {};
}

inline VkImageUsageFlags imageUsageOf(TextureUsage u, bool depth) {
  switch (u) {
    case TextureUsage::Sampled:
      return VK_IMAGE_USAGE_SAMPLED_BIT;
    case TextureUsage::StorageRead:
    case TextureUsage::StorageWrite:
      return VK_IMAGE_USAGE_STORAGE_BIT;
    case TextureUsage::ColorAttachment:
      return VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    case TextureUsage::DepthAttachment:
    case TextureUsage::DepthRead:
      return VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    case TextureUsage::TransferSrc:
      return VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    case TextureUsage::TransferDst:
      return VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  }
  (void)depth;
  return 0;
}

inline VkBufferUsageFlags bufferUsageOf(BufferUsage u) {
  switch (u) {
    case BufferUsage::Uniform:
      return VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
    case BufferUsage::StorageRead:
    case BufferUsage::StorageWrite:
      return VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    case BufferUsage::Vertex:
      return VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
    case BufferUsage::Index:
      return VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
    case BufferUsage::Indirect:
      return VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
    case BufferUsage::TransferSrc:
      return VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    case BufferUsage::TransferDst:
      return VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  }
  return 0;
}

// Sync state of one subresource (or a whole buffer) during execute. `state`: the layout, every
// stage that used it since its last write (what a new write waits for) and that write's access.
// `lastWrite`: the last write's stage and access. `visible`: the stages and accesses a barrier
// already made that write visible to (a later read elsewhere needs one).
struct SubState {
  SyncState state, lastWrite, visible;
};

// What one pass needs of one subresource: its accesses combined (one layout, stages, accesses).
struct SubNeed {
  SyncState sync;
  bool read = false, write = false;
};

}  // namespace graph_detail

struct FrameGraph::Access {
  uint32_t resource = 0, version = 0;
  bool write = false;
  TextureUsage textureUsage = TextureUsage::Sampled;
  BufferUsage bufferUsage = BufferUsage::StorageRead;
  Subresource sub;            // as declared
  graph_detail::Range range;  // resolved by compile()
  bool partial = false;  // a write that leaves part of the texture as the previous version had it
};

struct FrameGraph::Pass {
  std::string name;
  std::string owner;  // the effect that added it ("": the engine)
  std::vector<Access> accesses;
  // Resolved by compile(): per texture the pass uses, its combined need of every subresource
  // (indexed mip * layers + layer), so coinciding ranges share one barrier in execute().
  std::vector<std::pair<uint32_t, std::vector<graph_detail::SubNeed>>> textureNeeds;
  bool sideEffect = false;
  bool culled = false;
  PassExecute execute;
};

// An image the graph owns beyond one compile: a persistent (history) or fallback texture.
struct FrameGraph::Owned {
  vk::Context* ctx = nullptr;
  graph_detail::TextureDims dims;
  VkImage image = VK_NULL_HANDLE;
  vk::Allocation allocation;
  VkImageUsageFlags usage = 0;
  std::unique_ptr<graph_detail::ImageViews> views;
  std::vector<graph_detail::SubState> subs;  // carried across frames
  VkClearColorValue clear{};
  bool needsClear = true;  // recorded at the start of the next execute()
  bool written = false;    // a frame wrote it since (re)creation: history is valid
  bool declared = false;   // in the graph being built (persistent)
  Owned(vk::Context& c, const graph_detail::TextureDims& d) : ctx(&c), dims(d) {
    usage = graph_detail::supportedUsage(c.physicalDevice(), d.format);
    if (!(usage & VK_IMAGE_USAGE_TRANSFER_DST_BIT) || !(usage & VK_IMAGE_USAGE_SAMPLED_BIT))
      throw Error(
          ErrorKind::Usage, "",
          "frame graph: format " + std::to_string(int(d.format)) +
              " cannot be sampled and cleared on this device (persistent/fallback texture)");
    image = graph_detail::createImage(c, d, usage);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(c.device(), image, &req);
    allocation = c.allocator().allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    vk::check(vkBindImageMemory(c.device(), image, allocation.memory, allocation.offset),
              "vkBindImageMemory (frame graph)");
    views = std::make_unique<graph_detail::ImageViews>(c, image, d);
    subs.resize(d.subresources());
  }
  ~Owned() {
    views.reset();
    vkDestroyImage(ctx->device(), image, nullptr);
    ctx->allocator().free(allocation);
  }
  Owned(const Owned&) = delete;
  Owned& operator=(const Owned&) = delete;
};

struct FrameGraph::Resource {
  std::string name;
  bool texture = true;
  bool imported = false, persistent = false, fallback = false;
  TextureDesc textureDesc;
  BufferDesc bufferDesc;
  uint32_t version = 0;  // latest version declared so far
  // Vulkan objects (imported, owned, or created by allocateTransients).
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  graph_detail::TextureDims dims;  // resolved by compile()
  VkImageLayout importLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImageLayout finalLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  graph_detail::SyncState state, lastWrite, visible;  // buffers
  // Textures: one per (mip, layer), index mip * layers + layer; an owned texture's live in the
  // Owned (they carry across graphs), imported ones' across frames of this graph.
  std::vector<graph_detail::SubState> ownSubs;
  std::vector<graph_detail::SubState>* subs = &ownSubs;
  graph_detail::ImageViews* views = nullptr;  // the transient's or owned image's, or ...
  std::unique_ptr<graph_detail::ImageViews>
      importedViews;  // ... subresource views of an imported image
  Owned* owned = nullptr;
  int transient = -1;
  int firstUse = -1, lastUse = -1;                                      // kept-pass indices
  bool external() const { return imported || persistent || fallback; }  // not transient
};

// A transient's Vulkan objects, and the memory range they are bound to (shared by aliases).
struct FrameGraph::Transient {
  vk::Context* ctx = nullptr;
  VkImage image = VK_NULL_HANDLE;
  std::unique_ptr<graph_detail::ImageViews> views;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkMemoryRequirements requirements{};
  int slot = -1;
  ~Transient() {
    views.reset();  // before the image
    if (image) vkDestroyImage(ctx->device(), image, nullptr);
    if (buffer) vkDestroyBuffer(ctx->device(), buffer, nullptr);
  }
};

// One memory range shared by transients whose lifetimes do not overlap.
struct FrameGraph::Slot {
  vk::Allocation allocation;
  VkDeviceSize size = 0, alignment = 1;
  uint32_t typeBits = 0;
  std::vector<std::pair<int, int>> lifetimes;  // first/last kept-pass index of each occupant
  // During execute: every stage that touched the memory this frame. A transient's first use
  // waits for them, since an earlier occupant's reads and writes share its memory.
  VkPipelineStageFlags2 usedStages = VK_PIPELINE_STAGE_2_NONE;
  // ... and every write access: an occupant's first use must also make those available (a
  // write after an earlier occupant's write is a hazard an execution dependency alone leaves).
  VkAccessFlags2 writtenAccess = VK_ACCESS_2_NONE;
};

}  // namespace gi
