// Frame graph: culling from the outputs, versioned handles, size classes, memory aliasing and
// barriers that hold up under the validation layers on real GPU work.
#include <gtest/gtest.h>

#include "gi/errors.h"
#include "gi/graph/frame_graph.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

class FrameGraphTest : public test::VulkanTest {};

TextureDesc rgba8() {
  return TextureDesc{VK_FORMAT_R8G8B8A8_UNORM};
}

TEST_F(FrameGraphTest, CullsPassesWhoseOutputsReachNothing) {
  FrameGraph g(ctx(), {64, 48});
  TextureHandle a, b, unused, out;
  g.addPass(
      "produce_a",
      [&](PassBuilder& pb) { a = pb.write(pb.create("a", rgba8()), TextureUsage::StorageWrite); },
      {});
  g.addPass("unused",
            [&](PassBuilder& pb) {
              pb.read(a);
              unused = pb.write(pb.create("unused", rgba8()), TextureUsage::StorageWrite);
            },
            {});
  g.addPass("produce_b",
            [&](PassBuilder& pb) {
              pb.read(a);
              b = pb.write(pb.create("b", rgba8()), TextureUsage::StorageWrite);
            },
            {});
  g.addPass("readback",
            [&](PassBuilder& pb) {
              pb.read(b, TextureUsage::TransferSrc);
              pb.sideEffect();
            },
            {});
  g.addPass("dangling",
            [&](PassBuilder& pb) {
              out = pb.write(pb.create("never_output", rgba8()), TextureUsage::StorageWrite);
            },
            {});
  g.compile();
  EXPECT_EQ(g.executedPasses(), (std::vector<std::string>{"produce_a", "produce_b", "readback"}));
  EXPECT_EQ(g.culledPasses(), (std::vector<std::string>{"unused", "dangling"}));
  EXPECT_EQ(g.stats().transientTextures, 2u) << "culled passes' resources are not allocated";
  const std::string dot = g.toDot();
  EXPECT_NE(dot.find("digraph"), std::string::npos);
  EXPECT_NE(dot.find("\"unused\", style=dashed"), std::string::npos) << dot;
}

TEST_F(FrameGraphTest, StaleHandleIsCaught) {
  FrameGraph g(ctx(), {8, 8});
  TextureHandle v0, v1;
  g.addPass("w1",
            [&](PassBuilder& pb) {
              v0 = pb.create("t", rgba8());
              v1 = pb.write(v0, TextureUsage::StorageWrite);
            },
            {});
  EXPECT_THROW(g.addPass("stale", [&](PassBuilder& pb) { pb.read(v0); }, {}), Error);
  try {
    g.addPass("stale2", [&](PassBuilder& pb) { (void)pb.write(v0, TextureUsage::StorageWrite); },
              {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("stale handle to 't'"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(g.addPass("fresh", [&](PassBuilder& pb) { pb.read(v1); }, {}));
}

TEST_F(FrameGraphTest, ReadingSomethingNobodyWritesIsAnError) {
  FrameGraph g(ctx(), {8, 8});
  TextureHandle out;
  g.addPass("consumer",
            [&](PassBuilder& pb) {
              pb.read(pb.create("ghost", rgba8()));
              out = pb.write(pb.create("out", rgba8()), TextureUsage::StorageWrite);
            },
            {});
  g.markOutput(out);
  try {
    g.compile();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'ghost' but no pass writes it"), std::string::npos)
        << e.what();
  }
}

TEST_F(FrameGraphTest, SizeClassesResolve) {
  FrameGraph g(ctx(), {320, 240});
  TextureHandle full, half, quarterOfHalf, fixed;
  g.addPass(
      "p",
      [&](PassBuilder& pb) {
        full = pb.write(pb.create("full", rgba8()), TextureUsage::StorageWrite);
        TextureDesc h = rgba8();
        h.scale = 0.5f;
        half = pb.write(pb.create("half", h), TextureUsage::StorageWrite);
        TextureDesc q = rgba8();
        q.sizeClass = SizeClass::InputRelative;
        q.relativeTo = half;
        q.scale = 0.5f;
        quarterOfHalf = pb.write(pb.create("quarter", q), TextureUsage::StorageWrite);
        TextureDesc a = rgba8();
        a.sizeClass = SizeClass::Absolute;
        a.width = 100;
        a.height = 7;
        fixed = pb.write(pb.create("fixed", a), TextureUsage::StorageWrite);
      },
      [&](PassContext& pc) {
        EXPECT_EQ(pc.extent(full).width, 320u);
        EXPECT_EQ(pc.extent(half).height, 120u);
        EXPECT_EQ(pc.extent(quarterOfHalf).width, 80u);
        EXPECT_EQ(pc.extent(fixed).height, 7u);
      });
  g.markOutput(full);
  g.markOutput(half);
  g.markOutput(quarterOfHalf);
  g.markOutput(fixed);
  g.compile();
  vk::DescriptorArena arena(ctx());
  ctx().submitAndWait([&](VkCommandBuffer cmd) { g.execute(cmd, arena, nullptr); });
}

// A chain t1 -> t2 -> t3 -> output: t1 and t3 never live at the same time, so they alias.
// The aliasing tests' passes: transfer clears and copies of whole single-mip images.
void clearTo(PassContext& pc, TextureHandle t, float v) {
  VkClearColorValue c{{v, v, v, 1.0f}};
  VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(pc.cmd(), pc.image(t), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &c, 1, &range);
}
void copyImage(PassContext& pc, TextureHandle from, TextureHandle to) {
  VkImageCopy region{};
  region.srcSubresource = region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.extent = {pc.extent(from).width, pc.extent(from).height, 1};
  vkCmdCopyImage(pc.cmd(), pc.image(from), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.image(to),
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
}
// An RGBA8 image for the graph to import as its output.
vk::Image transferImage(vk::Context& ctx, VkExtent2D size) {
  vk::ImageDesc d;
  d.width = size.width;
  d.height = size.height;
  d.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
            VK_IMAGE_USAGE_SAMPLED_BIT;
  return vk::Image(ctx, d);
}

// Three transients in a chain: t1 cleared to 0.25, copied to t2, copied to t3. t1 and t3
// do not overlap in time, so t3 may take t1's memory.
struct CopyChain {
  TextureHandle t1, t2, t3;
  explicit CopyChain(FrameGraph& g) {
    g.addPass(
        "clear_t1",
        [&](PassBuilder& pb) {
          t1 = pb.write(pb.create("t1", rgba8()), TextureUsage::TransferDst);
        },
        [this](PassContext& pc) { clearTo(pc, t1, 0.25f); });
    g.addPass(
        "t1_to_t2",
        [&](PassBuilder& pb) {
          pb.read(t1, TextureUsage::TransferSrc);
          t2 = pb.write(pb.create("t2", rgba8()), TextureUsage::TransferDst);
        },
        [this](PassContext& pc) { copyImage(pc, t1, t2); });
    g.addPass(
        "t2_to_t3",
        [&](PassBuilder& pb) {
          pb.read(t2, TextureUsage::TransferSrc);
          t3 = pb.write(pb.create("t3", rgba8()), TextureUsage::TransferDst);
        },
        [this](PassContext& pc) { copyImage(pc, t2, t3); });
  }
};

TEST_F(FrameGraphTest, AliasesMemoryAndProducesCorrectPixels) {
  const VkExtent2D size{32, 16};
  FrameGraph g(ctx(), size);
  vk::Image outImage = transferImage(ctx(), size);
  TextureHandle out =
      g.importTexture("output", outImage.handle(), outImage.view(), rgba8(),
                      VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  CopyChain chain(g);
  TextureHandle &t1 = chain.t1, &t3 = chain.t3;
  g.addPass(
      "t3_to_output",
      [&](PassBuilder& pb) {
        pb.read(t3, TextureUsage::TransferSrc);
        out = pb.write(out, TextureUsage::TransferDst);
      },
      [&](PassContext& pc) { copyImage(pc, t3, out); });
  g.markOutput(out);
  g.compile();
  EXPECT_EQ(g.stats().transientTextures, 3u);
  EXPECT_LT(g.stats().transientBytesAllocated, g.stats().transientBytesRequested) << g.describe();
  // t3 took over t1's memory after t1's last read: t1 cannot be read after the frame.
  EXPECT_FALSE(g.intactAtEnd(t1)) << g.describe();
  EXPECT_TRUE(g.intactAtEnd(t3));
  EXPECT_TRUE(g.intactAtEnd(out));  // imported

  vk::DescriptorArena arena(ctx());
  vk::GpuTimer timer(ctx());
  vk::Buffer readback(ctx(), size.width * size.height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  for (int frame = 0; frame < 2; ++frame) {  // twice: imported state carries across frames
    ctx().submitAndWait([&](VkCommandBuffer cmd) {
      timer.beginFrame(cmd);
      g.execute(cmd, arena, &timer);
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {size.width, size.height, 1};
      vkCmdCopyImageToBuffer(cmd, outImage.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             readback.handle(), 1, &region);
    });
    EXPECT_EQ(timer.collect().size(), 4u);
  }
  const auto* px = static_cast<const uint8_t*>(readback.mapped());
  for (uint32_t i = 0; i < size.width * size.height; ++i)
    ASSERT_NEAR(px[i * 4], 64, 1) << "pixel " << i;
}

// t1 is written and read by nobody (an output no pass consumes this frame); t3, created later,
// may take its memory. t3's first write must then wait for t1's writes and make them available
// (a write-after-write on aliased memory): synchronization validation, on in these tests, checks
// the barrier carries the earlier occupant's write access, not only its stages.
// A texture marked as an output keeps its memory to the end of the frame, even when a later
// transient could otherwise have reused it.
TEST_F(FrameGraphTest, OutputsAreNotAliasedByLaterPasses) {
  const VkExtent2D size{32, 16};
  FrameGraph g(ctx(), size);
  CopyChain chain(g);
  TextureHandle &t1 = chain.t1, &t3 = chain.t3;
  g.markOutput(t3);
  g.markOutput(t1);  // read after the frame too
  g.compile();
  EXPECT_TRUE(g.intactAtEnd(t1)) << g.describe();
  EXPECT_TRUE(g.intactAtEnd(t3)) << g.describe();
}

TEST_F(FrameGraphTest, AliasedFirstWriteWaitsForTheEarlierOccupantsWrites) {
  const VkExtent2D size{32, 16};
  FrameGraph g(ctx(), size);
  vk::Image outImage = transferImage(ctx(), size);
  TextureHandle out =
      g.importTexture("output", outImage.handle(), outImage.view(), rgba8(),
                      VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  TextureHandle t1, t2, t3;
  g.addPass(
      "write_t1_and_t2",
      [&](PassBuilder& pb) {
        t1 = pb.write(pb.create("t1", rgba8()), TextureUsage::TransferDst);
        t2 = pb.write(pb.create("t2", rgba8()), TextureUsage::TransferDst);
      },
      [&](PassContext& pc) {
        clearTo(pc, t1, 1.0f);
        clearTo(pc, t2, 0.25f);
      });
  g.addPass(
      "t2_to_t3",
      [&](PassBuilder& pb) {
        pb.read(t2, TextureUsage::TransferSrc);
        t3 = pb.write(pb.create("t3", rgba8()), TextureUsage::TransferDst);
      },
      [&](PassContext& pc) { copyImage(pc, t2, t3); });
  g.addPass(
      "t3_to_output",
      [&](PassBuilder& pb) {
        pb.read(t3, TextureUsage::TransferSrc);
        out = pb.write(out, TextureUsage::TransferDst);
      },
      [&](PassContext& pc) { copyImage(pc, t3, out); });
  g.markOutput(out);
  g.compile();
  ASSERT_LT(g.stats().transientBytesAllocated, g.stats().transientBytesRequested)
      << "t3 must reuse t1's memory for the test to bite\n"
      << g.describe();
  vk::DescriptorArena arena(ctx());
  for (int frame = 0; frame < 2; ++frame)
    ctx().submitAndWait([&](VkCommandBuffer cmd) { g.execute(cmd, arena, nullptr); });
}

}  // namespace
}  // namespace gi
