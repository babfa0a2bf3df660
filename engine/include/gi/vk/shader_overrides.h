// Hot reload of effects' GLSL: the SPIR-V an effect built in is registered with its source file
// (by the header gi_add_effect generates), and a tool (gi-demo) may compile that file again and
// set the result as an override. Pipeline::compute / graphics build from the override when the
// SPIR-V they are given is a registered shader that has one, so effects' code does not change.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace gi::vk {

struct ShaderSource {
  std::string path;        // the GLSL file the SPIR-V was built from (absolute)
  std::string includeDir;  // the engine's shader include folder it was built with
};

// One static object per generated header and translation unit: registers on load, unregisters
// on unload (a module closed by dlclose leaves no dangling pointer behind).
class ShaderRegistration {
 public:
  ShaderRegistration(const uint32_t* words, size_t count, const char* path, const char* includeDir);
  ~ShaderRegistration();
  ShaderRegistration(const ShaderRegistration&) = delete;
  ShaderRegistration& operator=(const ShaderRegistration&) = delete;
};

// The registered sources, one per path, sorted by path.
std::vector<ShaderSource> registeredShaderSources();
// Builds the shader registered for `path` from `spirv` from now on (pipelines made before keep
// theirs). Compile first (compileGlslFile): this takes valid SPIR-V only.
void setShaderOverride(const std::string& path, std::vector<uint32_t> spirv);
void clearShaderOverride(const std::string& path);
void clearShaderOverrides();
// The words a pipeline is built from: the override when `spirv` is a registered shader that has
// one, else `spirv` itself.
std::vector<uint32_t> resolveShader(const std::vector<uint32_t>& spirv);

}  // namespace gi::vk
