// Frame graph textures with layers, mips, cube faces and depth: per-subresource writes and
// barriers, partial-write culling, persistent (history) textures and optional reads with a
// neutral fallback, all on real GPU work under validation + synchronization validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "gi/errors.h"
#include "gi/graph/frame_graph.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

class FrameGraphLayersTest : public test::VulkanTest {};

constexpr VkFormat kR32 = VK_FORMAT_R32_SFLOAT;

TextureDesc r32(uint32_t w, uint32_t h, TextureType type = TextureType::Tex2D, uint32_t layers = 1,
                uint32_t mips = 1, uint32_t depth = 1) {
  TextureDesc d{kR32, SizeClass::Absolute, 1.0f, w, h};
  d.type = type;
  d.layers = layers;
  d.mips = mips;
  d.depth = depth;
  return d;
}

// value = base + kx*x + ky*y + kz*z, z being the layer (IMAGE = image2DArray) or the depth
// slice (image3D).
struct FillPush {
  float base, kx, ky, kz;
};

std::string fillSource(const std::string& image) {
  const bool is2D = image == "image2D";
  return "#version 450\nlayout(local_size_x = 4, local_size_y = 4, local_size_z = 1) in;\n"
         "layout(binding = 0, r32f) uniform writeonly " +
         image +
         " img;\n"
         "layout(push_constant) uniform P { float base, kx, ky, kz; } pc;\n"
         "void main() {\n" +
         (is2D ? "  ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
                 "  if (any(greaterThanEqual(p, imageSize(img)))) return;\n"
                 "  imageStore(img, p, vec4(pc.base + pc.kx * p.x + pc.ky * p.y));\n"
               : "  ivec3 p = ivec3(gl_GlobalInvocationID);\n"
                 "  if (any(greaterThanEqual(p, imageSize(img)))) return;\n"
                 "  imageStore(img, p, vec4(pc.base + pc.kx * p.x + pc.ky * p.y + pc.kz * "
                 "p.z));\n") +
         "}\n";
}

vk::Pipeline computePipeline(vk::Context& ctx, const std::string& source, const std::string& name,
                             const std::vector<vk::Binding>& bindings, uint32_t pushBytes) {
  return vk::Pipeline::compute(ctx, vk::compileGlsl(source, VK_SHADER_STAGE_COMPUTE_BIT, name),
                               bindings, pushBytes);
}

// The pipeline of fillSource(image): one storage image, FillPush as push constants.
vk::Pipeline fillPipeline(vk::Context& ctx, const std::string& image, const std::string& name) {
  return computePipeline(ctx, fillSource(image), name, {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}},
                         sizeof(FillPush));
}

// Fills a storage view of `extent` (depth = layers or slices) with the FillPush pattern.
void fill(PassContext& pc, const vk::Pipeline& p, VkImageView view, VkExtent3D extent,
          FillPush push) {
  vk::DescriptorWriter w;
  w.storageImage(0, view);
  pc.descriptors().bind(pc.cmd(), p, w);
  vkCmdPushConstants(pc.cmd(), p.layout(), VK_SHADER_STAGE_ALL, 0, sizeof push, &push);
  vkCmdDispatch(pc.cmd(), (extent.width + 3) / 4, (extent.height + 3) / 4, extent.depth);
}

// A side-effect pass copying every mip (all layers, all slices) of an R32F texture into a
// host-visible buffer, mip after mip, tightly packed.
void addReadback(FrameGraph& g, TextureHandle h, vk::Buffer& out, uint32_t depth = 1) {
  g.addPass(
      "readback",
      [&, h](PassBuilder& pb) {
        pb.read(h, TextureUsage::TransferSrc);
        pb.sideEffect();
      },
      [h, &out, depth](PassContext& pc) {
        std::vector<VkBufferImageCopy> regions;
        VkDeviceSize offset = 0;
        for (uint32_t m = 0; m < pc.mips(h); ++m) {
          const VkExtent2D e = pc.extent(h, m);
          const uint32_t d = std::max(1u, depth >> m);
          VkBufferImageCopy r{};
          r.bufferOffset = offset;
          r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, pc.layers(h)};
          r.imageExtent = {e.width, e.height, d};
          regions.push_back(r);
          offset += VkDeviceSize(e.width) * e.height * d * pc.layers(h) * 4;
        }
        ASSERT_LE(offset, out.size());
        vkCmdCopyImageToBuffer(pc.cmd(), pc.image(h), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               out.handle(), uint32_t(regions.size()), regions.data());
      });
}

const float* floats(const vk::Buffer& b) {
  return static_cast<const float*>(b.mapped());
}

void run(vk::Context& ctx, FrameGraph& g) {
  vk::DescriptorArena arena(ctx);
  ctx.submitAndWait([&](VkCommandBuffer cmd) { g.execute(cmd, arena, nullptr); });
}

// Test 1: one compute pass per layer writes a constant through a single-layer view; a later
// pass samples the whole array (sampler2DArray) into a buffer.
TEST_F(FrameGraphLayersTest, PerLayerWritesThenWholeArrayRead) {
  constexpr uint32_t kSize = 32, kLayers = 4;
  FrameGraph g(ctx(), {kSize, kSize});
  vk::Pipeline fill2D = fillPipeline(ctx(), "image2D", "fill2d.comp");
  vk::Pipeline gather = computePipeline(
      ctx(),
      "#version 450\nlayout(local_size_x = 4, local_size_y = 4, local_size_z = 1) in;\n"
      "layout(binding = 0) uniform sampler2DArray src;\n"
      "layout(binding = 1, std430) writeonly buffer Out { float v[]; } o;\n"
      "void main() {\n"
      "  ivec3 p = ivec3(gl_GlobalInvocationID);\n"
      "  ivec3 s = textureSize(src, 0);\n"
      "  if (any(greaterThanEqual(p, s))) return;\n"
      "  o.v[(p.z * s.y + p.y) * s.x + p.x] = texelFetch(src, p, 0).r;\n"
      "}\n",
      "gather_array.comp",
      {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}, 0);
  vk::Sampler nearest(ctx(), VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
  const VkDeviceSize bytes = kSize * kSize * kLayers * 4;
  vk::Buffer out(ctx(), bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  std::memset(out.mapped(), 0xff, bytes);

  TextureHandle arr;
  g.addPass("create",
            [&](PassBuilder& pb) {
              arr = pb.create("array", r32(kSize, kSize, TextureType::Tex2DArray, kLayers));
            },
            {});
  for (uint32_t l = 0; l < kLayers; ++l)
    g.addPass(
        "layer" + std::to_string(l),
        [&, l](PassBuilder& pb) {
          arr = pb.write(arr, TextureUsage::StorageWrite, Subresource::layerOf(l));
        },
        [&, l, h = arr](PassContext& pc) {
          const VkExtent2D e = pc.extent(h);
          fill(pc, fill2D, pc.view(h, Subresource::layerOf(l)), {e.width, e.height, 1},
               {10.0f * float(l + 1), 0, 0, 0});
        });
  BufferHandle outHandle = g.importBuffer("out", out.handle(), bytes);
  g.addPass(
      "gather",
      [&](PassBuilder& pb) {
        pb.read(arr);  // whole array, sampled
        outHandle = pb.write(outHandle, BufferUsage::StorageWrite);
      },
      [&, h = arr](PassContext& pc) {
        EXPECT_EQ(pc.layers(h), kLayers);
        vk::DescriptorWriter w;
        w.sampled(0, pc.view(h), nearest.handle())
            .buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(outHandle));
        pc.descriptors().bind(pc.cmd(), gather, w);
        vkCmdDispatch(pc.cmd(), kSize / 4, kSize / 4, kLayers);
      });
  g.markOutput(outHandle);
  g.compile();
  EXPECT_EQ(g.executedPasses().size(), 5u) << g.describe();  // every layer writer is kept
  for (int frame = 0; frame < 2; ++frame) {
    run(ctx(), g);
    for (uint32_t l = 0; l < kLayers; ++l)
      for (uint32_t i = 0; i < kSize * kSize; ++i)
        ASSERT_EQ(floats(out)[l * kSize * kSize + i], 10.0f * float(l + 1))
            << "layer " << l << " texel " << i << " frame " << frame;
  }
  EXPECT_NE(g.describe().find("array[layer 2]"), std::string::npos) << g.describe();
}

// CPU model of the mip chain: mip 0 = x + 32 y, mip i = 2x2 average of mip i-1 (all values are
// exact in float, so the GPU must match exactly).
std::vector<std::vector<float>> expectedMips(uint32_t size) {
  std::vector<std::vector<float>> mips;
  std::vector<float> m0(size * size);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x) m0[y * size + x] = float(x) + float(size) * float(y);
  mips.push_back(m0);
  for (uint32_t s = size / 2; s >= 1; s /= 2) {
    const std::vector<float>& prev = mips.back();
    std::vector<float> next(s * s);
    for (uint32_t y = 0; y < s; ++y)
      for (uint32_t x = 0; x < s; ++x) {
        const uint32_t ps = s * 2;
        next[y * s + x] = (prev[2 * y * ps + 2 * x] + prev[2 * y * ps + 2 * x + 1] +
                           prev[(2 * y + 1) * ps + 2 * x] + prev[(2 * y + 1) * ps + 2 * x + 1]) *
                          0.25f;
      }
    mips.push_back(next);
  }
  return mips;
}

void expectMips(const vk::Buffer& out, uint32_t size) {
  const auto expected = expectedMips(size);
  size_t offset = 0;
  for (size_t m = 0; m < expected.size(); ++m) {
    for (size_t i = 0; i < expected[m].size(); ++i)
      ASSERT_EQ(floats(out)[offset + i], expected[m][i]) << "mip " << m << " texel " << i;
    offset += expected[m].size();
  }
}

std::string downsampleSource(bool storageSource) {
  return std::string("#version 450\nlayout(local_size_x = 4, local_size_y = 4) in;\n") +
         (storageSource ? "layout(binding = 0, r32f) uniform readonly image2D src;\n"
                          "#define FETCH(q) imageLoad(src, q).r\n"
                        : "layout(binding = 0) uniform sampler2D src;\n"
                          "#define FETCH(q) texelFetch(src, q, 0).r\n") +
         "layout(binding = 1, r32f) uniform writeonly image2D dst;\n"
         "void main() {\n"
         "  ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
         "  if (any(greaterThanEqual(p, imageSize(dst)))) return;\n"
         "  ivec2 q = 2 * p;\n"
         "  float s = FETCH(q) + FETCH(q + ivec2(1, 0)) + FETCH(q + ivec2(0, 1)) +\n"
         "            FETCH(q + ivec2(1, 1));\n"
         "  imageStore(dst, p, vec4(s * 0.25));\n"
         "}\n";
}

// Test 2: mip 0 written, then one pass per mip reads mip i-1 (sampled) and writes mip i.
TEST_F(FrameGraphLayersTest, MipChainPassPerMip) {
  constexpr uint32_t kSize = 32;
  FrameGraph g(ctx(), {kSize, kSize});
  vk::Pipeline fill2D = fillPipeline(ctx(), "image2D", "fill2d.comp");
  vk::Pipeline down = computePipeline(
      ctx(), downsampleSource(false), "down.comp",
      {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER}, {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}}, 0);
  vk::Sampler nearest(ctx(), VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
  vk::Buffer out(ctx(), kSize * kSize * 4 * 2, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);

  TextureHandle t;
  g.addPass(
      "mip0",
      [&](PassBuilder& pb) {
        t = pb.create("chain", r32(kSize, kSize, TextureType::Tex2D, 1, 0));  // full chain
        t = pb.write(t, TextureUsage::StorageWrite, Subresource::mipLevel(0));
      },
      [&, &h = t](PassContext& pc) {
        EXPECT_EQ(pc.mips(h), 6u);
        fill(pc, fill2D, pc.view(h, Subresource::mipLevel(0)), {kSize, kSize, 1},
             {0, 1, float(kSize), 0});
      });
  for (uint32_t m = 1; m < 6; ++m)
    g.addPass(
        "mip" + std::to_string(m),
        [&, m](PassBuilder& pb) {
          pb.read(t, TextureUsage::Sampled, Subresource::mipLevel(m - 1));
          t = pb.write(t, TextureUsage::StorageWrite, Subresource::mipLevel(m));
        },
        [&, m, &h = t](PassContext& pc) {
          const VkExtent2D e = pc.extent(h, m);
          EXPECT_EQ(e.width, kSize >> m);
          vk::DescriptorWriter w;
          w.sampled(0, pc.view(h, Subresource::mipLevel(m - 1)), nearest.handle())
              .storageImage(1, pc.view(h, Subresource::mipLevel(m)));
          pc.descriptors().bind(pc.cmd(), down, w);
          vkCmdDispatch(pc.cmd(), (e.width + 3) / 4, (e.height + 3) / 4, 1);
        });
  addReadback(g, t, out);
  g.compile();
  EXPECT_EQ(g.executedPasses().size(), 7u) << g.describe();
  run(ctx(), g);
  expectMips(out, kSize);
  EXPECT_NE(g.describe().find("chain[mip 3]"), std::string::npos) << g.describe();
  EXPECT_NE(g.toDot().find("label=\"[mip 3]\""), std::string::npos) << g.toDot();
  const FrameGraph::TextureState state = g.textureState(t);  // mip 0, layer 0
  EXPECT_EQ(state.extent.width, kSize);
  EXPECT_EQ(state.layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

// Test 2b: the whole chain in one pass, with PassContext::barrier between the mips.
TEST_F(FrameGraphLayersTest, MipChainInOnePassWithInternalBarriers) {
  constexpr uint32_t kSize = 32;
  FrameGraph g(ctx(), {kSize, kSize});
  vk::Pipeline fill2D = fillPipeline(ctx(), "image2D", "fill2d.comp");
  vk::Pipeline down = computePipeline(
      ctx(), downsampleSource(true), "down_storage.comp",
      {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}, {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}}, 0);
  vk::Buffer out(ctx(), kSize * kSize * 4 * 2, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  TextureHandle t;
  g.addPass(
      "mip0",
      [&](PassBuilder& pb) {
        t = pb.write(pb.create("chain", r32(kSize, kSize, TextureType::Tex2D, 1, 0)),
                     TextureUsage::StorageWrite, Subresource::mipLevel(0));
      },
      [&, &h = t](PassContext& pc) {
        fill(pc, fill2D, pc.view(h, Subresource::mipLevel(0)), {kSize, kSize, 1},
             {0, 1, float(kSize), 0});
      });
  g.addPass(
      "generate_mips",
      [&](PassBuilder& pb) {
        pb.read(t, TextureUsage::StorageRead, Subresource::mipLevel(0));
        t = pb.write(t, TextureUsage::StorageWrite);
      },
      [&, &h = t](PassContext& pc) {
        for (uint32_t m = 1; m < pc.mips(h); ++m) {
          if (m > 1) pc.barrier(h, Subresource::mipLevel(m - 1));
          const VkExtent2D e = pc.extent(h, m);
          vk::DescriptorWriter w;
          w.storageImage(0, pc.view(h, Subresource::mipLevel(m - 1)))
              .storageImage(1, pc.view(h, Subresource::mipLevel(m)));
          pc.descriptors().bind(pc.cmd(), down, w);
          vkCmdDispatch(pc.cmd(), (e.width + 3) / 4, (e.height + 3) / 4, 1);
        }
      });
  addReadback(g, t, out);
  g.compile();
  run(ctx(), g);
  expectMips(out, kSize);
}

// Test 3: a cube (written as a 2-D array of its faces, sampled through its natural cube view)
// and a 3-D texture, written and read back exactly.
TEST_F(FrameGraphLayersTest, CubeAndVolumeTextures) {
  FrameGraph g(ctx(), {16, 16});
  vk::Pipeline fillArray = fillPipeline(ctx(), "image2DArray", "fill_array.comp");
  vk::Pipeline fill3D = fillPipeline(ctx(), "image3D", "fill3d.comp");
  vk::Pipeline lookup = computePipeline(
      ctx(),
      "#version 450\nlayout(local_size_x = 1) in;\n"
      "layout(binding = 0) uniform samplerCube cube;\n"
      "layout(binding = 1, std430) writeonly buffer Out { float v[6]; } o;\n"
      "const vec3 dirs[6] = vec3[](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0),\n"
      "                            vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));\n"
      "void main() { for (int i = 0; i < 6; ++i) o.v[i] = textureLod(cube, dirs[i], 0).r; }\n",
      "cube_lookup.comp",
      {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}, 0);
  vk::Sampler nearest(ctx(), VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
  constexpr uint32_t kFace = 8, kW = 8, kH = 8, kD = 4;
  vk::Buffer cubeOut(ctx(), kFace * kFace * 6 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  vk::Buffer volumeOut(ctx(), kW * kH * kD * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  vk::Buffer faces(ctx(), 6 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  BufferHandle facesHandle = g.importBuffer("faces", faces.handle(), 6 * 4);

  TextureHandle cube, volume;
  g.addPass(
      "write_cube",
      [&](PassBuilder& pb) {
        TextureDesc d = r32(kFace, kFace, TextureType::Cube);
        cube = pb.write(pb.create("cube", d), TextureUsage::StorageWrite);
      },
      [&, &h = cube](PassContext& pc) {
        EXPECT_EQ(pc.layers(h), 6u);  // forced for cubes
        // Each face: 100 * (face + 1) + x + 8 y; the face is the array layer.
        fill(pc, fillArray, pc.view(h, Subresource::all()), {kFace, kFace, 6},
             {100, 1, float(kFace), 100});
      });
  g.addPass(
      "write_volume",
      [&](PassBuilder& pb) {
        volume = pb.write(pb.create("volume", r32(kW, kH, TextureType::Tex3D, 1, 1, kD)),
                          TextureUsage::StorageWrite);
      },
      [&, &h = volume](PassContext& pc) {
        fill(pc, fill3D, pc.view(h), {kW, kH, kD}, {0.5f, 1, float(kW), float(kW * kH)});
      });
  g.addPass(
      "sample_cube",
      [&](PassBuilder& pb) {
        pb.read(cube);
        facesHandle = pb.write(facesHandle, BufferUsage::StorageWrite);
      },
      [&, &h = cube](PassContext& pc) {
        vk::DescriptorWriter w;
        w.sampled(0, pc.view(h), nearest.handle())
            .buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(facesHandle));
        pc.descriptors().bind(pc.cmd(), lookup, w);
        vkCmdDispatch(pc.cmd(), 1, 1, 1);
      });
  g.markOutput(facesHandle);
  addReadback(g, cube, cubeOut);
  addReadback(g, volume, volumeOut, kD);
  g.compile();
  run(ctx(), g);
  for (uint32_t f = 0; f < 6; ++f)
    for (uint32_t y = 0; y < kFace; ++y)
      for (uint32_t x = 0; x < kFace; ++x)
        ASSERT_EQ(floats(cubeOut)[(f * kFace + y) * kFace + x], 100.0f * (f + 1) + x + kFace * y)
            << "face " << f << " (" << x << ", " << y << ")";
  // Each axis direction hits the centre of its face: one of the four centre texels.
  for (uint32_t f = 0; f < 6; ++f) {
    const float v = floats(faces)[f] - 100.0f * (f + 1);
    EXPECT_TRUE(v == 27 || v == 28 || v == 35 || v == 36) << "face " << f << ": " << v;
  }
  for (uint32_t i = 0; i < kW * kH * kD; ++i)
    ASSERT_EQ(floats(volumeOut)[i], 0.5f + float(i)) << "texel " << i;
}

// A 2-layer array and, after its last use, a cube share memory; both still read back exactly.
TEST_F(FrameGraphLayersTest, ArrayAndCubeAliasMemory) {
  constexpr uint32_t kSize = 16;
  FrameGraph g(ctx(), {kSize, kSize});
  vk::Pipeline fillArray = fillPipeline(ctx(), "image2DArray", "fill_array.comp");
  vk::Buffer arrayOut(ctx(), kSize * kSize * 2 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  vk::Buffer cubeOut(ctx(), kSize * kSize * 6 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  TextureHandle arr, cube;
  g.addPass(
      "write_array",
      [&](PassBuilder& pb) {
        arr = pb.write(pb.create("array", r32(kSize, kSize, TextureType::Tex2DArray, 2)),
                       TextureUsage::StorageWrite);
      },
      [&, &h = arr](PassContext& pc) {
        fill(pc, fillArray, pc.view(h, Subresource::all()), {kSize, kSize, 2}, {1, 1, 0, 1000});
      });
  addReadback(g, arr, arrayOut);
  g.addPass(
      "write_cube",
      [&](PassBuilder& pb) {
        cube = pb.write(pb.create("cube", r32(kSize, kSize, TextureType::Cube)),
                        TextureUsage::StorageWrite);
      },
      [&, &h = cube](PassContext& pc) {
        fill(pc, fillArray, pc.view(h, Subresource::all()), {kSize, kSize, 6}, {2, 0, 1, 100});
      });
  addReadback(g, cube, cubeOut);
  g.compile();
  EXPECT_EQ(g.stats().transientTextures, 2u);
  EXPECT_LT(g.stats().transientBytesAllocated, g.stats().transientBytesRequested) << g.describe();
  for (int frame = 0; frame < 2; ++frame) {
    run(ctx(), g);
    for (uint32_t l = 0; l < 2; ++l)
      for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x)
          ASSERT_EQ(floats(arrayOut)[(l * kSize + y) * kSize + x], 1.0f + x + 1000.0f * l);
    for (uint32_t f = 0; f < 6; ++f)
      for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x)
          ASSERT_EQ(floats(cubeOut)[(f * kSize + y) * kSize + x], 2.0f + y + 100.0f * f);
  }
}

// Test 4: a write to part of a texture keeps the producers of the rest; a whole write does not.
TEST_F(FrameGraphLayersTest, PartialWritesKeepEarlierProducers) {
  FrameGraph g(ctx(), {8, 8});
  const TextureDesc desc = r32(8, 8, TextureType::Tex2DArray, 2);
  TextureHandle a, b, c;
  g.addPass("A",
            [&](PassBuilder& pb) {
              a = pb.write(pb.create("t", desc), TextureUsage::StorageWrite,
                           Subresource::layerOf(0));
            },
            {});
  g.addPass("B",
            [&](PassBuilder& pb) {
              b = pb.write(a, TextureUsage::StorageWrite, Subresource::layerOf(1));
            },
            {});
  g.addPass("readB",
            [&](PassBuilder& pb) {
              pb.read(b);
              pb.sideEffect();
            },
            {});
  g.compile();
  EXPECT_EQ(g.executedPasses(), (std::vector<std::string>{"A", "B", "readB"}));

  g.reset();
  g.addPass("A",
            [&](PassBuilder& pb) {
              a = pb.write(pb.create("t", desc), TextureUsage::StorageWrite,
                           Subresource::layerOf(0));
            },
            {});
  g.addPass("B",
            [&](PassBuilder& pb) {
              b = pb.write(a, TextureUsage::StorageWrite, Subresource::layerOf(1));
            },
            {});
  g.addPass("C", [&](PassBuilder& pb) { c = pb.write(b, TextureUsage::StorageWrite); }, {});
  g.markOutput(c);
  g.compile();
  EXPECT_EQ(g.executedPasses(), (std::vector<std::string>{"C"}));
  EXPECT_EQ(g.culledPasses(), (std::vector<std::string>{"A", "B"}));

  // One subresource in two layouts in one pass is an error; different subresources are fine.
  g.reset();
  g.addPass("conflict",
            [&](PassBuilder& pb) {
              TextureHandle t = pb.write(pb.create("t", desc), TextureUsage::StorageWrite,
                                         Subresource::layerOf(0));
              pb.read(t, TextureUsage::Sampled, Subresource::layerOf(0));
              pb.sideEffect();
            },
            {});
  try {
    g.compile();
    FAIL() << "expected a layout conflict";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'t[layer 0]' in two conflicting layouts"),
              std::string::npos)
        << e.what();
  }

  // A subresource outside the texture is an error naming it.
  g.reset();
  g.addPass("bad",
            [&](PassBuilder& pb) {
              c = pb.write(pb.create("small", desc), TextureUsage::StorageWrite,
                           Subresource::layerOf(2));
            },
            {});
  g.markOutput(c);
  try {
    g.compile();
    FAIL() << "expected an out-of-range error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'small'"), std::string::npos) << e.what();
  }
}

// Test 5: a persistent texture holds last frame's value; history is invalid until written and
// after a resize, which recreates it cleared to zero.
TEST_F(FrameGraphLayersTest, PersistentHistoryAcrossFramesAndResize) {
  FrameGraph g(ctx(), {16, 16});
  vk::Pipeline fill2D = fillPipeline(ctx(), "image2D", "fill2d.comp");
  vk::Buffer out(ctx(), 16 * 16 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  TextureDesc desc{kR32};  // output-relative
  float frameValue = 0;
  bool validInPass = true;
  VkExtent2D extentInPass{};
  TextureHandle history;
  bool validAtSetup = true;
  auto build = [&] {
    history = g.persistentTexture("history", desc);
    validAtSetup = g.historyValid(history);  // effects decide at setup whether to use it
    addReadback(g, history, out);            // last frame's value, before this frame's write
    g.addPass(
        "update", [&](PassBuilder& pb) { history = pb.write(history, TextureUsage::StorageWrite); },
        [&, h = history](PassContext& pc) {
          validInPass = g.historyValid(h);
          extentInPass = pc.extent(h);
          fill(pc, fill2D, pc.view(h), {extentInPass.width, extentInPass.height, 1},
               {frameValue, 0, 0, 0});
        });
    g.compile();
  };
  auto f = [](int n) { return 3.0f * float(n) + 1.0f; };
  auto expectAll = [&](float v, uint32_t texels, const char* what) {
    for (uint32_t i = 0; i < texels; ++i) ASSERT_EQ(floats(out)[i], v) << what << " texel " << i;
  };
  build();
  EXPECT_FALSE(validAtSetup);
  EXPECT_FALSE(g.historyValid(history));
  for (int n = 0; n < 3; ++n) {
    frameValue = f(n);
    run(ctx(), g);
    EXPECT_EQ(validInPass, n > 0) << "frame " << n;
    EXPECT_TRUE(g.historyValid(history));
    expectAll(n == 0 ? 0.0f : f(n - 1), 16 * 16, "history");
  }
  EXPECT_NE(g.describe().find("history (persistent)"), std::string::npos) << g.describe();
  EXPECT_NE(g.toDot().find("(persistent)"), std::string::npos);

  // Rebuilt at the same size: the history survives reset() and compile().
  g.reset();
  build();
  EXPECT_TRUE(validAtSetup);
  EXPECT_TRUE(g.historyValid(history));
  frameValue = f(3);
  run(ctx(), g);
  expectAll(f(2), 16 * 16, "after rebuild");

  // Resized: recreated, cleared, invalid.
  g.reset();
  g.setOutputExtent({8, 8});
  build();
  EXPECT_FALSE(validAtSetup);
  EXPECT_FALSE(g.historyValid(history));
  EXPECT_EQ(g.textureState(history).extent.width, 8u);
  std::memset(out.mapped(), 0xff, 16 * 16 * 4);
  frameValue = f(4);
  run(ctx(), g);
  EXPECT_FALSE(validInPass);
  EXPECT_EQ(extentInPass.width, 8u);
  expectAll(0.0f, 8 * 8, "after resize");
  frameValue = f(5);
  run(ctx(), g);
  EXPECT_TRUE(validInPass);
  expectAll(f(4), 8 * 8, "after resize, next frame");

  // Not declared in a rebuild: freed, and a new declaration starts over.
  g.reset();
  g.compile();
  g.reset();
  build();
  EXPECT_FALSE(g.historyValid(history));
}

// Test 6: readOptional gives the neutral fallback without a producer, the producer's version
// with one, and an error naming the resource with neither.
TEST_F(FrameGraphLayersTest, OptionalReadsFallBackToNeutralTexture) {
  FrameGraph g(ctx(), {16, 16});
  g.declareFallback("ao", kR32, VkClearColorValue{{1.0f, 0, 0, 0}});
  vk::Pipeline fill2D = fillPipeline(ctx(), "image2D", "fill2d.comp");
  vk::Pipeline sample = computePipeline(
      ctx(),
      "#version 450\nlayout(local_size_x = 1) in;\n"
      "layout(binding = 0) uniform sampler2D ao;\n"
      "layout(binding = 1, std430) writeonly buffer Out { float v[5]; } o;\n"
      "const vec2 uv[5] = vec2[](vec2(0.1, 0.1), vec2(0.5, 0.5), vec2(0.9, 0.3), vec2(0, 0),\n"
      "                          vec2(1, 1));\n"
      "void main() { for (int i = 0; i < 5; ++i) o.v[i] = textureLod(ao, uv[i], 0).r; }\n",
      "sample_ao.comp",
      {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}, 0);
  vk::Sampler linear(ctx(), VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
  vk::Buffer out(ctx(), 5 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  bool fallback = false;
  auto consume = [&] {
    BufferHandle o = g.importBuffer("out", out.handle(), 5 * 4);
    g.addPass(
        "consume",
        [&](PassBuilder& pb) {
          TextureHandle ao = pb.readOptional("ao");
          fallback = pb.isFallback(ao);
          o = pb.write(o, BufferUsage::StorageWrite);
          g.blackboard().put("consumed", ao);
        },
        [&, o](PassContext& pc) {
          vk::DescriptorWriter w;
          w.sampled(0, pc.view(g.blackboard().texture("consumed")), linear.handle())
              .buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, pc.buffer(o));
          pc.descriptors().bind(pc.cmd(), sample, w);
          vkCmdDispatch(pc.cmd(), 1, 1, 1);
        });
    g.markOutput(o);
    g.compile();
  };
  for (int frame = 0; frame < 2; ++frame) {  // the fallback's clear happens once
    g.reset();
    consume();
    EXPECT_TRUE(fallback);
    std::memset(out.mapped(), 0, 5 * 4);
    run(ctx(), g);
    for (int i = 0; i < 5; ++i) EXPECT_EQ(floats(out)[i], 1.0f) << "uv " << i;
  }

  g.reset();
  g.addPass(
      "produce_ao",
      [&](PassBuilder& pb) {
        TextureHandle ao = pb.write(pb.create("ao", TextureDesc{kR32}), TextureUsage::StorageWrite);
        g.blackboard().put("ao", ao);
      },
      [&](PassContext& pc) {
        TextureHandle h = g.blackboard().texture("ao");
        fill(pc, fill2D, pc.view(h), {16, 16, 1}, {0.25f, 0, 0, 0});
      });
  consume();
  EXPECT_FALSE(fallback);
  run(ctx(), g);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(floats(out)[i], 0.25f) << "uv " << i;

  g.reset();
  try {
    g.addPass("needs_gi", [&](PassBuilder& pb) { pb.readOptional("indirect_light"); }, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'indirect_light'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gi
