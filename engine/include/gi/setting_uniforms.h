// A uniform block made from a few of an effect's settings, the common case of UniformBlock: the
// settings are found by name once (in prepare) and read by index while a pass records, and the
// block is rebuilt only when one of them changed since the last upload.
#pragma once

#include <array>
#include <cstddef>

#include "gi/settings.h"
#include "gi/uniform_block.h"

namespace gi {

template <class T, size_t N>
class SettingUniforms {
 public:
  // The settings' values, in the order of their names: a bool as 0 or 1, an int or enum as its
  // value (an enum's index).
  using Values = std::array<double, N>;

  void prepare(vk::Context& ctx, const SettingValues& settings,
               const std::array<const char*, N>& names) {
    block_.create(ctx);
    for (size_t i = 0; i < N; ++i) handles_[i] = settings.handle<double>(names[i]);
  }
  // Writes make(values) when the values differ from the last upload's; returns the buffer.
  template <class Make>
  VkBuffer upload(const SettingValues& settings, Make&& make) {
    Values v;
    for (size_t i = 0; i < N; ++i) v[i] = settings[handles_[i]];
    block_.update(v, [&] { return make(v); });
    return block_.handle();
  }
  VkBuffer handle() const { return block_.handle(); }
  UniformBlock<T>& block() { return block_; }  // writePart, invalidate

 private:
  UniformBlock<T> block_;
  std::array<Setting<double>, N> handles_{};
};

}  // namespace gi
