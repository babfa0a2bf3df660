#include "gi/vk/memory.h"

#include <algorithm>
#include <string>

#include "gi/errors.h"
#include "gi/vk/common.h"

namespace gi::vk {

namespace {
VkDeviceSize alignUp(VkDeviceSize v, VkDeviceSize a) {
  return (v + a - 1) / a * a;
}
}  // namespace

FreeList::FreeList(VkDeviceSize size) : capacity_(size) {
  free_[0] = size;
}

std::optional<VkDeviceSize> FreeList::allocate(VkDeviceSize size, VkDeviceSize alignment) {
  if (size == 0) size = 1;
  alignment = std::max<VkDeviceSize>(alignment, 1);
  for (auto it = free_.begin(); it != free_.end(); ++it) {
    const VkDeviceSize start = it->first, rangeSize = it->second;
    const VkDeviceSize aligned = alignUp(start, alignment);
    if (aligned + size > start + rangeSize) continue;
    free_.erase(it);
    if (aligned > start) free_[start] = aligned - start;  // padding before stays free
    const VkDeviceSize end = aligned + size, rangeEnd = start + rangeSize;
    if (rangeEnd > end) free_[end] = rangeEnd - end;
    used_ += size;
    return aligned;
  }
  return std::nullopt;
}

void FreeList::free(VkDeviceSize offset, VkDeviceSize size) {
  if (size == 0) size = 1;
  used_ -= size;
  auto next = free_.lower_bound(offset);
  // Merge with the following range.
  if (next != free_.end() && next->first == offset + size) {
    size += next->second;
    next = free_.erase(next);
  }
  // Merge with the preceding range.
  if (next != free_.begin()) {
    auto prev = std::prev(next);
    if (prev->first + prev->second == offset) {
      prev->second += size;
      return;
    }
  }
  free_[offset] = size;
}

MemoryAllocator::MemoryAllocator(VkPhysicalDevice physical, VkDevice device) : device_(device) {
  vkGetPhysicalDeviceMemoryProperties(physical, &props_);
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(physical, &p);
  granularity_ = std::max<VkDeviceSize>(p.limits.bufferImageGranularity, 1);
  blocks_.resize(props_.memoryTypeCount);
}

MemoryAllocator::~MemoryAllocator() {
  for (auto& perType : blocks_)
    for (Block& b : perType)
      if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
}

uint32_t MemoryAllocator::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const {
  for (uint32_t i = 0; i < props_.memoryTypeCount; ++i)
    if ((typeBits & (1u << i)) && (props_.memoryTypes[i].propertyFlags & flags) == flags) return i;
  return UINT32_MAX;
}

Allocation MemoryAllocator::allocate(const VkMemoryRequirements& req,
                                     VkMemoryPropertyFlags required,
                                     VkMemoryPropertyFlags preferred) {
  uint32_t type = findMemoryType(req.memoryTypeBits, required | preferred);
  if (type == UINT32_MAX) type = findMemoryType(req.memoryTypeBits, required);
  if (type == UINT32_MAX)
    throw Error(ErrorKind::Vulkan, "", "no memory type fits the resource's requirements");
  const bool hostVisible =
      props_.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
  // Aligning to bufferImageGranularity keeps linear and optimal resources from sharing a page.
  const VkDeviceSize alignment = std::max(req.alignment, granularity_);
  const VkDeviceSize size = alignUp(req.size, granularity_);

  auto& perType = blocks_[type];
  for (uint32_t i = 0; i < perType.size(); ++i) {
    Block& b = perType[i];
    if (!b.memory) continue;
    if (auto offset = b.ranges->allocate(size, alignment)) {
      ++liveAllocations_;
      return {b.memory, *offset, size, b.mapped ? static_cast<char*>(b.mapped) + *offset : nullptr,
              type,     i};
    }
  }
  // New block: large enough for this request (big resources get a block of their own size).
  Block b;
  const VkDeviceSize blockSize = std::max(kBlockSize, alignUp(size, alignment));
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  info.allocationSize = blockSize;
  info.memoryTypeIndex = type;
  check(vkAllocateMemory(device_, &info, nullptr, &b.memory), "vkAllocateMemory");
  if (hostVisible)
    check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  b.ranges = std::make_unique<FreeList>(blockSize);
  auto offset = b.ranges->allocate(size, alignment);
  uint32_t index = static_cast<uint32_t>(perType.size());
  for (uint32_t i = 0; i < perType.size(); ++i)
    if (!perType[i].memory) index = i;  // reuse an empty slot
  if (index == perType.size()) perType.emplace_back();
  perType[index] = std::move(b);
  ++liveAllocations_;
  Block& placed = perType[index];
  return {placed.memory, *offset,
          size,          placed.mapped ? static_cast<char*>(placed.mapped) + *offset : nullptr,
          type,          index};
}

void MemoryAllocator::free(const Allocation& a) {
  if (!a.memory) return;
  Block& b = blocks_[a.memoryType][a.block];
  b.ranges->free(a.offset, a.size);
  --liveAllocations_;
  if (b.ranges->used() == 0) {  // give empty blocks back so peak memory does not stick
    vkFreeMemory(device_, b.memory, nullptr);
    b = Block{};
  }
}

size_t MemoryAllocator::blockCount() const {
  size_t n = 0;
  for (auto& perType : blocks_)
    for (const Block& b : perType) n += b.memory ? 1 : 0;
  return n;
}

VkDeviceSize MemoryAllocator::bytesInUse() const {
  VkDeviceSize n = 0;
  for (auto& perType : blocks_)
    for (const Block& b : perType) n += b.memory ? b.ranges->used() : 0;
  return n;
}

}  // namespace gi::vk
