// Memory sub-allocation: a few large VkDeviceMemory blocks per memory type, carved into
// resources by a first-fit free list (no vkAllocateMemory per resource).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

namespace gi::vk {

// Pure range bookkeeping (no Vulkan), so the policy is unit-testable.
class FreeList {
 public:
  explicit FreeList(VkDeviceSize size);
  // Returns the offset of a range of `size` bytes aligned to `alignment`, or nullopt.
  std::optional<VkDeviceSize> allocate(VkDeviceSize size, VkDeviceSize alignment);
  // Returns a range given by allocate(); merges it with free neighbours.
  void free(VkDeviceSize offset, VkDeviceSize size);
  VkDeviceSize capacity() const { return capacity_; }
  VkDeviceSize used() const { return used_; }
  size_t freeRangeCount() const { return free_.size(); }

 private:
  VkDeviceSize capacity_;
  VkDeviceSize used_ = 0;
  std::map<VkDeviceSize, VkDeviceSize> free_;  // offset -> size, non-adjacent ranges
};

struct Allocation {
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  VkDeviceSize size = 0;
  void* mapped = nullptr;  // host pointer at `offset` for host-visible memory
  uint32_t memoryType = 0;
  uint32_t block = 0;
  explicit operator bool() const { return memory != VK_NULL_HANDLE; }
};

class MemoryAllocator {
 public:
  static constexpr VkDeviceSize kBlockSize = 64ull << 20;

  MemoryAllocator(VkPhysicalDevice physical, VkDevice device);
  ~MemoryAllocator();
  MemoryAllocator(const MemoryAllocator&) = delete;
  MemoryAllocator& operator=(const MemoryAllocator&) = delete;

  Allocation allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags required,
                      VkMemoryPropertyFlags preferred = 0);
  void free(const Allocation& allocation);

  size_t blockCount() const;        // live VkDeviceMemory objects
  VkDeviceSize bytesInUse() const;  // sum of live sub-allocations
  uint64_t allocationCount() const { return liveAllocations_; }

 private:
  struct Block {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    std::unique_ptr<FreeList> ranges;
  };
  uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const;

  VkDevice device_;
  VkPhysicalDeviceMemoryProperties props_{};
  VkDeviceSize granularity_ = 1;
  std::vector<std::vector<Block>> blocks_;  // per memory type
  uint64_t liveAllocations_ = 0;
};

}  // namespace gi::vk
