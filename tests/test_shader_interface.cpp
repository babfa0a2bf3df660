// Shader reflection (gi/vk/shader_interface.h): bindings, push constants and block layouts read
// from SPIR-V; C++ structs checked against them; pipelines and descriptor writes by name.
#include <gtest/gtest.h>

#include <algorithm>

#include <functional>
#include <glm/glm.hpp>
#include <string>

#include "gi/errors.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "gi/vk/shader_interface.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

// Every kind of resource the engine's shaders use, with std140 and std430 layouts that differ
// from a naive C++ struct (a vec3 after a float, a float array in std140).
const char* kShader = R"(#version 460
layout(local_size_x = 4) in;
layout(set = 0, binding = 0) uniform Frame { vec4 viewport; };
layout(set = 0, binding = 1) uniform Params { float scale; vec3 tint; float weights[4]; } params;
layout(set = 0, binding = 2) uniform sampler2D colorTex;
layout(set = 0, binding = 3) uniform usampler2D layers[3];
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D outImage;
layout(set = 0, binding = 6, std430) buffer Results { float values[]; } results;
layout(push_constant) uniform Push { float strength; vec3 tint; } pc;
void main() {
  uint i = gl_GlobalInvocationID.x;
  results.values[i] = pc.strength * float(i) + pc.tint.z + params.scale * 0.0 + viewport.x * 0.0
      + texelFetch(colorTex, ivec2(0), 0).x * 0.0 + float(texelFetch(layers[1], ivec2(0), 0).x) * 0.0;
  if (i == 0u) imageStore(outImage, ivec2(0), vec4(params.weights[3]));
}
)";

vk::ShaderInterface reflected() {
  return vk::reflectShader(vk::compileGlsl(kShader, VK_SHADER_STAGE_COMPUTE_BIT, "probe.comp"),
                           VK_SHADER_STAGE_COMPUTE_BIT, "probe.comp");
}

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::ShaderInterface) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected a gi::Error";
  return {};
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(ShaderInterface, ReadsBindingsByNameTypeAndCount) {
  const vk::ShaderInterface s = reflected();
  ASSERT_EQ(s.bindings.size(), 6u) << s.describe();
  struct Expect {
    const char* name;
    uint32_t binding;
    VkDescriptorType type;
    uint32_t count;
  };
  const Expect expect[] = {
      {"Frame", 0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},  // anonymous block: its type name
      {"params", 1, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
      {"colorTex", 2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1},
      {"layers", 3, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 3},
      {"outImage", 5, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
      {"results", 6, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
  };
  for (size_t i = 0; i < std::size(expect); ++i) {
    SCOPED_TRACE(expect[i].name);
    EXPECT_EQ(s.bindings[i].name, expect[i].name);
    EXPECT_EQ(s.bindings[i].binding, expect[i].binding);
    EXPECT_EQ(s.bindings[i].type, expect[i].type);
    EXPECT_EQ(s.bindings[i].count, expect[i].count);
    EXPECT_EQ(s.find(expect[i].name), &s.bindings[i]);
  }
  EXPECT_EQ(s.find("Params"), s.find("params")) << "a block is also found by its type name";
  EXPECT_EQ(s.find("nothing"), nullptr);
}

TEST(ShaderInterface, ReadsStd140AndStd430BlockLayouts) {
  const vk::ShaderInterface s = reflected();
  const vk::BlockLayout& params = s.find("params")->block;
  EXPECT_EQ(params.name, "Params");
  ASSERT_EQ(params.members.size(), 3u);
  EXPECT_EQ(params.members[1].name, "tint");
  EXPECT_EQ(params.members[1].offset, 16u);  // std140: a vec3 aligns to 16
  EXPECT_EQ(params.members[2].offset, 32u);
  EXPECT_EQ(params.members[2].size, 64u);  // std140: float[4] has a 16-byte stride
  EXPECT_EQ(params.size, 96u);
  // Push constants are std430: the vec3 still aligns to 16.
  EXPECT_EQ(s.pushConstants.name, "Push");
  ASSERT_EQ(s.pushConstants.members.size(), 2u);
  EXPECT_EQ(s.pushConstants.members[1].name, "tint");
  EXPECT_EQ(s.pushConstants.members[1].offset, 16u);
  EXPECT_EQ(s.pushConstants.size, 28u);
  EXPECT_EQ(s.find("results")->block.members[0].size, 0u) << "a runtime array has no size";
}

// The plugin author's bug: {float strength; vec3 tint;} mirrored as a packed C++ struct drew a
// black image with exit 0. Now the pipeline cannot be made and the error names the member.
struct PackedPush {
  float strength;
  glm::vec3 tint;  // offset 4 in C++, 16 in the shader
};
struct PaddedPush {
  float strength;
  float pad[3];
  glm::vec3 tint;
};

TEST(ShaderInterface, APushConstantMismatchNamesTheOwnerBlockAndMember) {
  const vk::ShaderInterface s = reflected();
  const std::string m = messageOf([&] {
    vk::checkBlockLayout(s.pushConstants, GI_CPP_BLOCK(PackedPush, strength, tint), "my_effect");
  });
  EXPECT_TRUE(contains(m, "my_effect")) << m;
  EXPECT_TRUE(contains(m, "'Push'")) << m;
  EXPECT_TRUE(contains(m, "'tint'")) << m;
  EXPECT_TRUE(contains(m, "offset 16 in the shader but 4 in C++")) << m;
  // The padded mirror is accepted.
  EXPECT_NO_THROW(vk::checkBlockLayout(
      s.pushConstants,
      vk::cppBlock<PaddedPush>(
          "PaddedPush", {GI_BLOCK_MEMBER(PaddedPush, strength), GI_BLOCK_MEMBER(PaddedPush, tint)}),
      "my_effect"));
}

// GI_CPP_BLOCK is the explicit list: the type's name and size, each named member's offset and
// size in the order given.
TEST(ShaderInterface, CppBlockFromMemberNames) {
  const vk::CppBlock b = GI_CPP_BLOCK(PaddedPush, tint, strength);
  EXPECT_EQ(b.type, "PaddedPush");
  EXPECT_EQ(b.size, sizeof(PaddedPush));
  ASSERT_EQ(b.members.size(), 2u);
  EXPECT_EQ(b.members[0].name, "tint");
  EXPECT_EQ(b.members[0].offset, offsetof(PaddedPush, tint));
  EXPECT_EQ(b.members[0].size, sizeof(glm::vec3));
  EXPECT_EQ(b.members[1].name, "strength");
  EXPECT_EQ(b.members[1].offset, 0u);
  struct Sixteen {
    float a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p;
  };
  const vk::CppBlock all = GI_CPP_BLOCK(Sixteen, a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p);
  ASSERT_EQ(all.members.size(), 16u);
  EXPECT_EQ(all.members[15].name, "p");
  EXPECT_EQ(all.members[15].offset, 60u);
}

TEST(ShaderInterface, MissingExtraAndMissizedMembersAreErrors) {
  const vk::BlockLayout params = reflected().find("params")->block;
  struct Naive {  // float weights[4] in C++ is 16 bytes; std140 makes it 64
    float scale, pad[3];
    glm::vec3 tint;
    float pad2;
    float weights[4];
  };
  std::string m = messageOf([&] {
    vk::checkBlockLayout(
        params,
        vk::cppBlock<Naive>("Naive", {GI_BLOCK_MEMBER(Naive, scale), GI_BLOCK_MEMBER(Naive, tint),
                                      GI_BLOCK_MEMBER(Naive, weights)}),
        "fx");
  });
  EXPECT_TRUE(contains(m, "'weights' is 64 bytes in the shader but 16 in C++")) << m;
  m = messageOf([&] {
    vk::checkBlockLayout(params, vk::cppBlock<Naive>("Naive", {GI_BLOCK_MEMBER(Naive, scale)}),
                         "fx");
  });
  EXPECT_TRUE(contains(m, "'tint'")) << m;
  EXPECT_TRUE(contains(m, "no C++ counterpart")) << m;
  vk::BlockLayout fewer = params;
  fewer.members.pop_back();
  m = messageOf([&] {
    vk::checkBlockLayout(
        fewer,
        vk::cppBlock<Naive>("Naive", {GI_BLOCK_MEMBER(Naive, scale), GI_BLOCK_MEMBER(Naive, tint),
                                      GI_BLOCK_MEMBER(Naive, weights)}),
        "fx");
  });
  EXPECT_TRUE(contains(m, "C++ member 'weights' is not in the shader")) << m;
  struct Short {
    float strength;
  };
  m = messageOf([&] {
    vk::checkBlockLayout(vk::BlockLayout{"Push", 28, {{"strength", 0, 4}}},
                         vk::cppBlock<Short>("Short", {GI_BLOCK_MEMBER(Short, strength)}), "fx");
  });
  EXPECT_TRUE(contains(m, "28 bytes, the C++ struct only 4")) << m;
}

TEST(ShaderInterface, UnreadableModulesAndOtherSetsAreClearErrors) {
  std::string m = messageOf([] {
    vk::reflectShader({0x07230203u, 1u, 2u}, VK_SHADER_STAGE_COMPUTE_BIT, "garbage.comp");
  });
  EXPECT_TRUE(contains(m, "garbage.comp")) << m;
  const char* set1 =
      "#version 460\nlayout(local_size_x = 1) in;\n"
      "layout(set = 1, binding = 0) uniform sampler2D t;\n"
      "layout(set = 0, binding = 0, r32f) uniform writeonly image2D o;\n"
      "void main() { imageStore(o, ivec2(0), texelFetch(t, ivec2(0), 0)); }\n";
  m = messageOf([&] {
    vk::reflectShader(vk::compileGlsl(set1, VK_SHADER_STAGE_COMPUTE_BIT, "set1.comp"),
                      VK_SHADER_STAGE_COMPUTE_BIT, "set1.comp");
  });
  EXPECT_TRUE(contains(m, "'t' is in descriptor set 1")) << m;
}

TEST(ShaderInterface, SpecializationConstantsByNameAndId) {
  const std::string src = R"(#version 450
layout(local_size_x = 1) in;
layout(constant_id = 3) const int kThird = 0;
layout(constant_id = 0) const int kFirst = 1;
layout(constant_id = 7) const bool kSeventh = false;
layout(set = 0, binding = 0) buffer Out { int v[]; } outBuf;
void main() { outBuf.v[0] = kThird + kFirst + (kSeventh ? 1 : 0); })";
  const auto constants = vk::reflectSpecializationConstants(
      vk::compileGlsl(src, VK_SHADER_STAGE_COMPUTE_BIT, "spec.comp"), "spec.comp");
  ASSERT_EQ(constants.size(), 3u);
  EXPECT_EQ(constants[0].name, "kFirst");
  EXPECT_EQ(constants[0].id, 0u);
  EXPECT_EQ(constants[1].name, "kThird");
  EXPECT_EQ(constants[1].id, 3u);
  EXPECT_EQ(constants[2].name, "kSeventh");
  EXPECT_EQ(constants[2].id, 7u);
  // The engine's lighting shader declares what its optional-input table names (the lighting
  // pass refuses a shader without them; every frame of the other tests goes through it).
  std::vector<std::string> names;
  for (const auto& c :
       vk::reflectSpecializationConstants(vk::loadSpirv("lighting.comp"), "lighting.comp"))
    names.push_back(c.name);
  for (const char* n :
       {"kAoInput", "kAmbientInput", "kIndirectInput", "kContactInput", "kDirectInput",
        "kLightTypes", "kShadowTypes", "kPcfRadius", "kEnvironmentKind"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

TEST(ShaderInterface, GraphicsStagesMergeAndMustAgree) {
  const char* vs =
      "#version 460\nlayout(set = 0, binding = 0) uniform Cam { mat4 m; } cam;\n"
      "void main() { gl_Position = cam.m * vec4(0); }\n";
  const char* fs =
      "#version 460\nlayout(set = 0, binding = 0) uniform Cam { mat4 m; } cam;\n"
      "layout(set = 0, binding = 1) uniform sampler2D t;\nlayout(location = 0) out vec4 c;\n"
      "void main() { c = texture(t, vec2(0)) + cam.m[0]; }\n";
  const char* fsBad =
      "#version 460\nlayout(set = 0, binding = 0) uniform sampler2D t;\n"
      "layout(location = 0) out vec4 c;\nvoid main() { c = texture(t, vec2(0)); }\n";
  auto reflect = [](const char* src, VkShaderStageFlagBits stage, const char* name) {
    return vk::reflectShader(vk::compileGlsl(src, stage, name), stage, name);
  };
  const vk::ShaderInterface v = reflect(vs, VK_SHADER_STAGE_VERTEX_BIT, "t.vert");
  const vk::ShaderInterface merged =
      vk::mergeInterfaces(v, reflect(fs, VK_SHADER_STAGE_FRAGMENT_BIT, "t.frag"));
  ASSERT_EQ(merged.bindings.size(), 2u);
  EXPECT_EQ(merged.bindings[0].stages,
            VkShaderStageFlags(VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT));
  const std::string m = messageOf(
      [&] { vk::mergeInterfaces(v, reflect(fsBad, VK_SHADER_STAGE_FRAGMENT_BIT, "bad.frag")); });
  EXPECT_TRUE(contains(m, "binding 0")) << m;
}

// An include may declare a block the including shader never reads, at a number the shader uses
// for something else (ism_common.glsl's IsmParams and a debug view's image): only the used
// resource is bound there.
TEST(ShaderInterface, AnUnusedDeclarationMayShareTheNumberOfAUsedOne) {
  const char* src =
      "#version 460\nlayout(local_size_x = 1) in;\n"
      "layout(set = 0, binding = 1) uniform Unused { float x; } unused;\n"
      "layout(set = 0, binding = 1, r32f) uniform writeonly image2D view;\n"
      "layout(set = 0, binding = 2) uniform Lonely { float y; } lonely;\n"
      "void main() { imageStore(view, ivec2(0), vec4(1)); }\n";
  const vk::ShaderInterface s =
      vk::reflectShader(vk::compileGlsl(src, VK_SHADER_STAGE_COMPUTE_BIT, "alias.comp"),
                        VK_SHADER_STAGE_COMPUTE_BIT, "alias.comp");
  ASSERT_EQ(s.bindings.size(), 3u);
  EXPECT_TRUE(s.bound(*s.find("view")));
  EXPECT_FALSE(s.find("unused")->active);
  EXPECT_FALSE(s.bound(*s.find("unused")));
  EXPECT_TRUE(s.bound(*s.find("lonely"))) << "unused but alone at its number: still bound";
  const char* clash =
      "#version 460\nlayout(local_size_x = 1) in;\n"
      "layout(set = 0, binding = 1) uniform U { float x; } u;\n"
      "layout(set = 0, binding = 1, r32f) uniform writeonly image2D view;\n"
      "void main() { imageStore(view, ivec2(0), vec4(u.x)); }\n";
  const std::string m = messageOf([&] {
    vk::reflectShader(vk::compileGlsl(clash, VK_SHADER_STAGE_COMPUTE_BIT, "clash.comp"),
                      VK_SHADER_STAGE_COMPUTE_BIT, "clash.comp");
  });
  EXPECT_TRUE(contains(m, "share binding 1")) << m;
}

class ShaderInterfaceGpu : public VulkanTest {
 protected:
  vk::ComputeDesc probe() const {
    return {"probe_effect: probe.comp",
            vk::compileGlsl(kShader, VK_SHADER_STAGE_COMPUTE_BIT, "probe.comp")};
  }
};

TEST_F(ShaderInterfaceGpu, APipelineWithAMismatchedPushStructIsNotMade) {
  vk::ComputeDesc d = probe();
  d.blocks.pushConstants = vk::cppBlock<PackedPush>(
      "PackedPush", {GI_BLOCK_MEMBER(PackedPush, strength), GI_BLOCK_MEMBER(PackedPush, tint)});
  std::string m = messageOf([&] { vk::Pipeline::compute(ctx(), d); });
  EXPECT_TRUE(contains(m, "probe_effect")) << m;
  EXPECT_TRUE(contains(m, "'tint'")) << m;
  d.blocks.pushConstants.reset();
  m = messageOf([&] { vk::Pipeline::compute(ctx(), d); });
  EXPECT_TRUE(contains(m, "declare the C++ struct")) << m;
}

// A pipeline made from reflection, bound by names and pushed a checked struct, computes what
// the shader says: values[i] = strength x i + tint.z.
TEST_F(ShaderInterfaceGpu, BindsByNameAndPushesTheCheckedStruct) {
  vk::ComputeDesc d = probe();
  d.blocks.pushConstants = vk::cppBlock<PaddedPush>(
      "PaddedPush", {GI_BLOCK_MEMBER(PaddedPush, strength), GI_BLOCK_MEMBER(PaddedPush, tint)});
  const vk::Pipeline p = vk::Pipeline::compute(ctx(), d);

  vk::Buffer frame(ctx(), 16, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
  vk::Buffer params(ctx(), 96, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
  vk::Buffer results(ctx(), 8 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  vk::ImageDesc color;
  color.format = VK_FORMAT_R8G8B8A8_UNORM;
  vk::ImageDesc layers = color;
  layers.format = VK_FORMAT_R32_UINT;
  vk::ImageDesc out = color;
  out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  out.usage = VK_IMAGE_USAGE_STORAGE_BIT;
  vk::Image colorImage(ctx(), color), layerImage(ctx(), layers), outImage(ctx(), out);
  const vk::Sampler nearest(ctx(), VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
  const VkSampler sampler = nearest.handle();

  vk::DescriptorArena arena(ctx());
  auto fill = [&](vk::DescriptorWriter& w) -> vk::DescriptorWriter& {
    w.buffer("Frame", frame.handle())
        .buffer("params", params.handle())
        .texture("colorTex", colorImage.view(), sampler, VK_IMAGE_LAYOUT_GENERAL);
    for (uint32_t i = 0; i < 3; ++i)
      w.texture("layers", layerImage.view(), sampler, VK_IMAGE_LAYOUT_GENERAL, i);
    return w.image("outImage", outImage.view()).buffer("results", results.handle());
  };
  const PaddedPush push{0.5f, {0, 0, 0}, glm::vec3(0.0f, 0.0f, 2.0f)};
  ctx().submitAndWait([&](VkCommandBuffer cmd) {
    const VkImage images[] = {colorImage.handle(), layerImage.handle(), outImage.handle()};
    for (VkImage image : images)
      vk::imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                       VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT);
    vk::DescriptorWriter w(p);
    arena.bind(cmd, p, fill(w));
    p.push(cmd, push);
    vkCmdDispatch(cmd, 2, 1, 1);
  });
  const float* values = static_cast<const float*>(results.mapped());
  for (int i = 0; i < 8; ++i) EXPECT_FLOAT_EQ(values[i], 0.5f * float(i) + 2.0f) << i;

  // Names the shader does not have, the wrong kind of binding, a binding left out, a push of
  // another struct: each a clear error.
  vk::DescriptorWriter w(p);
  std::string m = messageOf([&] { w.texture("colourTex", colorImage.view(), sampler); });
  EXPECT_TRUE(contains(m, "no binding named 'colourTex'")) << m;
  EXPECT_TRUE(contains(m, "colorTex (sampled texture, binding 2)")) << m;
  m = messageOf([&] { w.texture("results", colorImage.view(), sampler); });
  EXPECT_TRUE(contains(m, "'results' is a storage buffer")) << m;
  m = messageOf([&] { w.image("params", outImage.view()); });
  EXPECT_TRUE(contains(m, "'params' is a uniform buffer")) << m;
  m = messageOf([&] {
    vk::DescriptorWriter partial(p);
    partial.buffer("Frame", frame.handle());
    arena.bind(VK_NULL_HANDLE, p, partial);
  });
  EXPECT_TRUE(contains(m, "'params' (uniform buffer, binding 1) was not given")) << m;
  m = messageOf([&] { p.push(VK_NULL_HANDLE, PackedPush{}); });
  EXPECT_TRUE(contains(m, "pushed 16 bytes of push constants, but the declared C++ struct is 28"))
      << m;
}

TEST_F(ShaderInterfaceGpu, ExplicitBindingsMustCoverTheShader) {
  const std::vector<uint32_t> spirv = probe().spirv;
  const std::string m = messageOf([&] {
    vk::Pipeline::compute(ctx(), spirv,
                          {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                           {1, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                           {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE}},
                          28);
  });
  EXPECT_TRUE(contains(m, "binding 2 ('colorTex') is a sampled texture")) << m;
  // A shader without push constants takes none.
  const char* plain =
      "#version 460\nlayout(local_size_x = 1) in;\n"
      "layout(set = 0, binding = 0, r32f) uniform writeonly image2D o;\n"
      "void main() { imageStore(o, ivec2(0), vec4(1)); }\n";
  const vk::Pipeline p = vk::Pipeline::compute(
      ctx(), {"plain", vk::compileGlsl(plain, VK_SHADER_STAGE_COMPUTE_BIT, "plain.comp")});
  const std::string none = messageOf([&] { p.push(VK_NULL_HANDLE, 1.0f); });
  EXPECT_TRUE(contains(none, "plain: the shader has no push constants")) << none;
}

}  // namespace
}  // namespace gi
