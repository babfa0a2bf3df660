#include "shader_watcher.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "gi/vk/pipeline.h"

namespace demo {

namespace fs = std::filesystem;

namespace {

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "\x01missing";  // a deleted file is a change too
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void addGlslFiles(const fs::path& dir, std::set<std::string>& files) {
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) return;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && e.path().extension() == ".glsl") files.insert(e.path().string());
}

}  // namespace

ShaderWatcher::ShaderWatcher(std::string overrideDir)
    : overrideDir_(std::move(overrideDir)), sources_(gi::vk::registeredShaderSources()) {
  std::set<std::string> files;
  for (const gi::vk::ShaderSource& s : sources_) {
    files.insert(fileOf(s));
    addGlslFiles(fs::path(s.path).parent_path(), files);
    addGlslFiles(s.includeDir, files);
  }
  addGlslFiles(overrideDir_, files);
  files_.assign(files.begin(), files.end());
  baseline_ = texts_ = readAll();
}

std::string ShaderWatcher::fileOf(const gi::vk::ShaderSource& s) const {
  if (overrideDir_.empty()) return s.path;
  const fs::path local = fs::path(overrideDir_) / fs::path(s.path).filename();
  std::error_code ec;
  return fs::is_regular_file(local, ec) ? local.string() : s.path;
}

std::map<std::string, std::string> ShaderWatcher::readAll() const {
  std::map<std::string, std::string> texts;
  for (const std::string& f : files_) texts[f] = readText(f);
  return texts;
}

ShaderWatcher::Result ShaderWatcher::poll() {
  std::map<std::string, std::string> now = readAll();
  if (now == texts_) return {};
  // A changed shader file rebuilds that shader; a changed include may be in any of them.
  std::set<std::string> shaderFiles, changed;
  for (const gi::vk::ShaderSource& s : sources_) shaderFiles.insert(fileOf(s));
  for (const auto& [file, text] : now)
    if (texts_[file] != text) changed.insert(file);
  texts_ = std::move(now);
  const bool includeChanged = std::any_of(changed.begin(), changed.end(),
                                          [&](const auto& f) { return !shaderFiles.count(f); });

  Result result;
  if (texts_ == baseline_) {
    // Everything is as built: the built-in SPIR-V again, bit for bit.
    gi::vk::clearShaderOverrides();
    for (const gi::vk::ShaderSource& s : sources_)
      if (includeChanged || changed.count(fileOf(s))) result.rebuilt.push_back(fileOf(s));
    return result;
  }
  // Compile everything affected first: one error leaves every override as it was.
  std::vector<std::pair<std::string, std::vector<uint32_t>>> compiled;
  for (const gi::vk::ShaderSource& s : sources_) {
    const std::string file = fileOf(s);
    if (!includeChanged && !changed.count(file)) continue;
    try {
      compiled.emplace_back(
          s.path,
          gi::vk::compileGlslFile(file, {fs::path(s.path).parent_path().string(), s.includeDir}));
    } catch (const std::exception& e) {
      result.error = e.what();
      return result;
    }
    result.rebuilt.push_back(file);
  }
  for (auto& [path, words] : compiled) gi::vk::setShaderOverride(path, std::move(words));
  return result;
}

}  // namespace demo
