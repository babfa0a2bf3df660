// Bakes specialization-constant values into a SPIR-V module: the default value of every
// `layout(constant_id = N)` constant listed is replaced in the binary, so the driver folds the
// constant (and unrolls the loops it bounds) exactly as with VkSpecializationInfo, which
// gi::vk::Pipeline::compute does not take. Copied into each effect that uses it (effects do
// not depend on each other).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "gi/errors.h"

namespace gi::spirv {

// `values`: SpecId -> value (int bits, or 0 / 1 for bools). Throws gi::Error when a SpecId is
// not declared in the module or the module is malformed.
inline std::vector<uint32_t> specialize(std::vector<uint32_t> code,
                                        const std::map<uint32_t, uint32_t>& values,
                                        const std::string& what) {
  constexpr uint32_t kMagic = 0x07230203, kOpDecorate = 71, kDecorationSpecId = 1,
                     kOpSpecConstantTrue = 48, kOpSpecConstantFalse = 49, kOpSpecConstant = 50;
  auto fail = [&](const std::string& why) {
    return Error(ErrorKind::InvalidData, what, "cannot specialize the shader: " + why);
  };
  if (code.size() < 5 || code[0] != kMagic) throw fail("not a SPIR-V module");
  std::map<uint32_t, uint32_t> idOf;  // result id -> SpecId
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 5; i < code.size();) {
      const uint32_t words = code[i] >> 16, op = code[i] & 0xffffu;
      if (words == 0 || i + words > code.size()) throw fail("truncated instruction");
      if (pass == 0 && op == kOpDecorate && words == 4 && code[i + 2] == kDecorationSpecId)
        idOf[code[i + 1]] = code[i + 3];
      if (pass == 1 && (op == kOpSpecConstantTrue || op == kOpSpecConstantFalse) && words == 3) {
        auto it = idOf.find(code[i + 2]);
        if (it != idOf.end() && values.count(it->second))
          code[i] =
              (words << 16) | (values.at(it->second) ? kOpSpecConstantTrue : kOpSpecConstantFalse);
      }
      if (pass == 1 && op == kOpSpecConstant && words == 4) {  // 32-bit scalar
        auto it = idOf.find(code[i + 2]);
        if (it != idOf.end() && values.count(it->second)) code[i + 3] = values.at(it->second);
      }
      i += words;
    }
  }
  for (const auto& [specId, value] : values) {
    bool found = false;
    for (const auto& [id, s] : idOf) found |= s == specId;
    if (!found) throw fail("no constant_id " + std::to_string(specId));
  }
  return code;
}

}  // namespace gi::spirv
