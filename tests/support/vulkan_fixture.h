// A Vulkan context with validation layers for tests; any validation error fails the test.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "gi/vk/context.h"

namespace gi::test {

class VulkanTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite();
  static void TearDownTestSuite();
  void SetUp() override;
  void TearDown() override;  // fails the test if validation reported errors during it
  static vk::Context& ctx() { return *context_; }

 private:
  static std::unique_ptr<vk::Context> context_;
  uint32_t errorsBefore_ = 0;
};

}  // namespace gi::test
