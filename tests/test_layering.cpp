// The engine's layers, checked on the sources: the Vulkan layer (engine/src/vk,
// engine/include/gi/vk) includes only itself and gi/errors.h, so it names no renderer, effect,
// scene or frame graph.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace gi {
namespace {

namespace fs = std::filesystem;

// Every `#include "x"` of the files below `dir` (recursively), as "file:line: x".
std::vector<std::pair<std::string, std::string>> quotedIncludes(const fs::path& dir) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::regex include(R"re(^\s*#\s*include\s*"([^"]+)")re");
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path());
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
      std::smatch m;
      if (std::regex_search(line, m, include))
        out.emplace_back(entry.path().string() + ":" + std::to_string(n), m[1]);
    }
  }
  return out;
}

TEST(Layering, TheVulkanLayerIncludesOnlyItself) {
  const fs::path root = GI_SOURCE_DIR;
  size_t checked = 0;
  for (const fs::path& dir : {root / "engine/src/vk", root / "engine/include/gi/vk"}) {
    ASSERT_TRUE(fs::is_directory(dir)) << dir;
    for (const auto& [where, header] : quotedIncludes(dir)) {
      ++checked;
      EXPECT_TRUE(header.rfind("gi/vk/", 0) == 0 || header == "gi/errors.h")
          << where << " includes \"" << header
          << "\": the Vulkan layer depends on nothing above it";
    }
  }
  EXPECT_GT(checked, 10u) << "no includes found: the layout changed";
}

}  // namespace
}  // namespace gi
