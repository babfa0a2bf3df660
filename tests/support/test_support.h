// Helpers shared by the tests: asset paths (skipping when optional assets are absent).
#pragma once

#include <string>

#include <gtest/gtest.h>

namespace gi::test {

// ../shared/assets/<relative>; empty string when the shared assets folder is absent.
std::string sharedAsset(const std::string& relative);
// /usr/share/assimp/models/<relative> (installed by the set-up as a dependency).
std::string assimpModel(const std::string& relative);
// Path to a built executable in build/bin.
std::string binPath(const std::string& name);

}  // namespace gi::test

// Skips the current test with a printed reason when ../shared/assets is missing.
#define GI_REQUIRE_SHARED_ASSET(var, rel)                            \
  const std::string var = ::gi::test::sharedAsset(rel);              \
  if (var.empty())                                                   \
    GTEST_SKIP() << "shared assets folder absent (" GI_SHARED_ASSETS \
                    "): skipping test that needs " rel;
