// The clone stands alone: every file a shipped scene, tool or test names lies inside the
// repository (or in a Debian package the set-up installs), and no script runs on with an unset
// variable. The scenes are loaded from a copy of assets/ in a fresh folder with nothing above
// it, so a model reached through "../../.." or an absolute path into the checkout fails here.
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gi/scene_io.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

const fs::path kSource = GI_SOURCE_DIR;
const fs::path kDebianModels = "/usr/share/assimp/models";  // assimp-testmodels (tools/deps.sh)

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool inside(const fs::path& file, const fs::path& root) {
  const fs::path f = fs::weakly_canonical(file), r = fs::weakly_canonical(root);
  auto [ri, fi] = std::mismatch(r.begin(), r.end(), f.begin(), f.end());
  return ri == r.end();
}

// The files `model` names in turn: a glTF's buffers and images (not data: URIs), an OBJ's
// material libraries. Each must stay inside `root`.
std::vector<fs::path> referencedFiles(const fs::path& model) {
  std::vector<fs::path> out;
  const fs::path dir = model.parent_path();
  const std::string ext = model.extension().string();
  if (ext == ".gltf") {
    const auto j = nlohmann::json::parse(readText(model));
    for (const char* list : {"buffers", "images"})
      for (const auto& e : j.value(list, nlohmann::json::array()))
        if (e.contains("uri") && e["uri"].get<std::string>().rfind("data:", 0) != 0)
          out.push_back(dir / e["uri"].get<std::string>());
  } else if (ext == ".obj") {
    std::istringstream in(readText(model));
    for (std::string line; std::getline(in, line);)
      if (line.rfind("mtllib ", 0) == 0) out.push_back(dir / line.substr(7));
  }
  return out;
}

// A scene's model and environment files as written in it.
std::vector<std::string> namedFiles(const fs::path& scene) {
  const auto j = nlohmann::json::parse(readText(scene), nullptr, true, /*ignore_comments=*/true);
  std::vector<std::string> files;
  for (const auto& m : j.value("models", nlohmann::json::array()))
    if (m.contains("file")) files.push_back(m["file"].get<std::string>());
  if (j.contains("environment") && j["environment"].contains("file"))
    files.push_back(j["environment"]["file"].get<std::string>());
  return files;
}

std::vector<fs::path> sceneFiles(const fs::path& folder) {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(folder))
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

}  // namespace

TEST(SelfContained, EveryShippedSceneLoadsFromACopyOfAssetsWithNothingAboveIt) {
  gi::test::TempDir tmp("self_contained");
  const fs::path copy = fs::path(tmp.path("assets"));
  fs::copy(kSource / "assets", copy, fs::copy_options::recursive);
  const auto scenes = sceneFiles(copy / "scenes");
  ASSERT_GE(scenes.size(), 9u) << "assets/scenes holds fewer scenes than the project ships";
  size_t modelsChecked = 0;
  for (const fs::path& scene : scenes) {
    SCOPED_TRACE(scene.filename().string());
    for (const std::string& named : namedFiles(scene)) {
      SCOPED_TRACE(named);
      if (named.rfind("${", 0) == 0) {
        // The only variable: Debian's assimp-testmodels, a package the set-up installs.
        EXPECT_EQ(named.rfind("${ASSIMP_MODELS}/", 0), 0u);
        continue;
      }
      EXPECT_FALSE(fs::path(named).is_absolute()) << "absolute path in a shipped scene";
      const fs::path resolved = scene.parent_path() / named;
      EXPECT_TRUE(inside(resolved, copy)) << "names a file outside assets/";
      EXPECT_TRUE(fs::is_regular_file(resolved)) << "names a missing file";
      for (const fs::path& ref : referencedFiles(resolved)) {
        EXPECT_TRUE(inside(ref, copy)) << ref << " outside assets/";
        EXPECT_TRUE(fs::is_regular_file(ref)) << ref << " missing";
      }
      ++modelsChecked;
    }
    // The loader itself: every file found from the copy alone.
    EXPECT_NO_THROW({
      const gi::Scene s = gi::loadScene(scene.string());
      EXPECT_GT(s.triangleCount(), 0u);
    });
  }
  EXPECT_GE(modelsChecked, 10u);
}

TEST(SelfContained, EveryShippedModelHasItsLicenceFile) {
  size_t models = 0;
  for (const auto& e : fs::directory_iterator(kSource / "assets" / "models")) {
    if (!e.is_directory()) continue;
    ++models;
    const fs::path licence = e.path() / "LICENSE.md";
    ASSERT_TRUE(fs::is_regular_file(licence)) << e.path() << " has no LICENSE.md";
    const std::string text = readText(licence);
    EXPECT_NE(text.find("Source"), std::string::npos) << licence << " names no source";
    EXPECT_NE(text.find("icen"), std::string::npos) << licence << " states no licence";
  }
  EXPECT_GE(models, 4u);
}

// Text of every tool, test, script and build file: no path into a folder beside the clone or
// into one machine's home, no variable that once pointed there.
TEST(SelfContained, NoToolTestOrBuildFileNamesAPathOutsideTheClone) {
  // Spelled in pieces so that this file does not match itself.
  const std::regex outside(std::string("\\.\\./") + "shared|GI_" + "SHARED_ASSETS|/" + "work/|/" +
                           "home/|/" + "root/");
  const std::set<std::string> textExt = {".sh",   ".py",   ".cpp",  ".h",    ".cmake",
                                         ".txt",  ".json", ".comp", ".vert", ".frag",
                                         ".glsl", ".in",   ""};
  size_t scanned = 0;
  for (const char* top :
       {"tools", "tests", "apps", "engine", "effects", "cmake", "assets", "docs", ".ci"}) {
    for (const auto& e : fs::recursive_directory_iterator(kSource / top)) {
      if (!e.is_regular_file() || !textExt.count(e.path().extension().string())) continue;
      if (e.path().string().find("/tests/fuzz/corpus/") != std::string::npos) continue;
      if (e.file_size() > 4u << 20) continue;  // data (models), not code
      const std::string text = readText(e.path());
      std::smatch m;
      EXPECT_FALSE(std::regex_search(text, m, outside))
          << e.path() << " names '" << m.str() << "': a path outside the clone";
      ++scanned;
    }
  }
  for (const char* file : {"CMakeLists.txt", "CMakePresets.json"}) {
    std::smatch m;
    const std::string text = readText(kSource / file);
    EXPECT_FALSE(std::regex_search(text, m, outside)) << file << " names '" << m.str() << "'";
  }
  EXPECT_GT(scanned, 200u);
}

// A bash script with `set -u` stops at an unset variable instead of expanding it to nothing
// (how "${VAR}/model" silently became "/model").
TEST(SelfContained, EveryBashScriptStopsOnAnUnsetVariable) {
  const std::regex setU("(^|\\n)set -[a-z]*u");
  size_t scripts = 0;
  for (const char* top : {"tools", "docs", ".ci", "tests"}) {
    for (const auto& e : fs::recursive_directory_iterator(kSource / top)) {
      if (!e.is_regular_file()) continue;
      const std::string text = readText(e.path());
      if (text.rfind("#!/usr/bin/env bash", 0) != 0 && text.rfind("#!/bin/bash", 0) != 0 &&
          text.rfind("#!/bin/sh", 0) != 0)
        continue;
      ++scripts;
      EXPECT_TRUE(std::regex_search(text, setU)) << e.path() << " runs on with unset variables";
    }
  }
  EXPECT_GE(scripts, 15u);
}
