// Sets the values of a SPIR-V module's integer specialization constants by rewriting their
// defaults (OpSpecConstant literals), which is what VkSpecializationInfo does at pipeline
// creation. gi::vk::Pipeline::compute takes no specialization info, and on llvmpipe settings
// must be constants for the compiler to drop unused code and unroll loops (notes/llvmpipe.md):
// a runtime `if` costs both sides.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "gi/errors.h"

namespace gi::obscurance {

// `values`: SpecId -> 32-bit integer value. Throws gi::Error if an id has no 32-bit OpSpecConstant.
inline std::vector<uint32_t> specialize(std::vector<uint32_t> spirv,
                                        const std::map<uint32_t, int32_t>& values) {
  constexpr uint32_t kOpDecorate = 71, kOpSpecConstant = 50, kDecorationSpecId = 1;
  constexpr size_t kHeaderWords = 5;
  std::map<uint32_t, uint32_t> idToSpec;  // result id -> SpecId
  for (size_t i = kHeaderWords; i < spirv.size();) {
    const uint32_t op = spirv[i] & 0xffffu, words = spirv[i] >> 16;
    if (words == 0 || i + words > spirv.size())
      throw Error(ErrorKind::InvalidData, "", "specialize: malformed SPIR-V");
    if (op == kOpDecorate && words == 4 && spirv[i + 2] == kDecorationSpecId)
      idToSpec[spirv[i + 1]] = spirv[i + 3];
    i += words;
  }
  std::map<uint32_t, bool> done;
  for (size_t i = kHeaderWords; i < spirv.size();) {
    const uint32_t op = spirv[i] & 0xffffu, words = spirv[i] >> 16;
    if (op == kOpSpecConstant && words == 4) {  // type, id, one 32-bit literal
      auto spec = idToSpec.find(spirv[i + 2]);
      if (spec != idToSpec.end()) {
        auto v = values.find(spec->second);
        if (v != values.end()) {
          spirv[i + 3] = uint32_t(v->second);
          done[spec->second] = true;
        }
      }
    }
    i += words;
  }
  for (const auto& [id, value] : values)
    if (!done.count(id))
      throw Error(ErrorKind::InvalidData, "",
                  "specialize: no 32-bit specialization constant " + std::to_string(id));
  return spirv;
}

}  // namespace gi::obscurance
