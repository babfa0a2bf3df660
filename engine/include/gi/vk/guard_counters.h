// Guard counting: how often the shaders' numeric guards changed a value (a non-finite value
// replaced, a value clamped to its range, a distance clamp, a zero vector's fallback, a
// denominator kept from 0). A shader counts through engine/shaders/guards.glsl; a compute
// pipeline made while counting is on compiles the counting in (a specialization constant) and
// gets its own slot of counters, named by the pipeline, which every descriptor set made for it
// binds; made while counting is off, it compiles the counting out. The hard-case sweep turns it
// on: a guard that fires on an ordinary scene is a finding.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace gi::vk {

class Context;
class Buffer;

class GuardCounters {
 public:
  // The kinds, as guards.glsl numbers them.
  static constexpr uint32_t kKinds = 5;
  static const char* kindName(uint32_t kind);      // "non-finite", "range", ...
  static constexpr uint32_t kSlots = 256;          // pipeline names counted apart
  static constexpr VkDeviceSize kSlotBytes = 256;  // one slot's counters, offset-aligned

  explicit GuardCounters(Context& ctx);
  ~GuardCounters();
  GuardCounters(const GuardCounters&) = delete;
  GuardCounters& operator=(const GuardCounters&) = delete;

  // Pipelines made from now on count (or not). Made before, they keep what they were made with.
  void setEnabled(bool on) { enabled_ = on; }
  bool enabled() const { return enabled_; }

  struct Slot {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0, range = 0;
  };
  // The counters of pipeline `name` (pipelines of the same name share them; past kSlots names,
  // the last slot is shared and reported as "(other pipelines)").
  Slot slot(const std::string& name);

  struct Count {
    std::string pipeline;
    std::array<uint64_t, kKinds> fired{};
  };
  // The pipelines whose guards fired since the last reset (read once the queue is idle).
  std::vector<Count> read() const;
  void reset();

 private:
  Context& ctx_;
  std::unique_ptr<Buffer> buffer_;
  std::map<std::string, uint32_t> slots_;
  std::vector<std::string> names_;
  bool enabled_ = false;
};

}  // namespace gi::vk
