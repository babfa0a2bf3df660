#include "test_support.h"

#include <filesystem>

namespace gi::test {

std::string sharedAsset(const std::string& relative) {
  std::filesystem::path root(GI_SHARED_ASSETS);
  if (!std::filesystem::is_directory(root)) return {};
  return (root / relative).string();
}

std::string assimpModel(const std::string& relative) {
  return (std::filesystem::path(GI_ASSIMP_MODELS) / relative).string();
}

std::string binPath(const std::string& name) {
  return (std::filesystem::path(GI_BIN_DIR) / name).string();
}

}  // namespace gi::test
