// gi::UniformBlock: a parameter block is made and written only when its key changed.
#include <gtest/gtest.h>

#include <array>
#include <cstddef>

#include "gi/uniform_block.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

struct Params {
  float radius;
  int32_t samples;
};

class UniformBlockTest : public test::VulkanTest {};

TEST_F(UniformBlockTest, WritesOnlyWhenTheKeyChanges) {
  UniformBlock<Params> block;
  block.create(ctx());
  block.create(ctx());  // again: keeps the buffer
  ASSERT_NE(block.handle(), VK_NULL_HANDLE);
  int made = 0;
  auto upload = [&](double radius, int samples) {
    const std::array<double, 2> key = {radius, double(samples)};
    return block.update(key, [&] {
      ++made;
      return Params{float(key[0]), int32_t(key[1])};
    });
  };
  EXPECT_TRUE(upload(0.5, 16));
  EXPECT_FALSE(upload(0.5, 16));
  EXPECT_FALSE(upload(0.5, 16));
  EXPECT_EQ(made, 1) << "an unchanged key must not rebuild the block";
  EXPECT_TRUE(upload(0.5, 32));
  EXPECT_TRUE(upload(0.25, 32));
  EXPECT_EQ(block.uploads(), 3u);
  block.invalidate();
  EXPECT_TRUE(upload(0.25, 32));
  EXPECT_EQ(made, 4);

  // The buffer holds the last value (copied out as the GPU sees it).
  vk::Buffer host(ctx(), sizeof(Params), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  ctx().submitAndWait([&](VkCommandBuffer cmd) {
    const VkBufferCopy region{0, 0, sizeof(Params)};
    vkCmdCopyBuffer(cmd, block.handle(), host.handle(), 1, &region);
  });
  const auto* p = static_cast<const Params*>(host.mapped());
  EXPECT_EQ(p->radius, 0.25f);
  EXPECT_EQ(p->samples, 32);

  // A part written every frame stays while the key is unchanged; a new key rewrites it all.
  auto readBack = [&] {
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
      const VkBufferCopy region{0, 0, sizeof(Params)};
      vkCmdCopyBuffer(cmd, block.handle(), host.handle(), 1, &region);
    });
    return *static_cast<const Params*>(host.mapped());
  };
  const int32_t part = 7;
  block.writePart(&part, sizeof part, offsetof(Params, samples));
  EXPECT_FALSE(upload(0.25, 32));
  EXPECT_EQ(readBack().samples, 7);
  EXPECT_TRUE(upload(0.25, 64));
  EXPECT_EQ(readBack().samples, 64);
}

}  // namespace
}  // namespace gi
