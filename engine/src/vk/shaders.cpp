#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>

#include "gi/errors.h"
#include "gi/vk/pipeline.h"

namespace gi::vk {

std::string shaderDirectory() {
  if (const char* env = std::getenv("GI_SHADER_DIR"); env && *env) return env;
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "shaders";
  return (exe.parent_path() / "shaders").string();
}

std::vector<uint32_t> loadSpirv(const std::string& name) {
  const std::string path = shaderDirectory() + "/" + name + ".spv";
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in)
    throw Error(ErrorKind::FileNotFound, path, "SPIR-V shader not found (is the build complete?)");
  const auto size = static_cast<size_t>(in.tellg());
  if (size == 0 || size % 4 != 0) throw Error(ErrorKind::InvalidData, path, "not a SPIR-V module");
  std::vector<uint32_t> code(size / 4);
  in.seekg(0);
  in.read(reinterpret_cast<char*>(code.data()), static_cast<std::streamsize>(size));
  if (code[0] != 0x07230203u) throw Error(ErrorKind::InvalidData, path, "bad SPIR-V magic number");
  return code;
}

namespace {

// Resolves #include "x" relative to the including file, then in the given folders.
class FileIncluder : public glslang::TShader::Includer {
 public:
  explicit FileIncluder(std::vector<std::string> dirs) : dirs_(std::move(dirs)) {}
  IncludeResult* includeLocal(const char* requested, const char* includer, size_t) override {
    std::vector<std::filesystem::path> candidates{std::filesystem::path(includer).parent_path() /
                                                  requested};
    for (const auto& d : dirs_) candidates.push_back(std::filesystem::path(d) / requested);
    for (const auto& c : candidates) {
      std::ifstream in(c);
      if (!in) continue;
      std::stringstream ss;
      ss << in.rdbuf();
      auto* text = new std::string(ss.str());
      return new IncludeResult(c.string(), text->data(), text->size(), text);
    }
    return nullptr;
  }
  IncludeResult* includeSystem(const char* requested, const char* includer, size_t depth) override {
    return includeLocal(requested, includer, depth);
  }
  void releaseInclude(IncludeResult* result) override {
    if (!result) return;
    delete static_cast<std::string*>(result->userData);
    delete result;
  }

 private:
  std::vector<std::string> dirs_;
};

EShLanguage languageOf(VkShaderStageFlagBits stage) {
  switch (stage) {
    case VK_SHADER_STAGE_VERTEX_BIT:
      return EShLangVertex;
    case VK_SHADER_STAGE_FRAGMENT_BIT:
      return EShLangFragment;
    case VK_SHADER_STAGE_GEOMETRY_BIT:
      return EShLangGeometry;
    default:
      return EShLangCompute;
  }
}

}  // namespace

std::vector<uint32_t> compileGlsl(const std::string& source, VkShaderStageFlagBits stage,
                                  const std::string& sourceName,
                                  const std::vector<std::string>& includeDirs) {
  static std::once_flag initOnce;
  std::call_once(initOnce, [] { glslang::InitializeProcess(); });
  const EShLanguage language = languageOf(stage);
  glslang::TShader shader(language);
  const char* text = source.c_str();
  const char* name = sourceName.c_str();
  shader.setStringsWithLengthsAndNames(&text, nullptr, &name, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, language, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_3);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_6);
  FileIncluder includer(includeDirs);
  const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  if (!shader.parse(GetDefaultResources(), 460, false, messages, includer))
    throw Error(ErrorKind::Parse, sourceName,
                std::string("GLSL compilation failed:\n") + shader.getInfoLog());
  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages))
    throw Error(ErrorKind::Parse, sourceName,
                std::string("GLSL link failed:\n") + program.getInfoLog());
  std::vector<uint32_t> spirv;
  glslang::SpvOptions options;
  options.disableOptimizer = false;
  glslang::GlslangToSpv(*program.getIntermediate(language), spirv, &options);
  return spirv;
}

std::vector<uint32_t> compileGlslFile(const std::string& path,
                                      const std::vector<std::string>& includeDirs) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorKind::FileNotFound, path, "shader source not found");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string ext = std::filesystem::path(path).extension().string();
  VkShaderStageFlagBits stage = ext == ".vert"   ? VK_SHADER_STAGE_VERTEX_BIT
                                : ext == ".frag" ? VK_SHADER_STAGE_FRAGMENT_BIT
                                : ext == ".geom" ? VK_SHADER_STAGE_GEOMETRY_BIT
                                : ext == ".comp" ? VK_SHADER_STAGE_COMPUTE_BIT
                                                 : VK_SHADER_STAGE_ALL;
  if (stage == VK_SHADER_STAGE_ALL)
    throw Error(ErrorKind::Unsupported, path, "unknown shader stage extension '" + ext + "'");
  return compileGlsl(ss.str(), stage, path, includeDirs);
}

}  // namespace gi::vk
