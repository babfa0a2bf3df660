// Vulkan core services: sub-allocation, run-time GLSL compilation, the on-disk pipeline cache.
#include <gtest/gtest.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include "gi/errors.h"
#include "gi/vk/memory.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

TEST(FreeList, AlignsAndNeverOverlaps) {
  vk::FreeList list(1 << 20);
  std::mt19937 rng(7);
  std::vector<std::pair<VkDeviceSize, VkDeviceSize>> live;
  for (int i = 0; i < 2000; ++i) {
    if (!live.empty() && rng() % 3 == 0) {  // free a random live range
      size_t k = rng() % live.size();
      list.free(live[k].first, live[k].second);
      live.erase(live.begin() + long(k));
      continue;
    }
    VkDeviceSize size = 1 + rng() % 4096, align = VkDeviceSize(1) << (rng() % 9);
    auto offset = list.allocate(size, align);
    if (!offset) continue;
    EXPECT_EQ(*offset % align, 0u);
    EXPECT_LE(*offset + size, list.capacity());
    for (auto& [o, s] : live) ASSERT_TRUE(*offset + size <= o || o + s <= *offset) << "overlap";
    live.emplace_back(*offset, size);
  }
  for (auto& [o, s] : live) list.free(o, s);
  EXPECT_EQ(list.used(), 0u);
  EXPECT_EQ(list.freeRangeCount(), 1u) << "free ranges must coalesce back into one";
}

TEST(FreeList, ReportsExhaustion) {
  vk::FreeList list(256);
  EXPECT_TRUE(list.allocate(200, 1));
  EXPECT_FALSE(list.allocate(100, 1));
  EXPECT_TRUE(list.allocate(56, 1));
}

class VkCoreTest : public VulkanTest {};

TEST_F(VkCoreTest, ManyBuffersShareFewMemoryBlocks) {
  const size_t blocksBefore = ctx().allocator().blockCount();
  std::vector<vk::Buffer> buffers;
  for (int i = 0; i < 200; ++i)
    buffers.emplace_back(ctx(), 4096 + i * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, i % 2 == 0);
  // 200 resources, but only one block per memory type in use (sub-allocation).
  EXPECT_LE(ctx().allocator().blockCount() - blocksBefore, 2u);
  buffers.clear();
  EXPECT_EQ(ctx().allocator().blockCount(), blocksBefore);
}

// On a CPU device the context fixes glibc's malloc thresholds (context.cpp): a 30 MiB block
// then comes from the heap, not from a fresh mapping that the driver's per-frame allocations
// would fault in again every frame (glibc's default hands out anything above its moving mmap
// threshold, 128 KiB at first, as a mapping).
TEST_F(VkCoreTest, ACpuDeviceKeepsFreedMemoryInTheProcess) {
#if !defined(__GLIBC__) || defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "glibc's own allocator only";
#else
  if (ctx().properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU)
    GTEST_SKIP() << "not a CPU device";
  const size_t mappedBefore = mallinfo2().hblkhd;
  auto* volatile block = static_cast<char*>(std::malloc(30 << 20));
  ASSERT_NE(block, nullptr);
  block[0] = 1;
  const size_t mappedDuring = mallinfo2().hblkhd;
  std::free(block);
  EXPECT_EQ(mappedDuring, mappedBefore) << "the block was mapped, not taken from the heap";
#endif
}

TEST_F(VkCoreTest, RuntimeGlslCompilesEngineShaders) {
  const std::string dir = std::string(GI_SOURCE_DIR) + "/engine/shaders";
  for (const char* name : {"lighting.comp", "tonemap.comp", "gbuffer.vert", "gbuffer.frag"}) {
    std::vector<uint32_t> spirv = vk::compileGlslFile(dir + "/" + name, {dir});
    ASSERT_GT(spirv.size(), 5u) << name;
    EXPECT_EQ(spirv[0], 0x07230203u) << name;
  }
  // A run-time compiled compute shader builds a pipeline without validation errors.
  vk::Pipeline p = vk::Pipeline::compute(ctx(), vk::compileGlslFile(dir + "/floor.comp", {dir}),
                                         {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                                          {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                          {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}});
  EXPECT_NE(p.handle(), VK_NULL_HANDLE);
}

TEST_F(VkCoreTest, RuntimeGlslErrorNamesSourceAndLine) {
  const std::string bad =
      "#version 460\nlayout(local_size_x = 1) in;\nvoid main() { undefinedThing = 1; }\n";
  try {
    vk::compileGlsl(bad, VK_SHADER_STAGE_COMPUTE_BIT, "broken.comp");
    FAIL() << "expected a compilation error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Parse);
    EXPECT_NE(std::string(e.what()).find("broken.comp"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("undefinedThing"), std::string::npos) << e.what();
  }
}

TEST_F(VkCoreTest, MissingSpirvIsAClearError) {
  try {
    vk::loadSpirv("does-not-exist.comp");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::FileNotFound);
    EXPECT_NE(std::string(e.what()).find("does-not-exist.comp.spv"), std::string::npos);
  }
}

TEST(PipelineCache, WrittenToDiskAndReloaded) {
  const auto path = std::filesystem::temp_directory_path() / "gi-test-cache-roundtrip.bin";
  std::filesystem::remove(path);
  auto makeContext = [&] {
    vk::ContextOptions o;
    o.validation = true;
    o.pipelineCachePath = path.string();
    return std::make_unique<vk::Context>(o);
  };
  {
    auto ctx = makeContext();
    vk::Pipeline p = vk::Pipeline::compute(*ctx, vk::loadSpirv("floor.comp"),
                                           {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                                            {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                            {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}});
    EXPECT_EQ(ctx->validationErrors(), 0u);
  }
  ASSERT_TRUE(std::filesystem::exists(path));
  // At least the header naming this device (lavapipe stores nothing beyond it).
  ASSERT_GE(std::filesystem::file_size(path), sizeof(VkPipelineCacheHeaderVersionOne));
  {
    VkPipelineCacheHeaderVersionOne header{};
    std::ifstream(path, std::ios::binary).read(reinterpret_cast<char*>(&header), sizeof header);
    EXPECT_EQ(header.headerVersion, VK_PIPELINE_CACHE_HEADER_VERSION_ONE);
    EXPECT_GE(header.headerSize, 32u);
  }
  // A corrupt cache file is ignored, not trusted.
  {
    std::ofstream(path, std::ios::binary)
        << "garbage that is not a pipeline cache header at all......";
  }
  auto ctx = makeContext();
  EXPECT_EQ(ctx->validationErrors(), 0u);
  std::filesystem::remove(path);
}

// Every Vulkan test runs under synchronization validation (vulkan_fixture: validation on, and
// Context enables VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT with it). Proof
// that it is live: two transfer writes to one buffer without a barrier are reported as a hazard.
TEST(SyncValidation, AMissingBarrierIsReported) {
  vk::ContextOptions o;
  o.validation = true;
  o.pipelineCachePath =
      (std::filesystem::temp_directory_path() / "gi-test-sync-validation-cache.bin").string();
  vk::Context ctx(o);
  vk::Buffer buffer(ctx, 4096, VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
  ctx.submitAndWait([&](VkCommandBuffer c) {
    vkCmdFillBuffer(c, buffer.handle(), 0, VK_WHOLE_SIZE, 1u);
    vkCmdFillBuffer(c, buffer.handle(), 0, VK_WHOLE_SIZE, 2u);  // no barrier in between
  });
  EXPECT_GE(ctx.validationErrors(), 1u);
  bool hazard = false;
  for (const std::string& m : ctx.validationMessages())
    hazard |= m.find("SYNC-HAZARD-WRITE-AFTER-WRITE") != std::string::npos;
  EXPECT_TRUE(hazard) << "synchronization validation did not report the write-after-write";
}

}  // namespace
}  // namespace gi
