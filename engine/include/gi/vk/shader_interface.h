// What a SPIR-V module declares (its descriptor bindings, push constants and uniform-block
// layouts), read from the module itself, so binding numbers and block layouts are written once,
// in GLSL. Pipelines are made from it and passes bind resources by the names the shader uses;
// a C++ struct meant to mirror a block is checked member by member against it (CppBlock).
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace gi::vk {

struct BlockMember {
  std::string name;
  uint32_t offset = 0;
  uint32_t size = 0;  // declared size (arrays: stride x count; a runtime array: 0)
};

// A uniform, storage or push-constant block as the shader lays it out (std140 / std430).
struct BlockLayout {
  std::string name;  // the block's type name (e.g. "SsaoParams")
  uint32_t size = 0;
  std::vector<BlockMember> members;
};

struct ShaderBinding {
  std::string name;  // the name the shader uses: a block's instance name, else its type name
  uint32_t binding = 0;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_MAX_ENUM;
  uint32_t count = 1;             // array elements
  VkShaderStageFlags stages = 0;  // stages that declare it
  bool active = true;             // the entry point uses it (statically)
  BlockLayout block;              // uniform and storage buffers
  bool matches(std::string_view n) const { return n == name || (!n.empty() && n == block.name); }
};

struct ShaderInterface {
  std::string shader;                   // where it came from, for messages
  std::vector<ShaderBinding> bindings;  // set 0, sorted by binding
  BlockLayout pushConstants;            // size 0: none

  // The binding named `name` (instance or block type name); nullptr when there is none.
  const ShaderBinding* find(std::string_view name) const;
  // Whether `b` is in the pipeline's layout: every binding except an unused one sharing its
  // number with a used one.
  bool bound(const ShaderBinding& b) const;
  // "frame (uniform buffer, 0), gDepth (sampled texture, 2), ..." for messages.
  std::string describe() const;
};

// A specialization constant as the shader declares it: `layout(constant_id = id) const ... name`.
struct SpecializationConstant {
  std::string name;
  uint32_t id = 0;
};
// The specialization constants `spirv` declares, by constant_id. Throws gi::Error naming
// `shaderName` on a module it cannot parse.
std::vector<SpecializationConstant> reflectSpecializationConstants(
    const std::vector<uint32_t>& spirv, const std::string& shaderName);

// Reads set 0's bindings, the push-constant block and every block's layout from `spirv`.
// `shaderName` names the module in errors. Throws gi::Error on a module it cannot parse or on
// resources outside set 0 (the engine's pipelines have one set).
ShaderInterface reflectShader(const std::vector<uint32_t>& spirv, VkShaderStageFlagBits stage,
                              const std::string& shaderName);
// The union of two stages' interfaces (a graphics pipeline's vertex and fragment shaders); a
// binding both declare must agree in type and count.
ShaderInterface mergeInterfaces(const ShaderInterface& a, const ShaderInterface& b);

const char* descriptorTypeName(VkDescriptorType type);

// A C++ struct that mirrors a shader block: its size and each member's name, offset and size
// (GI_BLOCK_MEMBER). Checked when a pipeline is made (checkBlockLayout).
struct CppBlock {
  std::string type;  // C++ type name, for messages
  size_t size = 0;
  std::vector<BlockMember> members;
};

template <class T>
CppBlock cppBlock(std::string type, std::vector<BlockMember> members) {
  return {std::move(type), sizeof(T), std::move(members)};
}

// One member of a CppBlock: GI_BLOCK_MEMBER(Params, tint) -> {"tint", offsetof, sizeof}.
#define GI_BLOCK_MEMBER(T, m)                            \
  ::gi::vk::BlockMember {                                \
#m, uint32_t(offsetof(T, m)), uint32_t(sizeof(T::m)) \
  }

// The whole CppBlock of a struct from its members' names, in any order, at most 16:
// GI_CPP_BLOCK(Params, strength, tint) ->
//   cppBlock<Params>("Params", {GI_BLOCK_MEMBER(Params, strength), GI_BLOCK_MEMBER(Params, tint)})
#define GI_CPP_BLOCK(T, ...) \
  ::gi::vk::cppBlock<T>(     \
      #T, {GI_DETAIL_CAT(GI_DETAIL_MEMBERS_, GI_DETAIL_COUNT(__VA_ARGS__))(T, __VA_ARGS__)})
#define GI_DETAIL_CAT(a, b) GI_DETAIL_CAT_(a, b)
#define GI_DETAIL_CAT_(a, b) a##b
#define GI_DETAIL_COUNT(...) \
  GI_DETAIL_COUNT_(__VA_ARGS__, 16, 15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1)
#define GI_DETAIL_COUNT_(_1, _2, _3, _4, _5, _6, _7, _8, _9, _10, _11, _12, _13, _14, _15, _16, n, \
                         ...)                                                                      \
  n
#define GI_DETAIL_MEMBERS_1(T, m) GI_BLOCK_MEMBER(T, m)
#define GI_DETAIL_MEMBERS_2(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_1(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_3(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_2(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_4(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_3(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_5(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_4(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_6(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_5(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_7(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_6(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_8(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_7(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_9(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_8(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_10(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_9(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_11(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_10(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_12(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_11(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_13(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_12(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_14(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_13(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_15(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_14(T, __VA_ARGS__)
#define GI_DETAIL_MEMBERS_16(T, m, ...) GI_BLOCK_MEMBER(T, m), GI_DETAIL_MEMBERS_15(T, __VA_ARGS__)

// Throws gi::Error naming `owner`, the block and the first member that differs when `cpp` does
// not match `shader`: every member of each must be in the other by name, at the same offset and
// of the same size, and the C++ struct must hold the whole block (trailing padding allowed).
void checkBlockLayout(const BlockLayout& shader, const CppBlock& cpp, const std::string& owner);

}  // namespace gi::vk
