// The OpenCL backend's own duties: the embedded program builds on every
// device found, a broken kernel comes back as an error carrying the build
// log (no crash), device selection errors are clear, and "auto" picks a GPU
// or falls back to the CPU backend. Skipped where no OpenCL platform exists.
#include <gtest/gtest.h>

#include "backends/opencl/opencl_device.h"
#include "test_support.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

class OpenclBackend : public ::testing::Test {
 protected:
  void SetUp() override {
    auto devices = list_opencl_devices();
    if (!devices) GTEST_SKIP() << devices.error().message();
    devices_ = *devices;
  }
  std::vector<OpenclDeviceInfo> devices_;
};

TEST_F(OpenclBackend, EmbeddedKernelsBuildOnEveryDevice) {
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    auto device = create_device({.backend = "opencl", .device = std::to_string(i), .quiet = true});
    ASSERT_TRUE(device.ok()) << devices_[i].name << ": " << device.error().message();
    EXPECT_NE((*device)->device_name().find(devices_[i].name), std::string::npos);
    // Every kernel of the table is in the program: create_program finds and
    // accepts each one.
    auto buffer = (*device)->create_buffer(64, "x");
    ASSERT_TRUE(buffer.ok());
    for (std::size_t k = 0; k < kernel_count; ++k) {
      const auto kernel = static_cast<Kernel>(k);
      const FrameProgram p = test::single_dispatch_program(kernel, *buffer);
      const auto made = (*device)->create_program(p);
      EXPECT_TRUE(made.ok()) << devices_[i].name << ", " << kernel_name(kernel) << ": " << made.error().message();
    }
  }
}

TEST_F(OpenclBackend, BrokenKernelReportsTheBuildLog) {
  const Status s = try_build_opencl_source("kernel void broken(global float* x) { x[0] = undeclared_name; }", {});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("build failed"), std::string::npos) << s.error().message();
  EXPECT_NE(s.error().message().find("undeclared_name"), std::string::npos) << "the log names the problem:\n"
                                                                             << s.error().message();
  EXPECT_TRUE(try_build_opencl_source("kernel void fine(global float* x) { x[0] = 1.0f; }", {}).ok());
}

TEST_F(OpenclBackend, DeviceSelection) {
  auto by_name = create_device({.backend = "opencl", .device = devices_[0].name, .quiet = true});
  EXPECT_TRUE(by_name.ok());
  auto missing = create_device({.backend = "opencl", .device = "no such device 42", .quiet = true});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message().find("no such device 42"), std::string::npos);
  auto out_of_range = create_device({.backend = "opencl", .device = "999", .quiet = true});
  EXPECT_FALSE(out_of_range.ok());
}

TEST_F(OpenclBackend, AutoPrefersAGpuElseTheCpuBackend) {
  bool gpu = false;
  for (const auto& d : devices_) gpu = gpu || d.gpu;
  auto device = create_device({.backend = "auto", .quiet = true});
  ASSERT_TRUE(device.ok());
  EXPECT_EQ((*device)->backend_name(), gpu ? "opencl" : "cpu");
}

}  // namespace
}  // namespace sinew
