// A uniform block made from a few of an effect's settings, the common case of UniformBlock: the
// settings are found by name once (in prepare) and read by index while a pass records, and the
// block is rebuilt only when one of them changed since the last upload.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>

#include "gi/settings.h"
#include "gi/uniform_block.h"
#include "gi/vk/pipeline.h"

namespace gi {

template <class T, size_t N>
class SettingUniforms {
 public:
  // The settings' values, in the order of their names: a bool as 0 or 1, an int or enum as its
  // value (an enum's index).
  using Values = std::array<double, N>;

  // `make` builds the block from the values; it runs only when one of them changed.
  void prepare(vk::Context& ctx, const SettingValues& settings,
               const std::array<const char*, N>& names, std::function<T(const Values&)> make) {
    block_.create(ctx);
    for (size_t i = 0; i < N; ++i) handles_[i] = settings.handle<double>(names[i]);
    make_ = std::move(make);
  }
  // Rebuilds and writes the block when the values differ from the last upload's; returns the
  // buffer. `settings` are the ones prepare() took the handles from (or the graph's copy).
  VkBuffer upload(const SettingValues& settings) {
    Values v;
    for (size_t i = 0; i < N; ++i) v[i] = settings[handles_[i]];
    block_.update(v, [&] { return make_(v); });
    return block_.handle();
  }
  // Binds the uploaded block as the shader's `block` as a pass records: for passes whose
  // `bind` takes a DescriptorWriter (ScreenSpaceAO::addPasses). `settings` must outlive it.
  std::function<void(vk::DescriptorWriter&)> binding(std::string block,
                                                     const SettingValues& settings) {
    return [this, block = std::move(block), values = &settings](vk::DescriptorWriter& w) {
      w.buffer(block, upload(*values));
    };
  }
  VkBuffer handle() const { return block_.handle(); }
  UniformBlock<T>& block() { return block_; }  // writePart, invalidate

 private:
  UniformBlock<T> block_;
  std::function<T(const Values&)> make_;
  std::array<Setting<double>, N> handles_{};
};

}  // namespace gi
