// A compute pipeline's description from a shader compiled with the module: gi_add_effect turns
// <file>.comp into "<file>.comp.h" holding `const uint32_t <file>_comp[]`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "gi/vk/pipeline.h"

namespace gi {

// `name` names the pipeline in errors ("effect: file.comp"); `specialization[i]` is the value of
// the shader's `layout(constant_id = i)`; `blocks` are checked against the shader's reflection.
template <size_t N>
vk::ComputeDesc computeShader(std::string name, const uint32_t (&spirv)[N],
                              std::vector<uint32_t> specialization = {},
                              vk::BlockChecks blocks = {}) {
  return {std::move(name), {spirv, spirv + N}, std::move(specialization), std::move(blocks)};
}

}  // namespace gi
