// Frame graph: recording a frame (per-subresource barriers, clears of persistent and fallback
// images) and what a pass sees of its resources (PassContext).

#include <algorithm>
#include <exception>
#include <string>

#include "frame_graph_internal.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"

namespace gi {

using namespace graph_detail;  // NOLINT(google-build-using-namespace): this module's helpers

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

// Records a pass: whatever its code throws (of any type) becomes an error naming the pass and,
// for an effect's pass, an EffectError naming the effect, so an app can turn it off and go on.
void recordGuarded(const std::string& pass, const std::string& owner, const PassExecute& execute,
                   PassContext& pc) {
  auto fail = [&](ErrorKind kind, const std::string& file, const std::string& why) {
    const std::string where = "pass '" + pass + "' failed while recording: " + why;
    if (owner.empty()) throw Error(kind, file, where);
    throw EffectError(kind, file, "effect '" + owner + "', " + where, owner);
  };
  try {
    execute(pc);
  } catch (const EffectError&) {
    throw;
  } catch (const Error& e) {
    const std::string what = e.what();
    fail(e.kind(), e.file(),
         e.file().empty() ? what : what.substr(std::min(what.size(), e.file().size() + 2)));
  } catch (const std::exception& e) {
    fail(ErrorKind::InvalidData, "", e.what());
  } catch (...) {
    fail(ErrorKind::InvalidData, "", "it threw something that is not a std::exception");
  }
}

}  // namespace

// Persistent and fallback images start cleared (zero, or the fallback's value): recorded at the
// start of the frame, then treated as a write.
void FrameGraph::clearOwned(VkCommandBuffer cmd) {
  const SyncState cleared{VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
  auto clear = [&](Owned& o) {
    if (!o.needsClear) return;
    const VkImageAspectFlags aspect = graph_detail::aspectOf(o.dims.format);
    vk::imageBarrier(cmd, o.image, aspect, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                     VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    const VkImageSubresourceRange range{aspect, 0, VK_REMAINING_MIP_LEVELS, 0,
                                        VK_REMAINING_ARRAY_LAYERS};
    if (vk::isDepthFormat(o.dims.format)) {
      VkClearDepthStencilValue zero{};
      vkCmdClearDepthStencilImage(cmd, o.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1,
                                  &range);
    } else {
      vkCmdClearColorImage(cmd, o.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &o.clear, 1, &range);
    }
    for (SubState& s : o.subs) s = {cleared, cleared, {}};
    o.needsClear = false;
    o.written = false;
  };
  for (auto& [name, o] : persistent_) clear(*o);
  for (auto& [name, o] : fallbacks_) clear(*o);
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
  for (Slot& slot : slots_) {
    slot.usedStages = VK_PIPELINE_STAGE_2_NONE;
    slot.writtenAccess = VK_ACCESS_2_NONE;
  }
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
    // Textures: the pass's needs per subresource (combined by compile()).
    for (const auto& [id, subs] : p->textureNeeds) {
      Resource& r = *resources_[id];
      Slot* slot = slotOf(r);
      std::vector<SubBarrier> barriers(subs.size());
      VkPipelineStageFlags2 used = VK_PIPELINE_STAGE_2_NONE;
      VkAccessFlags2 written = VK_ACCESS_2_NONE;
      for (size_t i = 0; i < subs.size(); ++i) {
        const SubNeed& x = subs[i];
        if (!x.read && !x.write) continue;
        SubState& st = (*r.subs)[i];
        used |= x.sync.stage;
        if (x.write) written |= x.sync.access;
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
        if (b.srcStage == VK_PIPELINE_STAGE_2_NONE && slot) {  // first use of aliased memory
          b.srcStage = slot->usedStages;
          b.srcAccess = slot->writtenAccess;
        }
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
      if (slot) {
        slot->usedStages |= used;
        slot->writtenAccess |= written;
      }
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
      VkAccessFlags2 srcAccess = r.lastWrite.access;
      if (src == VK_PIPELINE_STAGE_2_NONE && slot) {  // aliased memory
        src = slot->usedStages;
        srcAccess = slot->writtenAccess;
      }
      if (slot) {
        slot->usedStages |= need.stage;
        if (a.write) slot->writtenAccess |= need.access;
      }
      if (src != VK_PIPELINE_STAGE_2_NONE) {
        VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
        b.srcStageMask = src;
        b.srcAccessMask = srcAccess;
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
    recordGuarded(p->name, p->owner, p->execute, pc);
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

void PassContext::dispatch(const vk::Pipeline& pipeline, vk::DescriptorWriter& writer,
                           VkExtent2D extent, uint32_t groupX, uint32_t groupY) const {
  descriptors_->bind(cmd_, pipeline, writer);
  dispatchGroups(extent, groupX, groupY);
}

void PassContext::dispatchPushing(const vk::Pipeline& pipeline, vk::DescriptorWriter& writer,
                                  VkExtent2D extent, uint32_t groupX, uint32_t groupY,
                                  const void* push, size_t size) const {
  descriptors_->bind(cmd_, pipeline, writer);
  pipeline.pushBytes(cmd_, push, size);
  dispatchGroups(extent, groupX, groupY);
}

void PassContext::dispatchGroups(VkExtent2D extent, uint32_t groupX, uint32_t groupY) const {
  vkCmdDispatch(cmd_, (extent.width + groupX - 1) / groupX, (extent.height + groupY - 1) / groupY,
                1);
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

}  // namespace gi
