#include "gi/vk/gpu_timer.h"

#include "gi/errors.h"
#include "gi/vk/common.h"

namespace gi::vk {

GpuTimer::GpuTimer(Context& ctx, uint32_t maxScopes) : ctx_(ctx), maxScopes_(maxScopes) {
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = maxScopes * 3;  // begin, end, and the flush write after each begin
  check(vkCreateQueryPool(ctx.device(), &info, nullptr, &pool_), "vkCreateQueryPool");
}

GpuTimer::~GpuTimer() {
  vkDestroyQueryPool(ctx_.device(), pool_, nullptr);
}

void GpuTimer::beginFrame(VkCommandBuffer cmd) {
  names_.clear();
  open_ = false;  // a frame whose recording failed left a scope open
  vkCmdResetQueryPool(cmd, pool_, 0, maxScopes_ * 3);
}

void GpuTimer::begin(VkCommandBuffer cmd, const std::string& name) {
  if (open_) throw Error(ErrorKind::Usage, "", "GpuTimer: nested scope '" + name + "'");
  if (names_.size() >= maxScopes_) throw Error(ErrorKind::Usage, "", "GpuTimer: too many scopes");
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_,
                       static_cast<uint32_t>(names_.size() * 2));
  // A second write, never read: lavapipe resolves a pending timestamp only at its next flush
  // (which every ALL_COMMANDS write does first), so without it the begin value would be taken
  // after the scope's compute work instead of before. Free on GPUs.
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_,
                       static_cast<uint32_t>(maxScopes_ * 2 + names_.size()));
  names_.push_back(name);
  open_ = true;
}

void GpuTimer::end(VkCommandBuffer cmd) {
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_,
                       static_cast<uint32_t>(names_.size() * 2 - 1));
  open_ = false;
}

std::vector<std::pair<std::string, double>> GpuTimer::collect() {
  std::vector<std::pair<std::string, double>> out;
  if (names_.empty()) return out;
  std::vector<uint64_t> ticks(names_.size() * 2);
  check(vkGetQueryPoolResults(ctx_.device(), pool_, 0, static_cast<uint32_t>(ticks.size()),
                              ticks.size() * sizeof(uint64_t), ticks.data(), sizeof(uint64_t),
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  const double nsPerTick = ctx_.properties().limits.timestampPeriod;
  for (size_t i = 0; i < names_.size(); ++i) {
    const uint64_t a = ticks[2 * i], b = ticks[2 * i + 1];
    out.emplace_back(names_[i], b >= a ? double(b - a) * nsPerTick * 1e-6 : 0.0);
  }
  return out;
}

}  // namespace gi::vk
