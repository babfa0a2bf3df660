// Helpers shared by the tests: asset paths, temporary folders, expected errors.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gi/environment.h"
#include "gi/errors.h"

namespace gi::test {

// assets/models/<relative> in the source tree (the models the repository ships).
std::string modelAsset(const std::string& relative);
// /usr/share/assimp/models/<relative> (installed by the set-up as a dependency).
std::string assimpModel(const std::string& relative);
// Path to a built executable in build/bin.
std::string binPath(const std::string& name);

// (1 / pi) int L cos over the upper hemisphere (+y) of environment `env` as
// gi::environmentLookup reads it, per channel (luminance weights 0.2126, 0.7152, 0.0722 when
// `luminance`): the exact environment term of an open floor per unit albedo, by the midpoint
// rule on a 1024 x 256 grid of (phi, theta).
double upperHemisphereIrradianceOverPi(const Environment& env, bool luminance = true);

// `f` must throw a gi::Error of `kind` whose message contains every fragment.
void expectError(const std::function<void()>& f, ErrorKind kind,
                 const std::vector<std::string>& fragments);

// A fresh folder per test (named after the test and the process) for files written on the
// fly; removed with everything in it when the object goes away.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  // Writes `text` to `name` (sub-folders created) and returns the file's path.
  std::string write(const std::string& name, const std::string& text) const;
  std::string path(const std::string& name) const;

 private:
  std::string dir_;
};

}  // namespace gi::test
