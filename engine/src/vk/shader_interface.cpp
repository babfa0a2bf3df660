#include "gi/vk/shader_interface.h"

#include <spirv_cross/spirv_cross_c.h>

#include <algorithm>
#include <memory>
#include <sstream>

#include "gi/errors.h"

namespace gi::vk {

namespace {

// SPIRV-Cross's C API: one context per reflection; its error callback keeps the last message.
class Reflector {
 public:
  Reflector(const std::vector<uint32_t>& spirv, std::string shader) : shader_(std::move(shader)) {
    if (spvc_context_create(&context_) != SPVC_SUCCESS)
      throw Error(ErrorKind::ShaderInterface, "",
                  "shader " + shader_ + ": cannot create a SPIRV-Cross context");
    spvc_context_set_error_callback(
        context_, [](void* self, const char* msg) { static_cast<Reflector*>(self)->error_ = msg; },
        this);
    spvc_parsed_ir ir = nullptr;
    check(spvc_context_parse_spirv(context_, spirv.data(), spirv.size(), &ir), "parse");
    check(spvc_context_create_compiler(context_, SPVC_BACKEND_NONE, ir,
                                       SPVC_CAPTURE_MODE_TAKE_OWNERSHIP, &compiler_),
          "compiler");
    check(spvc_compiler_create_shader_resources(compiler_, &resources_), "resources");
    spvc_set active = nullptr;
    check(spvc_compiler_get_active_interface_variables(compiler_, &active), "active variables");
    check(spvc_compiler_create_shader_resources_for_active_variables(compiler_, &active_, active),
          "active resources");
  }
  ~Reflector() { spvc_context_destroy(context_); }
  Reflector(const Reflector&) = delete;
  Reflector& operator=(const Reflector&) = delete;

  // Every declared resource of `type`, or only those the entry point uses.
  std::vector<spvc_reflected_resource> list(spvc_resource_type type, bool activeOnly = false) {
    const spvc_reflected_resource* items = nullptr;
    size_t count = 0;
    check(spvc_resources_get_resource_list_for_type(activeOnly ? active_ : resources_, type, &items,
                                                    &count),
          "list");
    return {items, items + count};
  }

  BlockLayout block(spvc_type_id typeId, const char* fallbackName) {
    spvc_type type = spvc_compiler_get_type_handle(compiler_, typeId);
    BlockLayout b;
    b.name = nameOf(typeId, fallbackName);
    size_t size = 0;
    check(spvc_compiler_get_declared_struct_size(compiler_, type, &size), "struct size");
    b.size = uint32_t(size);
    for (unsigned i = 0; i < spvc_type_get_num_member_types(type); ++i) {
      unsigned offset = 0;
      size_t memberSize = 0;
      check(spvc_compiler_type_struct_member_offset(compiler_, type, i, &offset), "offset");
      check(spvc_compiler_get_declared_struct_member_size(compiler_, type, i, &memberSize),
            "member size");
      const char* name = spvc_compiler_get_member_name(compiler_, typeId, i);
      std::string memberName = name && *name ? name : std::to_string(i);  // unnamed: its index
      b.members.push_back({std::move(memberName), offset, uint32_t(memberSize)});
    }
    return b;
  }

  std::string nameOf(SpvId id, const char* fallback = nullptr) const {
    const char* n = spvc_compiler_get_name(compiler_, id);
    if (n && *n) return n;
    return fallback ? fallback : "";
  }
  unsigned decoration(SpvId id, SpvDecoration d) const {
    return spvc_compiler_get_decoration(compiler_, id, d);
  }
  spvc_type type(spvc_type_id id) const { return spvc_compiler_get_type_handle(compiler_, id); }
  std::vector<SpecializationConstant> specializationConstants() {
    const spvc_specialization_constant* list = nullptr;
    size_t count = 0;
    check(spvc_compiler_get_specialization_constants(compiler_, &list, &count),
          "specialization constants");
    std::vector<SpecializationConstant> out;
    for (size_t i = 0; i < count; ++i) out.push_back({nameOf(list[i].id), list[i].constant_id});
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    return out;
  }

 private:
  void check(spvc_result r, const char* what) {
    if (r != SPVC_SUCCESS)
      throw Error(ErrorKind::ShaderInterface, "",
                  "shader " + shader_ + ": cannot reflect its SPIR-V (" + what +
                      (error_.empty() ? "" : ": " + error_) + ")");
  }
  std::string shader_;
  std::string error_;
  spvc_context context_ = nullptr;
  spvc_compiler compiler_ = nullptr;
  spvc_resources resources_ = nullptr;
  spvc_resources active_ = nullptr;
};

uint32_t arrayCount(spvc_type type) {
  uint32_t count = 1;
  for (unsigned d = 0; d < spvc_type_get_num_array_dimensions(type); ++d)
    if (spvc_type_array_dimension_is_literal(type, d))
      count *= std::max<uint32_t>(1, spvc_type_get_array_dimension(type, d));
  return count;
}

}  // namespace

const char* descriptorTypeName(VkDescriptorType type) {
  switch (type) {
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER:
      return "uniform buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER:
      return "storage buffer";
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER:
      return "sampled texture";
    case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE:
      return "texture without sampler";
    case VK_DESCRIPTOR_TYPE_SAMPLER:
      return "sampler";
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE:
      return "storage image";
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER:
      return "uniform texel buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER:
      return "storage texel buffer";
    case VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT:
      return "input attachment";
    default:
      return "unknown descriptor";
  }
}

std::vector<SpecializationConstant> reflectSpecializationConstants(
    const std::vector<uint32_t>& spirv, const std::string& shaderName) {
  return Reflector(spirv, shaderName).specializationConstants();
}

ShaderInterface reflectShader(const std::vector<uint32_t>& spirv, VkShaderStageFlagBits stage,
                              const std::string& shaderName) {
  Reflector r(spirv, shaderName);
  ShaderInterface out;
  out.shader = shaderName;

  struct Kind {
    spvc_resource_type spvc;
    VkDescriptorType vk;
    bool block;
  };
  const Kind kinds[] = {
      {SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, true},
      {SPVC_RESOURCE_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, true},
      {SPVC_RESOURCE_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, false},
      {SPVC_RESOURCE_TYPE_SEPARATE_IMAGE, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, false},
      {SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS, VK_DESCRIPTOR_TYPE_SAMPLER, false},
      {SPVC_RESOURCE_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, false},
      {SPVC_RESOURCE_TYPE_SUBPASS_INPUT, VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT, false},
  };
  for (const Kind& k : kinds) {
    const auto used = r.list(k.spvc, true);
    for (const spvc_reflected_resource& res : r.list(k.spvc)) {
      const unsigned set = r.decoration(res.id, SpvDecorationDescriptorSet);
      ShaderBinding b;
      b.active = std::any_of(used.begin(), used.end(),
                             [&](const spvc_reflected_resource& u) { return u.id == res.id; });
      b.binding = r.decoration(res.id, SpvDecorationBinding);
      b.type = k.vk;
      b.stages = VkShaderStageFlags(stage);
      b.count = arrayCount(r.type(res.type_id));
      if (k.block) {
        b.block = r.block(res.base_type_id, res.name);
        b.name = r.nameOf(res.id);  // instance name; empty for an anonymous block
        if (b.name.empty()) b.name = b.block.name;
      } else {
        b.name = r.nameOf(res.id, res.name);
        // Texel buffers are images of dimension Buffer.
        if (spvc_type_get_image_dimension(r.type(res.base_type_id)) == SpvDimBuffer) {
          if (b.type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE)
            b.type = VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
          else if (b.type == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE)
            b.type = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        }
      }
      if (set != 0)
        throw Error(ErrorKind::ShaderInterface, "",
                    "shader " + shaderName + ": '" + b.name + "' is in descriptor set " +
                        std::to_string(set) + "; the engine's pipelines have only set 0");
      out.bindings.push_back(std::move(b));
    }
  }
  // Declared but unused resources may share a number with a used one (an include's block in a
  // shader that does not read it): only used ones are bound, and two of those must not clash.
  std::stable_sort(out.bindings.begin(), out.bindings.end(),
                   [](const ShaderBinding& a, const ShaderBinding& b) {
                     return a.binding != b.binding ? a.binding < b.binding : a.active > b.active;
                   });
  for (size_t i = 1; i < out.bindings.size(); ++i)
    if (out.bindings[i].binding == out.bindings[i - 1].binding && out.bindings[i].active)
      throw Error(ErrorKind::ShaderInterface, "",
                  "shader " + shaderName + ": '" + out.bindings[i - 1].name + "' and '" +
                      out.bindings[i].name + "' share binding " +
                      std::to_string(out.bindings[i].binding));

  const auto push = r.list(SPVC_RESOURCE_TYPE_PUSH_CONSTANT);
  if (!push.empty()) {
    out.pushConstants = r.block(push.front().base_type_id, push.front().name);
  }
  return out;
}

ShaderInterface mergeInterfaces(const ShaderInterface& a, const ShaderInterface& b) {
  ShaderInterface out = a;
  out.shader = a.shader + " + " + b.shader;
  for (const ShaderBinding& nb : b.bindings) {
    auto same = std::find_if(out.bindings.begin(), out.bindings.end(),
                             [&](const ShaderBinding& x) { return x.binding == nb.binding; });
    if (same == out.bindings.end()) {
      out.bindings.push_back(nb);
      continue;
    }
    if (same->type != nb.type || same->count != nb.count)
      throw Error(ErrorKind::ShaderInterface, "",
                  "shaders " + out.shader + ": binding " + std::to_string(nb.binding) + " is a " +
                      descriptorTypeName(same->type) + " '" + same->name + "' in one and a " +
                      descriptorTypeName(nb.type) + " '" + nb.name + "' in the other");
    same->stages |= nb.stages;
    same->active |= nb.active;
  }
  std::sort(out.bindings.begin(), out.bindings.end(),
            [](const ShaderBinding& x, const ShaderBinding& y) { return x.binding < y.binding; });
  if (b.pushConstants.size > out.pushConstants.size) out.pushConstants = b.pushConstants;
  return out;
}

const ShaderBinding* ShaderInterface::find(std::string_view name) const {
  for (const ShaderBinding& b : bindings)
    if (b.name == name) return &b;
  for (const ShaderBinding& b : bindings)
    if (b.matches(name)) return &b;
  return nullptr;
}

bool ShaderInterface::bound(const ShaderBinding& b) const {
  if (b.active) return true;  // used: bound
  // Declared, unused, and alone at its number: bound too (harmless; keeps explicit layouts
  // valid). One that shares its number with a used resource is left out.
  return std::none_of(bindings.begin(), bindings.end(), [&](const ShaderBinding& o) {
    return &o != &b && o.binding == b.binding && o.active;
  });
}

std::string ShaderInterface::describe() const {
  std::ostringstream s;
  for (size_t i = 0; i < bindings.size(); ++i)
    s << (i ? ", " : "") << bindings[i].name << " (" << descriptorTypeName(bindings[i].type)
      << ", binding " << bindings[i].binding << ")";
  return bindings.empty() ? "no bindings" : s.str();
}

void checkBlockLayout(const BlockLayout& shader, const CppBlock& cpp, const std::string& owner) {
  const std::string where = owner + ": block '" + shader.name + "' (C++ " + cpp.type + ")";
  for (const BlockMember& s : shader.members) {
    auto c = std::find_if(cpp.members.begin(), cpp.members.end(),
                          [&](const BlockMember& m) { return m.name == s.name; });
    if (c == cpp.members.end())
      throw Error(ErrorKind::ShaderInterface, "",
                  where + ": member '" + s.name + "' (offset " + std::to_string(s.offset) +
                      ") has no C++ counterpart");
    if (c->offset != s.offset)
      throw Error(ErrorKind::ShaderInterface, "",
                  where + ": member '" + s.name + "' is at offset " + std::to_string(s.offset) +
                      " in the shader but " + std::to_string(c->offset) +
                      " in C++ (std140/std430 align vec3 and vec4 to 16 bytes)");
    if (s.size != 0 && c->size != s.size)
      throw Error(ErrorKind::ShaderInterface, "",
                  where + ": member '" + s.name + "' is " + std::to_string(s.size) +
                      " bytes in the shader but " + std::to_string(c->size) +
                      " in C++ (std140 arrays have a 16-byte stride)");
  }
  for (const BlockMember& c : cpp.members)
    if (std::none_of(shader.members.begin(), shader.members.end(),
                     [&](const BlockMember& m) { return m.name == c.name; }))
      throw Error(ErrorKind::ShaderInterface, "",
                  where + ": C++ member '" + c.name + "' is not in the shader's block");
  if (cpp.size < shader.size)
    throw Error(ErrorKind::ShaderInterface, "",
                where + ": the shader's block is " + std::to_string(shader.size) +
                    " bytes, the C++ struct only " + std::to_string(cpp.size));
}

}  // namespace gi::vk
