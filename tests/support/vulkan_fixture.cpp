#include "vulkan_fixture.h"

#include <filesystem>

namespace gi::test {

std::unique_ptr<vk::Context> VulkanTest::context_;

void VulkanTest::SetUpTestSuite() {
  if (context_) return;
  vk::ContextOptions options = vk::ContextOptions::fromEnvironment();
  options.validation = true;
  // Keep test runs from touching the user's pipeline cache.
  options.pipelineCachePath =
      (std::filesystem::temp_directory_path() / "gi-test-pipeline-cache.bin").string();
  context_ = std::make_unique<vk::Context>(options);
}

void VulkanTest::TearDownTestSuite() {
  context_.reset();
}

void VulkanTest::SetUp() {
  errorsBefore_ = context_->validationErrors();
}

void VulkanTest::TearDown() {
  EXPECT_EQ(context_->validationErrors(), errorsBefore_)
      << "Vulkan validation errors during the test";
}

}  // namespace gi::test
