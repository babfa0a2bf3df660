// The engine's layers, checked on the sources: the Vulkan layer (engine/src/vk,
// engine/include/gi/vk) includes only itself and gi/errors.h, so it names no renderer, effect,
// scene or frame graph; the scene (engine/src/scene, engine/src/image) and configuration
// (engine/src/config) layers reach no Vulkan header through any chain of includes; apps share
// code only through apps/common and apps/scoring.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
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

// Every header reachable from the sources below `dirs` through quoted includes (resolved in
// engine/include, then beside the including file), with the chain that reaches each system
// header whose name starts with "vulkan/" in `vulkanChains`.
void includeClosure(const std::vector<fs::path>& dirs, std::set<std::string>& reached,
                    std::vector<std::string>& vulkanChains) {
  const fs::path include = fs::path(GI_SOURCE_DIR) / "engine/include";
  const std::regex quoted(R"re(^\s*#\s*include\s*"([^"]+)")re");
  const std::regex system(R"re(^\s*#\s*include\s*<(vulkan/[^>]+)>)re");
  std::vector<std::pair<fs::path, std::string>> todo;  // file, chain that reached it
  for (const fs::path& dir : dirs)
    for (const auto& entry : fs::recursive_directory_iterator(dir))
      if (entry.is_regular_file()) todo.emplace_back(entry.path(), entry.path().string());
  while (!todo.empty()) {
    auto [file, chain] = todo.back();
    todo.pop_back();
    if (!reached.insert(fs::weakly_canonical(file).string()).second) continue;
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line)) {
      std::smatch m;
      if (std::regex_search(line, m, system))
        vulkanChains.push_back(chain + " -> <" + m[1].str() + ">");
      if (!std::regex_search(line, m, quoted)) continue;
      for (const fs::path& candidate : {include / m[1].str(), file.parent_path() / m[1].str()})
        if (fs::is_regular_file(candidate)) {
          todo.emplace_back(candidate, chain + " -> " + m[1].str());
          break;
        }
    }
  }
}

TEST(Layering, TheSceneAndConfigurationLayersReachNoVulkanHeader) {
  const fs::path root = GI_SOURCE_DIR;
  std::set<std::string> reached;
  std::vector<std::string> vulkan;
  includeClosure({root / "engine/src/scene", root / "engine/src/image", root / "engine/src/config"},
                 reached, vulkan);
  for (const std::string& chain : vulkan) ADD_FAILURE() << chain << ": this layer has no Vulkan";
  // What the configuration layer declares is reached (the walk follows includes).
  for (const char* header : {"gi/effect_info.h", "gi/render_settings.h", "gi/effect_registry.h",
                             "gi/effect_config.h", "gi/settings.h", "gi/image_io.h"})
    EXPECT_TRUE(reached.count((root / "engine/include" / header).string())) << header;
  // The walk sees a Vulkan include where there is one.
  reached.clear();
  vulkan.clear();
  includeClosure({root / "engine/src/render"}, reached, vulkan);
  EXPECT_FALSE(vulkan.empty());
}

// An app reaches another app's code only through a library (apps/common, apps/scoring): no
// quoted include of an app names a header that lives only in another app's folder.
TEST(Layering, AppsIncludeNoOtherAppsHeaders) {
  const fs::path apps = fs::path(GI_SOURCE_DIR) / "apps";
  const std::set<std::string> shared = {"common", "scoring"};
  size_t checked = 0;
  for (const auto& app : fs::directory_iterator(apps)) {
    if (!app.is_directory() || shared.count(app.path().filename().string())) continue;
    for (const auto& [where, header] : quotedIncludes(app.path())) {
      if (fs::exists(app.path() / header) || header.rfind("gi/", 0) == 0) continue;
      ++checked;
      bool inShared = false;
      for (const std::string& lib : shared) inShared |= fs::exists(apps / lib / header);
      EXPECT_TRUE(inShared) << where << " includes \"" << header
                            << "\", which is neither its own nor a shared library's";
    }
  }
  EXPECT_GT(checked, 5u) << "no includes of the shared libraries found: the layout changed";
}

}  // namespace
}  // namespace gi
