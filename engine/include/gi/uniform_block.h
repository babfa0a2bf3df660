// A uniform buffer holding one T, written only when what it is made from changed: the effects'
// parameter blocks (kernels, rotations, radii) are rebuilt from the settings only when a
// setting changed since the last upload, not every frame.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "gi/vk/resources.h"

namespace gi {

template <class T>
class UniformBlock {
  static_assert(std::is_trivially_copyable_v<T>, "a uniform block is copied as bytes");

 public:
  // Host-visible and written while recording: the renderer waits for each frame before it
  // records the next, so the GPU is not reading it. Creating again keeps the buffer.
  void create(vk::Context& ctx) {
    if (!buffer_)  // transfer source: tools and tests can read back what the shader sees
      buffer_ =
          vk::Buffer(ctx, sizeof(T),
                     VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  }
  VkBuffer handle() const { return buffer_.handle(); }

  // Writes make() when `key` (the inputs it is made from: trivially copyable, without padding,
  // e.g. a std::array of numbers) differs from the last upload's, or nothing was uploaded since
  // create()/invalidate(). True when it wrote.
  template <class Key, class Make>
  bool update(const Key& key, Make&& make) {
    static_assert(std::is_trivially_copyable_v<Key>, "the key is compared as bytes");
    const auto* bytes = reinterpret_cast<const unsigned char*>(&key);
    if (key_.size() == sizeof(Key) && std::memcmp(key_.data(), bytes, sizeof(Key)) == 0)
      return false;
    const T value = make();
    buffer_.write(&value, sizeof value);
    key_.assign(bytes, bytes + sizeof(Key));
    ++uploads_;
    return true;
  }
  // Writes `bytes` at `offset` now: a part of the block that changes every frame (a camera),
  // kept when update() does not rewrite the block, overwritten when it does.
  void writePart(const void* data, size_t bytes, size_t offset) {
    buffer_.write(data, bytes, offset);
  }
  // The next update() writes whatever its key (e.g. what make() reads besides the key changed).
  void invalidate() { key_.clear(); }
  uint64_t uploads() const { return uploads_; }

 private:
  vk::Buffer buffer_;
  std::vector<unsigned char> key_;
  uint64_t uploads_ = 0;
};

}  // namespace gi
