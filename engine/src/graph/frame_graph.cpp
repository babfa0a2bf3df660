// Frame graph: declaration (passes, resources, persistent and fallback textures), culling,
// allocation with aliasing, and the graph's descriptions.
#include "gi/graph/frame_graph.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <set>
#include <sstream>

#include "frame_graph_internal.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"

namespace gi {

using namespace graph_detail;  // NOLINT(google-build-using-namespace): this module's helpers

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
  passOwner_.clear();
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

void FrameGraph::checkCurrent(uint32_t id, uint32_t version, const char* what,
                              const std::string& pass) const {
  if (id >= resources_.size()) {
    // Most often a blackboard look-up that found nothing: name what was missing.
    std::string missing;
    for (const std::string& name : blackboard_.lookedUp())
      if (!blackboard_.has(name)) missing += (missing.empty() ? "'" : ", '") + name + "'";
    throw Error(ErrorKind::Usage, "",
                "frame graph: pass '" + pass + "' uses an invalid resource handle for " + what +
                    (missing.empty() ? std::string(" (never created or published)")
                                     : " (looked up on the blackboard but published by no "
                                       "pass: " +
                                           missing + ")"));
  }
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
  p->owner = passOwner_;
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
  graph_.checkCurrent(h.id, h.version, "a read", graph_.passes_[pass_]->name);
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = h.version;
  a.textureUsage = usage;
  a.sub = sub;
  graph_.passes_[pass_]->accesses.push_back(a);
  return h;
}

BufferHandle PassBuilder::read(BufferHandle h, BufferUsage usage) {
  graph_.checkCurrent(h.id, h.version, "a read", graph_.passes_[pass_]->name);
  FrameGraph::Access a;
  a.resource = h.id;
  a.version = h.version;
  a.bufferUsage = usage;
  graph_.passes_[pass_]->accesses.push_back(a);
  return h;
}

TextureHandle PassBuilder::write(TextureHandle h, TextureUsage usage, const Subresource& sub) {
  graph_.checkCurrent(h.id, h.version, "a write", graph_.passes_[pass_]->name);
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
  graph_.checkCurrent(h.id, h.version, "a write", graph_.passes_[pass_]->name);
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
  // Each pass's accesses combined per subresource, once, for execute() (layouts agree: above).
  for (auto& p : passes_) {
    p->textureNeeds.clear();
    for (const Access& a : p->accesses) {
      const Resource& r = *resources_[a.resource];
      if (!r.texture) continue;
      auto it = std::find_if(p->textureNeeds.begin(), p->textureNeeds.end(),
                             [&](const auto& e) { return e.first == a.resource; });
      if (it == p->textureNeeds.end()) {
        p->textureNeeds.emplace_back(a.resource,
                                     std::vector<graph_detail::SubNeed>(r.dims.subresources()));
        it = std::prev(p->textureNeeds.end());
      }
      const SyncState n = required(a.textureUsage, vk::isDepthFormat(r.dims.format));
      for (uint32_t m = a.range.mip; m < a.range.mip + a.range.mipCount; ++m)
        for (uint32_t l = a.range.layer; l < a.range.layer + a.range.layerCount; ++l) {
          graph_detail::SubNeed& x = it->second[m * r.dims.layers + l];
          x.sync.layout = n.layout;
          x.sync.stage |= n.stage;
          x.sync.access |= n.access;
          (a.write ? x.write : x.read) = true;
        }
    }
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
  for (const auto& [id, version] : outputs_) {
    if (!produced.count({id, version}))
      throw Error(ErrorKind::Usage, "",
                  "frame graph: output '" + resources_[id]->name + "' is never written");
    // Read after execute(): no later transient may share its memory.
    resources_[id]->lastUse = order;
  }
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
        fits = fits && aliasing_ && (r.lastUse < first || last < r.firstUse);
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

bool FrameGraph::intactAtEnd(TextureHandle h) const {
  const Resource& r = resource(h.id);
  if (r.external() || r.transient < 0) return true;
  const Transient& t = *pool_[r.transient];
  if (t.slot < 0) return true;
  for (const auto& [first, last] : slots_[t.slot].lifetimes)
    if (first > r.lastUse) return false;  // a later occupant overwrote it
  return true;
}

VkFormat FrameGraph::textureFormat(TextureHandle h) const {
  return resource(h.id).textureDesc.format;
}

bool FrameGraph::produced(TextureHandle h) const {
  const Resource& r = resource(h.id);
  return r.texture && r.image;
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

std::vector<std::pair<std::string, FrameGraph::TextureState>> FrameGraph::allocatedTextures()
    const {
  std::vector<std::pair<std::string, TextureState>> out;
  for (uint32_t id = 0; id < resources_.size(); ++id) {
    const Resource& r = *resources_[id];
    if (!r.texture || !r.image || r.firstUse < 0) continue;
    out.emplace_back(r.name, textureState(TextureHandle{id, r.version}));
  }
  return out;
}

std::vector<std::string> FrameGraph::passNames() const {
  std::vector<std::string> out;
  for (auto& p : passes_) out.push_back(p->name);
  return out;
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

TextureHandle Blackboard::texture(const std::string& name) const {
  lookedUp_.insert(name);
  auto it = textures_.find(name);
  return it == textures_.end() ? TextureHandle{} : it->second;
}

BufferHandle Blackboard::buffer(const std::string& name) const {
  lookedUp_.insert(name);
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
  lookedUp_.clear();
  published_.clear();
}

}  // namespace gi
