// Specialization constants without VkSpecializationInfo: gi::vk::Pipeline::compute takes SPIR-V
// only, so the default value of each OpSpecConstant is rewritten in the code instead. Drivers
// treat unspecialized constants as constants with their default value, so the result is the
// same (on llvmpipe: branches folded and loops unrolled before code generation, see
// notes/llvmpipe.md). Only 32-bit integer constants (GLSL `layout(constant_id = N) const int`).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "gi/errors.h"

namespace gi::alchemy {

inline std::vector<uint32_t> specialize(std::span<const uint32_t> code,
                                        const std::vector<std::pair<uint32_t, int32_t>>& values,
                                        const std::string& who) {
  constexpr uint32_t kOpDecorate = 71, kDecorationSpecId = 1, kOpSpecConstant = 50;
  std::vector<uint32_t> out(code.begin(), code.end());
  if (out.size() < 5 || out[0] != 0x07230203u)
    throw Error(ErrorKind::InvalidData, who, "not a SPIR-V module");
  std::unordered_map<uint32_t, uint32_t> specIdOf;  // result id -> SpecId
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 5; i < out.size();) {
      const uint32_t words = out[i] >> 16, op = out[i] & 0xffffu;
      if (words == 0 || i + words > out.size())
        throw Error(ErrorKind::InvalidData, who, "malformed SPIR-V instruction");
      if (pass == 0 && op == kOpDecorate && words == 4 && out[i + 2] == kDecorationSpecId)
        specIdOf[out[i + 1]] = out[i + 3];
      if (pass == 1 && op == kOpSpecConstant && words == 4) {
        const auto id = specIdOf.find(out[i + 2]);
        if (id != specIdOf.end())
          for (const auto& [specId, value] : values)
            if (specId == id->second) out[i + 3] = uint32_t(value);
      }
      i += words;
    }
  }
  for (const auto& [specId, value] : values) {
    bool found = false;
    for (const auto& [id, s] : specIdOf) found = found || s == specId;
    if (!found)
      throw Error(ErrorKind::InvalidData, who,
                  "no specialization constant with constant_id " + std::to_string(specId));
  }
  return out;
}

}  // namespace gi::alchemy
