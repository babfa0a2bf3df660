#include "gi/graph/frame_graph.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "gi/errors.h"
#include "gi/vk/common.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"

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

struct FrameGraph::Access {
  uint32_t resource = 0, version = 0;
  bool write = false;
  TextureUsage textureUsage = TextureUsage::Sampled;
  BufferUsage bufferUsage = BufferUsage::StorageRead;
};

struct FrameGraph::Pass {
  std::string name;
  std::vector<Access> accesses;
  bool sideEffect = false;
  bool culled = false;
  PassExecute execute;
};

struct FrameGraph::Resource {
  std::string name;
  bool texture = true;
  bool imported = false;
  TextureDesc textureDesc;
  BufferDesc bufferDesc;
  uint32_t version = 0;  // latest version declared so far
  // Vulkan objects (imported, or created by allocateTransients).
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkExtent2D extent{};
  VkImageLayout finalLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  // During execute; persist across frames for imported resources. `state`: the layout, every
  // stage that used the resource since its last write (what a new write waits for) and that
  // write's access. `lastWrite`: the last write's stage and access. `visible`: the stages and
  // accesses a barrier already made that write visible to (a later read elsewhere needs one).
  SyncState state, lastWrite, visible;
  int transient = -1;
  int firstUse = -1, lastUse = -1;  // kept-pass indices
};

// A transient's Vulkan objects, and the memory range they are bound to (shared by aliases).
struct FrameGraph::Transient {
  vk::Context* ctx = nullptr;
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkMemoryRequirements requirements{};
  int slot = -1;
  ~Transient() {
    if (view) vkDestroyImageView(ctx->device(), view, nullptr);
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
}

void FrameGraph::reset() {
  pool_.clear();
  for (Slot& s : slots_) ctx_.allocator().free(s.allocation);
  slots_.clear();
  resources_.clear();
  passes_.clear();
  outputs_.clear();
  blackboard_.clear();
  stats_ = {};
  compiled_ = false;
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

TextureHandle PassBuilder::read(TextureHandle h, TextureUsage usage) {
  graph_.checkCurrent(h.id, h.version, "a read");
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = h.version;
  a.textureUsage = usage;
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

TextureHandle PassBuilder::write(TextureHandle h, TextureUsage usage) {
  graph_.checkCurrent(h.id, h.version, "a write");
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = ++graph_.resources_[h.id]->version;
  a.write = true;
  a.textureUsage = usage;
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
  r.finalLayout = finalLayout;
  r.state = {currentLayout, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT};
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

void FrameGraph::compile() {
  if (compiled_)
    throw Error(ErrorKind::Usage, "", "frame graph: compile() called twice (reset() first)");
  // Cull: walk passes backwards from the outputs, keeping each pass that writes a needed
  // version (or has a side effect) and marking what it reads as needed.
  std::set<std::pair<uint32_t, uint32_t>> needed(outputs_.begin(), outputs_.end());
  for (auto it = passes_.rbegin(); it != passes_.rend(); ++it) {
    Pass& p = **it;
    bool keep = p.sideEffect;
    for (const Access& a : p.accesses)
      keep = keep || (a.write && needed.count({a.resource, a.version}));
    p.culled = !keep;
    if (!keep) continue;
    for (const Access& a : p.accesses)
      if (!a.write) needed.insert({a.resource, a.version});
  }
  // Every kept read must have a producer (a kept write of that version, or an import).
  std::set<std::pair<uint32_t, uint32_t>> produced;
  for (uint32_t id = 0; id < resources_.size(); ++id)
    if (resources_[id]->imported) produced.insert({id, 0});
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
    if (r.imported || r.firstUse < 0) continue;  // imported, or only used by culled passes
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
      r.extent = resolveExtent(id);
      VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
      info.imageType = VK_IMAGE_TYPE_2D;
      info.format = r.textureDesc.format;
      info.extent = {r.extent.width, r.extent.height, 1};
      info.mipLevels = 1;
      info.arrayLayers = 1;
      info.samples = VK_SAMPLE_COUNT_1_BIT;
      info.tiling = VK_IMAGE_TILING_OPTIMAL;
      info.usage = usage;
      vk::check(vkCreateImage(device, &info, nullptr, &t->image), "vkCreateImage (frame graph)");
      vkGetImageMemoryRequirements(device, t->image, &t->requirements);
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
      VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      view.image = t.image;
      view.viewType = VK_IMAGE_VIEW_TYPE_2D;
      view.format = r.textureDesc.format;
      const VkImageAspectFlags aspect = vk::isDepthFormat(r.textureDesc.format)
                                            ? VK_IMAGE_ASPECT_DEPTH_BIT
                                            : VK_IMAGE_ASPECT_COLOR_BIT;
      view.subresourceRange = {aspect, 0, 1, 0, 1};
      vk::check(vkCreateImageView(device, &view, nullptr, &t.view), "vkCreateImageView");
      r.image = t.image;
      r.view = t.view;
    } else {
      vk::check(
          vkBindBufferMemory(device, t.buffer, slot.allocation.memory, slot.allocation.offset),
          "vkBindBufferMemory");
      r.buffer = t.buffer;
    }
  }
}

void FrameGraph::execute(VkCommandBuffer cmd, vk::DescriptorArena& descriptors, vk::GpuTimer* timer,
                         const PassBoundary& afterPass) {
  if (!compiled_) throw Error(ErrorKind::Usage, "", "frame graph: execute() before compile()");
  // Transient contents never survive a frame: they start undefined.
  for (auto& r : resources_)
    if (!r->imported) r->state = r->lastWrite = r->visible = {};
  for (Slot& slot : slots_) slot.usedStages = VK_PIPELINE_STAGE_2_NONE;
  // The memory slot under a transient (nullptr for imported resources).
  auto slotOf = [this](const Resource& r) -> Slot* {
    if (r.imported || r.transient < 0) return nullptr;
    const int slot = pool_[size_t(r.transient)]->slot;
    return slot >= 0 ? &slots_[size_t(slot)] : nullptr;
  };

  // A read needs no barrier when nothing wrote the resource yet, or a barrier already made the
  // last write visible to this stage and access.
  auto alreadyVisible = [](const Resource& r, const SyncState& need) {
    return r.lastWrite.access == VK_ACCESS_2_NONE ||
           ((need.stage & ~r.visible.stage) == 0 && (need.access & ~r.visible.access) == 0);
  };
  // Bookkeeping after a barrier for a write or a layout change to `need`.
  auto afterBarrier = [](Resource& r, const SyncState& need, bool write) {
    r.state = need;
    if (write) {
      r.lastWrite = {need.layout, need.stage, need.access & kWriteAccess};
      r.visible = {};  // nothing has seen this write yet
    } else {
      r.visible = need;
    }
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
    // Does this pass read the resource's previous contents? If not, they may be discarded.
    auto readsResource = [&](uint32_t id) {
      for (const Access& a : p->accesses)
        if (a.resource == id && !a.write) return true;
      return false;
    };
    for (const Access& a : p->accesses) {
      Resource& r = *resources_[a.resource];
      if (r.texture) {
        SyncState need = required(a.textureUsage, vk::isDepthFormat(r.textureDesc.format));
        const bool sameLayoutRead = !a.write && r.state.layout == need.layout;
        if (sameLayoutRead && alreadyVisible(r, need)) {
          r.state.stage |= need.stage;  // a later write waits for this reader too
          if (Slot* slot = slotOf(r)) slot->usedStages |= need.stage;
          continue;
        }
        VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
        // A read in the same layout waits for the last write only; a write or a layout change
        // waits for every use since (write-after-read needs the readers done).
        b.srcStageMask = sameLayoutRead ? r.lastWrite.stage : r.state.stage;
        b.srcAccessMask = r.lastWrite.access;
        b.dstStageMask = need.stage;
        b.dstAccessMask = need.access;
        const bool discard = a.write && !readsResource(a.resource) && !r.imported;
        b.oldLayout = discard ? VK_IMAGE_LAYOUT_UNDEFINED : r.state.layout;
        b.newLayout = need.layout;
        Slot* slot = slotOf(r);
        if (b.srcStageMask == VK_PIPELINE_STAGE_2_NONE && slot)  // first use of aliased memory
          b.srcStageMask = slot->usedStages;
        if (b.srcStageMask == VK_PIPELINE_STAGE_2_NONE)
          b.srcStageMask = VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT;
        if (slot) slot->usedStages |= need.stage;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.image = r.image;
        const VkImageAspectFlags aspect = vk::isDepthFormat(r.textureDesc.format)
                                              ? VK_IMAGE_ASPECT_DEPTH_BIT
                                              : VK_IMAGE_ASPECT_COLOR_BIT;
        b.subresourceRange = {aspect, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
        // Merge with an earlier barrier of this pass on the same image (read + write).
        bool merged = false;
        for (auto& e : imageBarriers)
          if (e.image == b.image) {
            if (e.newLayout != b.newLayout)
              throw Error(ErrorKind::Usage, "",
                          "frame graph: pass '" + p->name + "' uses '" + r.name +
                              "' in two conflicting layouts");
            e.srcStageMask |= b.srcStageMask;
            e.srcAccessMask |= b.srcAccessMask;
            e.dstStageMask |= b.dstStageMask;
            e.dstAccessMask |= b.dstAccessMask;
            merged = true;
          }
        if (!merged) imageBarriers.push_back(b);
        if (sameLayoutRead) {
          r.state.stage |= need.stage;
          r.visible.stage |= need.stage;
          r.visible.access |= need.access;
        } else {
          afterBarrier(r, need, a.write);
        }
      } else {
        SyncState need = required(a.bufferUsage);
        if (!a.write && alreadyVisible(r, need)) {
          r.state.stage |= need.stage;
          if (Slot* slot = slotOf(r)) slot->usedStages |= need.stage;
          continue;
        }
        Slot* slot = slotOf(r);
        VkPipelineStageFlags2 src = a.write ? r.state.stage : r.lastWrite.stage;
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
          afterBarrier(r, need, true);
        } else {
          r.state.stage |= need.stage;
          r.visible.stage |= need.stage;
          r.visible.access |= need.access;
        }
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
  // Leave imported images in the layout their owner asked for.
  for (auto& r : resources_) {
    if (!r->imported || !r->texture || r->finalLayout == VK_IMAGE_LAYOUT_UNDEFINED ||
        r->finalLayout == r->state.layout)
      continue;
    const VkImageAspectFlags aspect = vk::isDepthFormat(r->textureDesc.format)
                                          ? VK_IMAGE_ASPECT_DEPTH_BIT
                                          : VK_IMAGE_ASPECT_COLOR_BIT;
    vk::imageBarrier(cmd, r->image, aspect, r->state.layout, r->finalLayout,
                     r->state.stage ? r->state.stage : VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT,
                     r->state.access & kWriteAccess, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    r->state = {r->finalLayout, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT};
  }
}

FrameGraph::TextureState FrameGraph::textureState(TextureHandle h) const {
  const Resource& r = resource(h.id);
  if (!r.texture || !r.image)
    throw Error(ErrorKind::Usage, "",
                "frame graph: '" + r.name + "' was not produced (its passes were culled)");
  return {r.image, r.view, r.textureDesc.format, r.imported ? resolveExtent(h.id) : r.extent,
          r.state.layout};
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
    for (const Access& a : p->accesses)
      (a.write ? writes : reads) += " " + resources_[a.resource]->name;
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
  for (size_t r = 0; r < resources_.size(); ++r)
    s << "  r" << r << " [shape=ellipse, label=\"" << resources_[r]->name << "\""
      << (resources_[r]->imported ? ", peripheries=2" : "") << "];\n";
  for (size_t i = 0; i < passes_.size(); ++i)
    for (const Access& a : passes_[i]->accesses) {
      const char* style = passes_[i]->culled ? " [style=dashed, color=gray]" : "";
      if (a.write)
        s << "  p" << i << " -> r" << a.resource << style << ";\n";
      else
        s << "  r" << a.resource << " -> p" << i << style << ";\n";
    }
  s << "}\n";
  return s.str();
}

VkImage PassContext::image(TextureHandle h) const {
  return graph_->resource(h.id).image;
}
VkImageView PassContext::view(TextureHandle h) const {
  return graph_->resource(h.id).view;
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
VkExtent2D PassContext::extent(TextureHandle h) const {
  const auto& r = graph_->resource(h.id);
  return r.imported ? graph_->resolveExtent(h.id) : r.extent;
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
