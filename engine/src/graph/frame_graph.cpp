#include "gi/graph/frame_graph.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <sstream>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "graph_images.h"

namespace gi {

namespace {

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

SyncState required(TextureUsage u, bool depthFormat) {
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

SyncState required(BufferUsage u) {
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

VkImageUsageFlags imageUsageOf(TextureUsage u, bool depth) {
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

VkBufferUsageFlags bufferUsageOf(BufferUsage u) {
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

}  // namespace

using graph_detail::ImageViews;
using graph_detail::Range;
using graph_detail::SubBarrier;
using graph_detail::TextureDims;

namespace {

// Sync state of one subresource (or a whole buffer) during execute. `state`: the layout, every
// stage that used it since its last write (what a new write waits for) and that write's access.
// `lastWrite`: the last write's stage and access. `visible`: the stages and accesses a barrier
// already made that write visible to (a later read elsewhere needs one).
struct SubState {
  SyncState state, lastWrite, visible;
};

}  // namespace

struct FrameGraph::Access {
  uint32_t resource = 0, version = 0;
  bool write = false;
  TextureUsage textureUsage = TextureUsage::Sampled;
  BufferUsage bufferUsage = BufferUsage::StorageRead;
  Subresource sub;       // as declared
  Range range;           // resolved by compile()
  bool partial = false;  // a write that leaves part of the texture as the previous version had it
};

struct FrameGraph::Pass {
  std::string name;
  std::vector<Access> accesses;
  bool sideEffect = false;
  bool culled = false;
  PassExecute execute;
};

// An image the graph owns beyond one compile: a persistent (history) or fallback texture.
struct FrameGraph::Owned {
  vk::Context* ctx = nullptr;
  TextureDesc desc;
  TextureDims dims;
  VkImage image = VK_NULL_HANDLE;
  vk::Allocation allocation;
  VkImageUsageFlags usage = 0;
  std::unique_ptr<ImageViews> views;
  std::vector<SubState> subs;  // carried across frames
  VkClearColorValue clear{};
  bool needsClear = true;  // recorded at the start of the next execute()
  bool written = false;    // a frame wrote it since (re)creation: history is valid
  bool declared = false;   // in the graph being built (persistent)
  Owned(vk::Context& c, const TextureDims& d) : ctx(&c), dims(d) {
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
    views = std::make_unique<ImageViews>(c, image, d);
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
  TextureDims dims;  // resolved by compile()
  VkImageLayout importLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImageLayout finalLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  SyncState state, lastWrite, visible;  // buffers
  // Textures: one per (mip, layer), index mip * layers + layer; an owned texture's live in the
  // Owned (they carry across graphs), imported ones' across frames of this graph.
  std::vector<SubState> ownSubs;
  std::vector<SubState>* subs = &ownSubs;
  ImageViews* views = nullptr;                // the transient's or owned image's, or ...
  std::unique_ptr<ImageViews> importedViews;  // ... subresource views of an imported image
  Owned* owned = nullptr;
  int transient = -1;
  int firstUse = -1, lastUse = -1;                                      // kept-pass indices
  bool external() const { return imported || persistent || fallback; }  // not transient
};

// A transient's Vulkan objects, and the memory range they are bound to (shared by aliases).
struct FrameGraph::Transient {
  vk::Context* ctx = nullptr;
  VkImage image = VK_NULL_HANDLE;
  std::unique_ptr<ImageViews> views;
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
};

FrameGraph::FrameGraph(vk::Context& ctx, VkExtent2D outputExtent)
    : ctx_(ctx), outputExtent_(outputExtent) {
  if (outputExtent.width == 0 || outputExtent.height == 0)
    throw Error(ErrorKind::Usage, "", "frame graph output size must be at least 1x1");
}

FrameGraph::~FrameGraph() {
  reset();
  releasePersistent();
}

void FrameGraph::reset() {
  resources_.clear();  // imported images' views first
  pool_.clear();
  for (Slot& s : slots_) ctx_.allocator().free(s.allocation);
  slots_.clear();
  passes_.clear();
  outputs_.clear();
  blackboard_.clear();
  fallbackIds_.clear();
  for (auto& [name, p] : persistent_) p->declared = false;
  stats_ = {};
  compiled_ = false;
}

void FrameGraph::setOutputExtent(VkExtent2D e) {
  if (compiled_)
    throw Error(ErrorKind::Usage, "",
                "frame graph: setOutputExtent() after compile() (reset() first)");
  if (e.width == 0 || e.height == 0)
    throw Error(ErrorKind::Usage, "", "frame graph output size must be at least 1x1");
  outputExtent_ = e;
}

void FrameGraph::releasePersistent() {
  if (compiled_)
    throw Error(
        ErrorKind::Usage, "",
        "frame graph: releasePersistent() while a compiled graph uses them (reset() first)");
  for (auto& r : resources_)
    if (r->owned)
      throw Error(
          ErrorKind::Usage, "",
          "frame graph: releasePersistent() while '" + r->name + "' is declared (reset() first)");
  persistent_.clear();
  fallbacks_.clear();
}

void FrameGraph::declareFallback(const std::string& name, VkFormat format,
                                 VkClearColorValue value) {
  if (vk::isDepthFormat(format))
    throw Error(ErrorKind::Usage, "", "frame graph: fallback '" + name + "' needs a color format");
  auto it = fallbacks_.find(name);
  if (it != fallbacks_.end() && it->second->dims.format == format &&
      std::memcmp(&it->second->clear, &value, sizeof value) == 0)
    return;  // already declared like this
  if (fallbackIds_.count(name) || compiled_)
    throw Error(
        ErrorKind::Usage, "",
        "frame graph: fallback '" + name + "' changed while a graph uses it (reset() first)");
  TextureDims dims;
  dims.format = format;
  dims.extent = {1, 1};
  auto owned = std::make_unique<Owned>(ctx_, dims);
  owned->clear = value;
  fallbacks_[name] = std::move(owned);
}

TextureHandle FrameGraph::persistentTexture(const std::string& name, const TextureDesc& desc) {
  for (auto& r : resources_)
    if (r->persistent && r->name == name)
      throw Error(ErrorKind::Usage, "",
                  "frame graph: persistent texture '" + name + "' declared twice");
  if (desc.sizeClass == SizeClass::InputRelative && !desc.relativeTo.valid())
    throw Error(ErrorKind::Usage, "",
                "frame graph: '" + name + "' is input-relative but names no input");
  uint32_t id = addResource(name, true);
  Resource& r = *resources_[id];
  r.persistent = true;
  r.textureDesc = desc;
  return {id, 0};
}

bool FrameGraph::historyValid(TextureHandle h) const {
  const Resource& r = resource(h.id);
  if (!r.persistent)
    throw Error(ErrorKind::Usage, "",
                "frame graph: historyValid('" + r.name + "'): not a persistent texture");
  auto it = persistent_.find(r.name);
  if (it == persistent_.end() || !it->second->written) return false;
  if (compiled_) return it->second.get() == r.owned;
  // Before compile(): valid if compile() will keep the image (its resolved shape is the same).
  return it->second->dims == graph_detail::resolveDims(r.name, r.textureDesc, resolveExtent(h.id));
}

const FrameGraph::Resource& FrameGraph::resource(uint32_t id) const {
  if (id >= resources_.size())
    throw Error(ErrorKind::Usage, "", "frame graph: invalid resource handle");
  return *resources_[id];
}

uint32_t FrameGraph::addResource(const std::string& name, bool texture) {
  if (compiled_)
    throw Error(ErrorKind::Usage, "", "frame graph: cannot add '" + name + "' after compile()");
  auto r = std::make_unique<Resource>();
  r->name = name;
  r->texture = texture;
  resources_.push_back(std::move(r));
  return uint32_t(resources_.size() - 1);
}

void FrameGraph::checkCurrent(uint32_t id, uint32_t version, const char* what) const {
  const Resource& r = resource(id);
  if (version != r.version)
    throw Error(ErrorKind::Usage, "",
                std::string("frame graph: stale handle to '") + r.name + "' used for " + what +
                    " (version " + std::to_string(version) + ", current " +
                    std::to_string(r.version) + ")");
}

void FrameGraph::addPass(const std::string& name, const std::function<void(PassBuilder&)>& setup,
                         PassExecute execute) {
  if (compiled_)
    throw Error(ErrorKind::Usage, "",
                "frame graph: cannot add pass '" + name + "' after compile()");
  auto p = std::make_unique<Pass>();
  p->name = name;
  p->execute = std::move(execute);
  passes_.push_back(std::move(p));
  PassBuilder builder(*this, uint32_t(passes_.size() - 1));
  setup(builder);
}

TextureHandle PassBuilder::create(const std::string& name, const TextureDesc& desc) {
  if (desc.sizeClass == SizeClass::InputRelative && !desc.relativeTo.valid())
    throw Error(ErrorKind::Usage, "",
                "frame graph: '" + name + "' is input-relative but names no input");
  uint32_t id = graph_.addResource(name, true);
  graph_.resources_[id]->textureDesc = desc;
  return {id, 0};
}

BufferHandle PassBuilder::create(const std::string& name, const BufferDesc& desc) {
  uint32_t id = graph_.addResource(name, false);
  graph_.resources_[id]->bufferDesc = desc;
  return {id, 0};
}

TextureHandle PassBuilder::read(TextureHandle h, TextureUsage usage, const Subresource& sub) {
  graph_.checkCurrent(h.id, h.version, "a read");
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = h.version;
  a.textureUsage = usage;
  a.sub = sub;
  graph_.passes_[pass_]->accesses.push_back(a);
  return h;
}

BufferHandle PassBuilder::read(BufferHandle h, BufferUsage usage) {
  graph_.checkCurrent(h.id, h.version, "a read");
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = h.version;
  a.bufferUsage = usage;
  graph_.passes_[pass_]->accesses.push_back(a);
  return h;
}

TextureHandle PassBuilder::write(TextureHandle h, TextureUsage usage, const Subresource& sub) {
  graph_.checkCurrent(h.id, h.version, "a write");
  FrameGraph::Resource& r = *graph_.resources_[h.id];
  if (r.fallback)
    throw Error(ErrorKind::Usage, "",
                "frame graph: pass '" + graph_.passes_[pass_]->name + "' writes the fallback '" +
                    r.name + "' (fallbacks are read-only)");
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = ++r.version;
  a.write = true;
  a.textureUsage = usage;
  a.sub = sub;
  graph_.passes_[pass_]->accesses.push_back(a);
  return {h.id, a.version};
}

BufferHandle PassBuilder::write(BufferHandle h, BufferUsage usage) {
  graph_.checkCurrent(h.id, h.version, "a write");
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = ++graph_.resources_[h.id]->version;
  a.write = true;
  a.bufferUsage = usage;
  graph_.passes_[pass_]->accesses.push_back(a);
  return {h.id, a.version};
}

TextureHandle PassBuilder::readOptional(const std::string& name, TextureUsage usage) {
  if (TextureHandle h = graph_.blackboard_.texture(name); h.valid()) return read(h, usage);
  auto it = graph_.fallbacks_.find(name);
  if (it == graph_.fallbacks_.end())
    throw Error(ErrorKind::Usage, "",
                "frame graph: pass '" + graph_.passes_[pass_]->name + "' reads optional '" + name +
                    "', which no pass published and which has no fallback "
                    "(FrameGraph::declareFallback)");
  auto [id, isNew] = graph_.fallbackIds_.try_emplace(name, 0u);
  if (isNew) {
    id->second = graph_.addResource(name + " (fallback)", true);
    FrameGraph::Resource& r = *graph_.resources_[id->second];
    r.fallback = true;
    r.owned = it->second.get();
    r.textureDesc.format = r.owned->dims.format;
    r.textureDesc.sizeClass = SizeClass::Absolute;
    r.textureDesc.width = r.textureDesc.height = 1;
  }
  return read({id->second, 0}, usage);
}

bool PassBuilder::isFallback(TextureHandle h) const {
  return h.id < graph_.resources_.size() && graph_.resources_[h.id]->fallback;
}

void PassBuilder::sideEffect() {
  graph_.passes_[pass_]->sideEffect = true;
}

TextureHandle FrameGraph::importTexture(const std::string& name, VkImage image, VkImageView view,
                                        const TextureDesc& desc, VkImageLayout currentLayout,
                                        VkImageLayout finalLayout) {
  uint32_t id = addResource(name, true);
  Resource& r = *resources_[id];
  r.imported = true;
  r.textureDesc = desc;
  r.image = image;
  r.view = view;
  r.importLayout = currentLayout;
  r.finalLayout = finalLayout;
  return {id, 0};
}

BufferHandle FrameGraph::importBuffer(const std::string& name, VkBuffer buffer, VkDeviceSize size) {
  uint32_t id = addResource(name, false);
  Resource& r = *resources_[id];
  r.imported = true;
  r.buffer = buffer;
  r.bufferDesc.size = size;
  r.state = {VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
             VK_ACCESS_2_MEMORY_WRITE_BIT};
  return {id, 0};
}

void FrameGraph::markOutput(TextureHandle h) {
  resource(h.id);
  outputs_.emplace_back(h.id, h.version);
}
void FrameGraph::markOutput(BufferHandle h) {
  resource(h.id);
  outputs_.emplace_back(h.id, h.version);
}

VkExtent2D FrameGraph::resolveExtent(uint32_t id) const {
  const Resource& r = resource(id);
  const TextureDesc& d = r.textureDesc;
  auto scaled = [&](VkExtent2D e) {
    return VkExtent2D{std::max(1u, uint32_t(std::lround(e.width * d.scale))),
                      std::max(1u, uint32_t(std::lround(e.height * d.scale)))};
  };
  switch (d.sizeClass) {
    case SizeClass::Absolute:
      return {std::max(1u, d.width), std::max(1u, d.height)};
    case SizeClass::OutputRelative:
      return scaled(outputExtent_);
    case SizeClass::InputRelative:
      return scaled(resolveExtent(d.relativeTo.id));
  }
  return outputExtent_;
}

void FrameGraph::resolveTextures() {
  for (uint32_t id = 0; id < resources_.size(); ++id) {
    Resource& r = *resources_[id];
    if (!r.texture) continue;
    r.dims = r.fallback ? r.owned->dims
                        : graph_detail::resolveDims(r.name, r.textureDesc, resolveExtent(id));
  }
  for (auto& p : passes_)
    for (Access& a : p->accesses) {
      const Resource& r = *resources_[a.resource];
      if (!r.texture) continue;
      a.range = graph_detail::resolveRange(r.name, a.sub, r.dims);
      a.partial = a.write && !a.range.covers(r.dims);
    }
  // One subresource has one layout during a pass.
  for (auto& p : passes_)
    for (size_t i = 0; i < p->accesses.size(); ++i)
      for (size_t j = 0; j < i; ++j) {
        const Access& a = p->accesses[i];
        const Access& b = p->accesses[j];
        const Resource& r = *resources_[a.resource];
        if (a.resource != b.resource || !r.texture) continue;
        const bool overlap = a.range.mip < b.range.mip + b.range.mipCount &&
                             b.range.mip < a.range.mip + a.range.mipCount &&
                             a.range.layer < b.range.layer + b.range.layerCount &&
                             b.range.layer < a.range.layer + a.range.layerCount;
        const bool depth = vk::isDepthFormat(r.dims.format);
        if (overlap &&
            required(a.textureUsage, depth).layout != required(b.textureUsage, depth).layout)
          throw Error(ErrorKind::Usage, "",
                      "frame graph: pass '" + p->name + "' uses '" + r.name +
                          graph_detail::describeSubresource(a.sub) +
                          "' in two conflicting layouts");
      }
}

// Links this graph's persistent textures to their images, (re)creating those whose shape
// changed and freeing those no longer declared.
void FrameGraph::preparePersistent() {
  for (auto& r : resources_)
    if (r->persistent) {
      auto it = persistent_.find(r->name);
      if (it != persistent_.end() && !(it->second->dims == r->dims)) {
        persistent_.erase(it);  // resized or reshaped: the history is gone
        it = persistent_.end();
      }
      if (it == persistent_.end())
        it = persistent_.emplace(r->name, std::make_unique<Owned>(ctx_, r->dims)).first;
      it->second->declared = true;
      r->owned = it->second.get();
    }
  std::erase_if(persistent_, [](const auto& kv) { return !kv.second->declared; });
  for (auto& r : resources_)
    if (r->owned) {
      r->image = r->owned->image;
      r->views = r->owned->views.get();
      r->subs = &r->owned->subs;
      if (r->dims.type != TextureType::CubeArray) r->view = r->views->natural();
    } else if (r->imported && r->texture) {
      r->importedViews = std::make_unique<ImageViews>(ctx_, r->image, r->dims);
      r->views = r->importedViews.get();
      // Whatever came before is unknown: a write waits for all of it, a read in the same
      // layout needs no barrier.
      r->ownSubs.assign(r->dims.subresources(),
                        SubState{{r->importLayout, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                  VK_ACCESS_2_MEMORY_WRITE_BIT},
                                 {},
                                 {}});
    }
}

void FrameGraph::compile() {
  if (compiled_)
    throw Error(ErrorKind::Usage, "", "frame graph: compile() called twice (reset() first)");
  resolveTextures();
  preparePersistent();
  // A persistent texture's last version is next frame's history: an implicit output.
  std::vector<std::pair<uint32_t, uint32_t>> outputs = outputs_;
  for (uint32_t id = 0; id < resources_.size(); ++id)
    if (resources_[id]->persistent && resources_[id]->version > 0)
      outputs.emplace_back(id, resources_[id]->version);
  // Cull: walk passes backwards from the outputs, keeping each pass that writes a needed
  // version (or has a side effect) and marking what it reads as needed. A partial write also
  // needs the previous version: the subresources it leaves alone carry over.
  std::set<std::pair<uint32_t, uint32_t>> needed(outputs.begin(), outputs.end());
  for (auto it = passes_.rbegin(); it != passes_.rend(); ++it) {
    Pass& p = **it;
    bool keep = p.sideEffect;
    for (const Access& a : p.accesses)
      keep = keep || (a.write && needed.count({a.resource, a.version}));
    p.culled = !keep;
    if (!keep) continue;
    for (const Access& a : p.accesses) {
      if (!a.write) needed.insert({a.resource, a.version});
      if (a.partial) needed.insert({a.resource, a.version - 1});
    }
  }
  // Every kept read must have a producer (a kept write of that version, or an external one).
  std::set<std::pair<uint32_t, uint32_t>> produced;
  for (uint32_t id = 0; id < resources_.size(); ++id)
    if (resources_[id]->external()) produced.insert({id, 0});
  int order = 0;
  for (auto& p : passes_) {
    if (p->culled) continue;
    for (const Access& a : p->accesses) {
      Resource& r = *resources_[a.resource];
      if (!a.write && !produced.count({a.resource, a.version}))
        throw Error(
            ErrorKind::Usage, "",
            "frame graph: pass '" + p->name + "' reads '" + r.name + "' but no pass writes it");
      if (a.write) produced.insert({a.resource, a.version});
      if (r.owned && r.texture && (imageUsageOf(a.textureUsage, false) & ~r.owned->usage) != 0)
        throw Error(ErrorKind::Usage, "",
                    "frame graph: pass '" + p->name + "' uses '" + r.name +
                        "' in a way its format does not support (format " +
                        std::to_string(int(r.dims.format)) + ")");
      if (r.firstUse < 0) r.firstUse = order;
      r.lastUse = order;
    }
    ++order;
  }
  for (const auto& [id, version] : outputs_)
    if (!produced.count({id, version}))
      throw Error(ErrorKind::Usage, "",
                  "frame graph: output '" + resources_[id]->name + "' is never written");
  allocateTransients();
  compiled_ = true;
}

void FrameGraph::allocateTransients() {
  VkDevice device = ctx_.device();
  std::vector<uint32_t> transientIds;
  for (uint32_t id = 0; id < resources_.size(); ++id) {
    Resource& r = *resources_[id];
    if (r.external() || r.firstUse < 0) continue;  // not transient, or only used by culled passes
    auto t = std::make_unique<Transient>();
    t->ctx = &ctx_;
    if (r.texture) {
      const bool depth = vk::isDepthFormat(r.textureDesc.format);
      // Any target can be read back or sampled by a debug view; a view also needs one of these.
      VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
      for (auto& p : passes_)
        if (!p->culled)
          for (const Access& a : p->accesses)
            if (a.resource == id) usage |= imageUsageOf(a.textureUsage, depth);
      t->image = graph_detail::createImage(ctx_, r.dims, usage);
      vkGetImageMemoryRequirements(device, t->image, &t->requirements);
      r.ownSubs.resize(r.dims.subresources());
      ++stats_.transientTextures;
    } else {
      VkBufferUsageFlags usage = 0;
      for (auto& p : passes_)
        if (!p->culled)
          for (const Access& a : p->accesses)
            if (a.resource == id) usage |= bufferUsageOf(a.bufferUsage);
      VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
      info.size = std::max<VkDeviceSize>(r.bufferDesc.size, 16);
      info.usage = usage;
      vk::check(vkCreateBuffer(device, &info, nullptr, &t->buffer), "vkCreateBuffer (frame graph)");
      vkGetBufferMemoryRequirements(device, t->buffer, &t->requirements);
      ++stats_.transientBuffers;
    }
    stats_.transientBytesRequested += t->requirements.size;
    r.transient = int(pool_.size());
    pool_.push_back(std::move(t));
    transientIds.push_back(id);
  }

  // Aliasing: largest first, each resource goes into the first slot whose occupants' lifetimes
  // do not overlap its own and whose memory fits it; otherwise it opens a new slot.
  std::sort(transientIds.begin(), transientIds.end(), [&](uint32_t a, uint32_t b) {
    return pool_[resources_[a]->transient]->requirements.size >
           pool_[resources_[b]->transient]->requirements.size;
  });
  for (uint32_t id : transientIds) {
    Resource& r = *resources_[id];
    Transient& t = *pool_[r.transient];
    int chosen = -1;
    for (size_t s = 0; s < slots_.size() && chosen < 0; ++s) {
      Slot& slot = slots_[s];
      bool fits = slot.size >= t.requirements.size &&
                  (slot.typeBits & t.requirements.memoryTypeBits) &&
                  slot.alignment % t.requirements.alignment == 0;
      for (auto& [first, last] : slot.lifetimes)
        fits = fits && (r.lastUse < first || last < r.firstUse);
      if (fits) chosen = int(s);
    }
    if (chosen < 0) {
      Slot slot;
      slot.size = t.requirements.size;
      slot.alignment = t.requirements.alignment;
      slot.typeBits = t.requirements.memoryTypeBits;
      slot.allocation =
          ctx_.allocator().allocate(t.requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
      stats_.transientBytesAllocated += slot.allocation.size;
      slots_.push_back(std::move(slot));
      chosen = int(slots_.size() - 1);
    }
    Slot& slot = slots_[chosen];
    slot.lifetimes.emplace_back(r.firstUse, r.lastUse);
    t.slot = chosen;
    if (t.image) {
      vk::check(vkBindImageMemory(device, t.image, slot.allocation.memory, slot.allocation.offset),
                "vkBindImageMemory");
      t.views = std::make_unique<ImageViews>(ctx_, t.image, r.dims);
      r.views = t.views.get();
      // A cube array's natural view needs the imageCubeArray feature: made only when asked.
      if (r.dims.type != TextureType::CubeArray) r.view = t.views->natural();
      r.image = t.image;
    } else {
      vk::check(
          vkBindBufferMemory(device, t.buffer, slot.allocation.memory, slot.allocation.offset),
          "vkBindBufferMemory");
      r.buffer = t.buffer;
    }
  }
}

namespace {

// A read needs no barrier when nothing wrote the subresource yet, or a barrier already made the
// last write visible to this stage and access.
bool alreadyVisible(const SyncState& lastWrite, const SyncState& visible, const SyncState& need) {
  return lastWrite.access == VK_ACCESS_2_NONE ||
         ((need.stage & ~visible.stage) == 0 && (need.access & ~visible.access) == 0);
}

// Bookkeeping after a barrier for a write or a layout change to `need`.
void afterBarrier(SyncState& state, SyncState& lastWrite, SyncState& visible, const SyncState& need,
                  bool write) {
  state = need;
  if (write) {
    lastWrite = {need.layout, need.stage, need.access & kWriteAccess};
    visible = {};  // nothing has seen this write yet
  } else {
    visible = need;
  }
}

// What one pass needs of one subresource: all its accesses there, combined.
struct SubNeed {
  SyncState sync;
  bool read = false, write = false;
};

}  // namespace

// Persistent and fallback images start cleared (zero, or the fallback's value): recorded at the
// start of the frame, then treated as a write.
void FrameGraph::clearOwned(VkCommandBuffer cmd) {
  std::vector<Owned*> owned;
  for (auto& [name, o] : persistent_)
    if (o->needsClear) owned.push_back(o.get());
  for (auto& [name, o] : fallbacks_)
    if (o->needsClear) owned.push_back(o.get());
  if (owned.empty()) return;
  std::vector<VkImageMemoryBarrier2> barriers;
  for (Owned* o : owned) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = VK_PIPELINE_STAGE_2_NONE;
    b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
    b.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = o->image;
    b.subresourceRange = {graph_detail::aspectOf(o->dims.format), 0, VK_REMAINING_MIP_LEVELS, 0,
                          VK_REMAINING_ARRAY_LAYERS};
    barriers.push_back(b);
  }
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = uint32_t(barriers.size());
  dep.pImageMemoryBarriers = barriers.data();
  vkCmdPipelineBarrier2(cmd, &dep);
  const SyncState cleared{VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
  for (size_t i = 0; i < owned.size(); ++i) {
    Owned* o = owned[i];
    const VkImageSubresourceRange& range = barriers[i].subresourceRange;
    if (vk::isDepthFormat(o->dims.format)) {
      VkClearDepthStencilValue zero{};
      vkCmdClearDepthStencilImage(cmd, o->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1,
                                  &range);
    } else {
      vkCmdClearColorImage(cmd, o->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &o->clear, 1,
                           &range);
    }
    for (SubState& s : o->subs) s = {cleared, cleared, {}};
    o->needsClear = false;
    o->written = false;
  }
}

void FrameGraph::execute(VkCommandBuffer cmd, vk::DescriptorArena& descriptors, vk::GpuTimer* timer,
                         const PassBoundary& afterPass) {
  if (!compiled_) throw Error(ErrorKind::Usage, "", "frame graph: execute() before compile()");
  // Transient contents never survive a frame: they start undefined.
  for (auto& r : resources_)
    if (!r->external()) {
      r->state = r->lastWrite = r->visible = {};
      for (SubState& s : r->ownSubs) s = {};
    }
  for (Slot& slot : slots_) slot.usedStages = VK_PIPELINE_STAGE_2_NONE;
  clearOwned(cmd);
  // The memory slot under a transient (nullptr for external resources).
  auto slotOf = [this](const Resource& r) -> Slot* {
    if (r.external() || r.transient < 0) return nullptr;
    const int slot = pool_[size_t(r.transient)]->slot;
    return slot >= 0 ? &slots_[size_t(slot)] : nullptr;
  };

  PassContext pc;
  pc.graph_ = this;
  pc.ctx_ = &ctx_;
  pc.descriptors_ = &descriptors;
  pc.cmd_ = cmd;
  for (auto& p : passes_) {
    if (p->culled) continue;
    std::vector<VkImageMemoryBarrier2> imageBarriers;
    std::vector<VkBufferMemoryBarrier2> bufferBarriers;
    // Textures: combine the pass's accesses per subresource first, so that coinciding ranges
    // share one barrier and different ranges of one image get their own.
    std::vector<uint32_t> images;
    std::unordered_map<uint32_t, std::vector<SubNeed>> needs;
    for (const Access& a : p->accesses) {
      Resource& r = *resources_[a.resource];
      if (!r.texture) continue;
      std::vector<SubNeed>& subs = needs[a.resource];
      if (subs.empty()) {
        subs.resize(r.dims.subresources());
        images.push_back(a.resource);
      }
      const SyncState n = required(a.textureUsage, vk::isDepthFormat(r.dims.format));
      for (uint32_t m = a.range.mip; m < a.range.mip + a.range.mipCount; ++m)
        for (uint32_t l = a.range.layer; l < a.range.layer + a.range.layerCount; ++l) {
          SubNeed& x = subs[m * r.dims.layers + l];
          if ((x.read || x.write) && x.sync.layout != n.layout)
            throw Error(ErrorKind::Usage, "",
                        "frame graph: pass '" + p->name + "' uses '" + r.name +
                            graph_detail::describeSubresource(Subresource::one(m, l)) +
                            "' in two conflicting layouts");
          x.sync.layout = n.layout;
          x.sync.stage |= n.stage;
          x.sync.access |= n.access;
          (a.write ? x.write : x.read) = true;
        }
    }
    for (uint32_t id : images) {
      Resource& r = *resources_[id];
      Slot* slot = slotOf(r);
      const std::vector<SubNeed>& subs = needs[id];
      std::vector<SubBarrier> barriers(subs.size());
      VkPipelineStageFlags2 used = VK_PIPELINE_STAGE_2_NONE;
      for (size_t i = 0; i < subs.size(); ++i) {
        const SubNeed& x = subs[i];
        if (!x.read && !x.write) continue;
        SubState& st = (*r.subs)[i];
        used |= x.sync.stage;
        const bool sameLayoutRead = !x.write && st.state.layout == x.sync.layout;
        if (sameLayoutRead && alreadyVisible(st.lastWrite, st.visible, x.sync)) {
          st.state.stage |= x.sync.stage;  // a later write waits for this reader too
          continue;
        }
        SubBarrier& b = barriers[i];
        b.needed = true;
        // A read in the same layout waits for the last write only; a write or a layout change
        // waits for every use since (write-after-read needs the readers done).
        // (The last write's own stage joins too: its access must be in a stage of the mask.)
        b.srcStage = sameLayoutRead ? st.lastWrite.stage : st.state.stage | st.lastWrite.stage;
        b.srcAccess = st.lastWrite.access;
        b.dstStage = x.sync.stage;
        b.dstAccess = x.sync.access;
        // A transient's previous contents may be discarded where this pass only writes.
        const bool discard = x.write && !x.read && !r.external();
        b.oldLayout = discard ? VK_IMAGE_LAYOUT_UNDEFINED : st.state.layout;
        b.newLayout = x.sync.layout;
        if (b.srcStage == VK_PIPELINE_STAGE_2_NONE && slot)  // first use of aliased memory
          b.srcStage = slot->usedStages;
        if (b.srcStage == VK_PIPELINE_STAGE_2_NONE)
          b.srcStage = VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT;
        if (sameLayoutRead) {
          st.state.stage |= x.sync.stage;
          st.visible.stage |= x.sync.stage;
          st.visible.access |= x.sync.access;
        } else {
          afterBarrier(st.state, st.lastWrite, st.visible, x.sync, x.write);
        }
      }
      if (slot) slot->usedStages |= used;
      graph_detail::appendBarriers(barriers, r.dims, r.image, imageBarriers);
    }
    for (const Access& a : p->accesses) {
      Resource& r = *resources_[a.resource];
      if (r.texture) continue;
      SyncState need = required(a.bufferUsage);
      if (!a.write && alreadyVisible(r.lastWrite, r.visible, need)) {
        r.state.stage |= need.stage;
        if (Slot* slot = slotOf(r)) slot->usedStages |= need.stage;
        continue;
      }
      Slot* slot = slotOf(r);
      VkPipelineStageFlags2 src = a.write ? r.state.stage | r.lastWrite.stage : r.lastWrite.stage;
      if (src == VK_PIPELINE_STAGE_2_NONE && slot) src = slot->usedStages;  // aliased memory
      if (slot) slot->usedStages |= need.stage;
      if (src != VK_PIPELINE_STAGE_2_NONE) {
        VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
        b.srcStageMask = src;
        b.srcAccessMask = r.lastWrite.access;
        b.dstStageMask = need.stage;
        b.dstAccessMask = need.access;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.buffer = r.buffer;
        b.size = VK_WHOLE_SIZE;
        bufferBarriers.push_back(b);
      }
      if (a.write) {
        afterBarrier(r.state, r.lastWrite, r.visible, need, true);
      } else {
        r.state.stage |= need.stage;
        r.visible.stage |= need.stage;
        r.visible.access |= need.access;
      }
    }
    if (!imageBarriers.empty() || !bufferBarriers.empty()) {
      VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
      dep.imageMemoryBarrierCount = uint32_t(imageBarriers.size());
      dep.pImageMemoryBarriers = imageBarriers.data();
      dep.bufferMemoryBarrierCount = uint32_t(bufferBarriers.size());
      dep.pBufferMemoryBarriers = bufferBarriers.data();
      vkCmdPipelineBarrier2(cmd, &dep);
    }
    if (timer) timer->begin(cmd, p->name);
    p->execute(pc);
    if (timer) timer->end(cmd);
    if (afterPass) pc.cmd_ = cmd = afterPass(cmd);
  }
  // Leave imported images in the layout their owner asked for, each subresource from its own.
  std::vector<VkImageMemoryBarrier2> finals;
  for (auto& r : resources_) {
    if (!r->imported || !r->texture || r->finalLayout == VK_IMAGE_LAYOUT_UNDEFINED) continue;
    std::vector<SubBarrier> barriers(r->ownSubs.size());
    for (size_t i = 0; i < barriers.size(); ++i) {
      SyncState& s = r->ownSubs[i].state;
      if (s.layout == r->finalLayout) continue;
      barriers[i] = {true,
                     s.stage ? s.stage : VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     s.access & kWriteAccess,
                     VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                     s.layout,
                     r->finalLayout};
      s = {r->finalLayout, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT};
    }
    graph_detail::appendBarriers(barriers, r->dims, r->image, finals);
  }
  if (!finals.empty()) {
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = uint32_t(finals.size());
    dep.pImageMemoryBarriers = finals.data();
    vkCmdPipelineBarrier2(cmd, &dep);
  }
  // A persistent texture some kept pass wrote now holds history for the next frame.
  for (auto& p : passes_)
    if (!p->culled)
      for (const Access& a : p->accesses)
        if (a.write && resources_[a.resource]->persistent)
          resources_[a.resource]->owned->written = true;
}

FrameGraph::TextureState FrameGraph::textureState(TextureHandle h) const {
  const Resource& r = resource(h.id);
  if (!r.texture || !r.image)
    throw Error(ErrorKind::Usage, "",
                "frame graph: '" + r.name + "' was not produced (its passes were culled)");
  const VkImageLayout layout = r.subs->empty() ? r.importLayout : (*r.subs)[0].state.layout;
  return {r.image, r.view, r.textureDesc.format, r.imported ? resolveExtent(h.id) : r.dims.extent,
          layout};
}

std::vector<std::string> FrameGraph::executedPasses() const {
  std::vector<std::string> out;
  for (auto& p : passes_)
    if (!p->culled) out.push_back(p->name);
  return out;
}

std::vector<std::string> FrameGraph::culledPasses() const {
  std::vector<std::string> out;
  for (auto& p : passes_)
    if (p->culled) out.push_back(p->name);
  return out;
}

std::string FrameGraph::describe() const {
  std::ostringstream s;
  s << "frame graph: " << executedPasses().size() << " pass(es) executed, " << culledPasses().size()
    << " culled\n";
  for (auto& p : passes_) {
    s << (p->culled ? "  [culled] " : "  [run]    ") << p->name;
    std::string reads, writes;
    for (const Access& a : p->accesses) {
      const Resource& r = *resources_[a.resource];
      (a.write ? writes : reads) += " " + r.name + (r.persistent ? " (persistent)" : "") +
                                    (r.texture ? graph_detail::describeSubresource(a.sub) : "");
    }
    s << "\n      reads:" << (reads.empty() ? " -" : reads)
      << "\n      writes:" << (writes.empty() ? " -" : writes) << "\n";
  }
  s << "transient resources: " << stats_.transientTextures << " image(s), "
    << stats_.transientBuffers << " buffer(s), " << stats_.transientBytesRequested / 1024
    << " KiB requested, " << stats_.transientBytesAllocated / 1024
    << " KiB allocated after aliasing\n";
  return s.str();
}

std::string FrameGraph::toDot() const {
  std::ostringstream s;
  s << "digraph framegraph {\n  rankdir=LR;\n  node [fontname=\"sans\"];\n";
  for (size_t i = 0; i < passes_.size(); ++i)
    s << "  p" << i << " [shape=box, label=\"" << passes_[i]->name << "\""
      << (passes_[i]->culled ? ", style=dashed, color=gray" : ", style=filled, fillcolor=lightblue")
      << "];\n";
  for (size_t r = 0; r < resources_.size(); ++r) {
    const Resource& res = *resources_[r];
    s << "  r" << r << " [shape=ellipse, label=\"" << res.name
      << (res.persistent ? "\\n(persistent)\", style=bold, color=darkgreen" : "\"")
      << (res.imported ? ", peripheries=2" : "") << "];\n";
  }
  for (size_t i = 0; i < passes_.size(); ++i)
    for (const Access& a : passes_[i]->accesses) {
      const std::string sub =
          resources_[a.resource]->texture ? graph_detail::describeSubresource(a.sub) : "";
      std::string attrs;
      if (!sub.empty()) attrs += "label=\"" + sub + "\"";
      if (passes_[i]->culled)
        attrs += std::string(attrs.empty() ? "" : ", ") + "style=dashed, color=gray";
      if (!attrs.empty()) attrs = " [" + attrs + "]";
      if (a.write)
        s << "  p" << i << " -> r" << a.resource << attrs << ";\n";
      else
        s << "  r" << a.resource << " -> p" << i << attrs << ";\n";
    }
  s << "}\n";
  return s.str();
}

VkImage PassContext::image(TextureHandle h) const {
  return graph_->resource(h.id).image;
}
VkImageView PassContext::view(TextureHandle h) const {
  const auto& r = graph_->resource(h.id);
  if (!r.view && r.views) return r.views->natural();  // a cube array's, made on request
  return r.view;
}
VkImageView PassContext::view(TextureHandle h, const Subresource& sub) const {
  const auto& r = graph_->resource(h.id);
  if (!r.views)
    throw Error(ErrorKind::Usage, "", "frame graph: '" + r.name + "' has no image to view");
  return r.views->ofRange(graph_detail::resolveRange(r.name, sub, r.dims));
}
VkFormat PassContext::format(TextureHandle h) const {
  return graph_->resource(h.id).textureDesc.format;
}
VkBuffer PassContext::buffer(BufferHandle h) const {
  return graph_->resource(h.id).buffer;
}
VkDeviceSize PassContext::bufferSize(BufferHandle h) const {
  return graph_->resource(h.id).bufferDesc.size;
}
VkExtent2D PassContext::outputExtent() const {
  return graph_->outputExtent();
}
VkExtent2D PassContext::extent(TextureHandle h, uint32_t mip) const {
  return graph_->resource(h.id).dims.mipExtent(mip);
}
uint32_t PassContext::layers(TextureHandle h) const {
  return graph_->resource(h.id).dims.layers;
}
uint32_t PassContext::mips(TextureHandle h) const {
  return graph_->resource(h.id).dims.mips;
}

void PassContext::barrier(TextureHandle h, const Subresource& sub) const {
  const auto& r = graph_->resource(h.id);
  const graph_detail::Range range = graph_detail::resolveRange(r.name, sub, r.dims);
  std::vector<SubBarrier> barriers(r.dims.subresources());
  for (uint32_t m = range.mip; m < range.mip + range.mipCount; ++m)
    for (uint32_t l = range.layer; l < range.layer + range.layerCount; ++l) {
      const uint32_t i = m * r.dims.layers + l;
      SubState& st = (*r.subs)[i];
      if ((st.state.access & kWriteAccess) == 0) continue;  // this pass does not write it
      barriers[i] = {true,
                     st.state.stage,
                     st.state.stage,
                     st.state.access & kWriteAccess,
                     st.state.access,
                     st.state.layout,
                     st.state.layout};
      // `visible` stays as it was: the pass may write the range again after this barrier.
    }
  std::vector<VkImageMemoryBarrier2> out;
  graph_detail::appendBarriers(barriers, r.dims, r.image, out);
  if (out.empty()) return;
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = uint32_t(out.size());
  dep.pImageMemoryBarriers = out.data();
  vkCmdPipelineBarrier2(cmd_, &dep);
}

TextureHandle Blackboard::texture(const std::string& name) const {
  auto it = textures_.find(name);
  return it == textures_.end() ? TextureHandle{} : it->second;
}

BufferHandle Blackboard::buffer(const std::string& name) const {
  auto it = buffers_.find(name);
  return it == buffers_.end() ? BufferHandle{} : it->second;
}

std::vector<std::string> Blackboard::names() const {
  std::vector<std::string> out;
  for (auto& [k, v] : textures_) out.push_back(k);
  for (auto& [k, v] : buffers_) out.push_back(k);
  std::sort(out.begin(), out.end());
  return out;
}

void Blackboard::clear() {
  textures_.clear();
  buffers_.clear();
}

}  // namespace gi
