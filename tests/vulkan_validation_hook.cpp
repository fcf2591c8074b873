// vulkan_validation_hook.cpp — linked into every test program that may run
// the Vulkan backend. CTest runs the tests with SINEW_VULKAN_VALIDATION=1, so
// every Vulkan device runs under VK_LAYER_KHRONOS_validation; at the end of
// the program this fails the run if the layer reported any warning or error
// (each message also goes to the log callback, sinew/log.h, where it happened).
#include <gtest/gtest.h>

#include "backends/vulkan/vulkan_device.h"

namespace {

class VulkanValidationIsClean : public ::testing::Environment {
 public:
  void TearDown() override {
    EXPECT_EQ(sinew::vulkan_validation_messages(), 0u)
        << "the Vulkan validation layer reported problems (logged above as 'sinew: warning: Vulkan validation: ...' by the default log callback)";
  }
};

[[maybe_unused]] ::testing::Environment* const registered =
    ::testing::AddGlobalTestEnvironment(new VulkanValidationIsClean);

}  // namespace
