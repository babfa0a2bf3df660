#include "test_support.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace gi::test {

std::string modelAsset(const std::string& relative) {
  return (std::filesystem::path(GI_SOURCE_DIR) / "assets" / "models" / relative).string();
}

std::string assimpModel(const std::string& relative) {
  return (std::filesystem::path(GI_ASSIMP_MODELS) / relative).string();
}

std::string binPath(const std::string& name) {
  return (std::filesystem::path(GI_BIN_DIR) / name).string();
}

TempDir::TempDir(const std::string& prefix) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = info ? info->name() : "no_test";
  dir_ = (std::filesystem::temp_directory_path() /
          ("gi_" + prefix + "_" + std::to_string(::getpid()) + "_" + test))
             .string();
  std::filesystem::remove_all(dir_);
  std::filesystem::create_directories(dir_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

std::string TempDir::write(const std::string& name, const std::string& text) const {
  const std::filesystem::path p = std::filesystem::path(dir_) / name;
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

std::string TempDir::path(const std::string& name) const {
  return (std::filesystem::path(dir_) / name).string();
}

void expectError(const std::function<void()>& f, ErrorKind kind,
                 const std::vector<std::string>& fragments) {
  try {
    f();
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    for (const std::string& frag : fragments)
      EXPECT_NE(std::string(e.what()).find(frag), std::string::npos)
          << "'" << frag << "' missing from: " << e.what();
  }
}

double upperHemisphereIrradianceOverPi(const Environment& env, bool luminance) {
  const int nu = 1024, nv = 512;  // v over the whole sphere; the upper half's rows summed
  double sum = 0.0;
  for (int j = 0; j < nv / 2; ++j)
    for (int i = 0; i < nu; ++i) {
      const double theta = (j + 0.5) * M_PI / nv, phi = (i + 0.5) * 2.0 * M_PI / nu;
      const glm::vec3 d(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                        float(std::sin(theta) * std::sin(phi)));
      const glm::vec3 l = environmentLookup(env, d);
      const double value = luminance ? 0.2126 * l.x + 0.7152 * l.y + 0.0722 * l.z : l.x;
      sum += value * std::cos(theta) * std::sin(theta) * (M_PI / nv) * (2.0 * M_PI / nu);
    }
  return sum / M_PI;
}

}  // namespace gi::test
