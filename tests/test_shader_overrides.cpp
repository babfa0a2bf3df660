// The engine's hot-reload table (gi/vk/shader_overrides.h): registered built-in SPIR-V is found
// by its content (effects copy it into a vector), an override replaces it only for its own
// source path, and a registration that goes away (a module unloaded) takes its entry with it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "gi/errors.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/shader_overrides.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

const uint32_t kBuiltIn[] = {0x07230203u, 1, 2, 3, 4};

bool registered(const std::string& path) {
  for (const vk::ShaderSource& s : vk::registeredShaderSources())
    if (s.path == path) return true;
  return false;
}

TEST(ShaderOverrides, OverrideReplacesTheRegisteredWordsOnlyWhileRegistered) {
  const std::vector<uint32_t> copy(std::begin(kBuiltIn), std::end(kBuiltIn));
  const std::vector<uint32_t> other = {0x07230203u, 9, 9};
  const std::vector<uint32_t> reloaded = {0x07230203u, 7, 7, 7};
  std::optional<vk::ShaderRegistration> reg;
  reg.emplace(kBuiltIn, std::size(kBuiltIn), "/fx/a.comp", "/fx/include");
  ASSERT_TRUE(registered("/fx/a.comp"));
  for (const vk::ShaderSource& s : vk::registeredShaderSources()) {
    if (s.path == "/fx/a.comp") {
      EXPECT_EQ(s.includeDir, "/fx/include");
    }
  }

  EXPECT_EQ(vk::resolveShader(copy), copy);
  vk::setShaderOverride("/fx/a.comp", reloaded);
  EXPECT_EQ(vk::resolveShader(copy), reloaded);
  EXPECT_EQ(vk::resolveShader(other), other) << "an unregistered shader is never replaced";
  vk::setShaderOverride("/fx/b.comp", other);
  EXPECT_EQ(vk::resolveShader(copy), reloaded) << "overrides go by source path";
  vk::clearShaderOverride("/fx/a.comp");
  EXPECT_EQ(vk::resolveShader(copy), copy);

  vk::setShaderOverride("/fx/a.comp", reloaded);
  reg.reset();  // the module is unloaded
  EXPECT_FALSE(registered("/fx/a.comp"));
  EXPECT_EQ(vk::resolveShader(copy), copy);
  vk::clearShaderOverrides();
}

// What the hot reload compiles with: local includes next to the edited file or in the source's
// folder, errors as gi::Error naming the file.
TEST(ShaderOverrides, CompileFileResolvesIncludesAndNamesTheFileOnError) {
  namespace fs = std::filesystem;
  const std::string dir = test::makeTempDir("shader_overrides");
  fs::create_directories(dir + "/src");
  std::ofstream(dir + "/src/value.glsl") << "const float kValue = 0.5;\n";
  const std::string head =
      "#version 460\n#extension GL_GOOGLE_include_directive : require\n#include \"value.glsl\"\n"
      "layout(local_size_x = 1) in;\nlayout(set = 0, binding = 0) buffer B { float v; } b;\n";
  std::ofstream(dir + "/good.comp") << head << "void main() { b.v = kValue; }\n";
  std::ofstream(dir + "/bad.comp") << head << "void main() { b.v = kValue }\n";
  const std::vector<uint32_t> words = vk::compileGlslFile(dir + "/good.comp", {dir + "/src"});
  ASSERT_GT(words.size(), 5u);
  EXPECT_EQ(words[0], 0x07230203u);
  try {
    vk::compileGlslFile(dir + "/bad.comp", {dir + "/src"});
    FAIL() << "a syntax error must throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/bad.comp"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ERROR"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gi
