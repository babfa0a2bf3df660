#include "gi/vk/guard_counters.h"

#include <algorithm>
#include <cstring>

#include "gi/vk/resources.h"

namespace gi::vk {

const char* GuardCounters::kindName(uint32_t kind) {
  static const char* names[kKinds] = {"non-finite", "range", "distance", "zero vector",
                                      "denominator"};
  return kind < kKinds ? names[kind] : "unknown";
}

GuardCounters::GuardCounters(Context& ctx) : ctx_(ctx) {
  buffer_ = std::make_unique<Buffer>(ctx_, kSlots * kSlotBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                     /*hostVisible=*/true);
  reset();
}

GuardCounters::~GuardCounters() = default;

GuardCounters::Slot GuardCounters::slot(const std::string& name) {
  auto it = slots_.find(name);
  if (it == slots_.end()) {
    const uint32_t index = std::min(uint32_t(names_.size()), kSlots - 1);
    if (names_.size() < kSlots) names_.push_back(index == kSlots - 1 ? "(other pipelines)" : name);
    it = slots_.emplace(name, index).first;
  }
  return {buffer_->handle(), VkDeviceSize(it->second) * kSlotBytes, kKinds * sizeof(uint32_t)};
}

std::vector<GuardCounters::Count> GuardCounters::read() const {
  std::vector<Count> out;
  const auto* base = static_cast<const uint8_t*>(buffer_->mapped());
  for (uint32_t s = 0; s < names_.size(); ++s) {
    uint32_t fired[kKinds];
    std::memcpy(fired, base + s * kSlotBytes, sizeof fired);
    Count c{names_[s], {}};
    bool any = false;
    for (uint32_t k = 0; k < kKinds; ++k) {
      c.fired[k] = fired[k];
      any = any || fired[k] > 0;
    }
    if (any) out.push_back(c);
  }
  return out;
}

void GuardCounters::reset() {
  std::memset(buffer_->mapped(), 0, kSlots * kSlotBytes);
}

}  // namespace gi::vk
