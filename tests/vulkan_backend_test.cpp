// The Vulkan backend's own duties: the embedded SPIR-V (of every
// kernels/gpu/NAME.gpu, compiled to OpenCL C and SPIR-V) makes a pipeline
// for every kernel on every device found, device selection errors are
// clear, staged copies (discrete GPUs) and mapped memory (lavapipe,
// integrated GPUs) agree, a recorded frame with barriers
// reproduces the CPU reference bitwise, a cube scene runs clean under the
// validation layer with GPU timestamps per kernel, the validation counter
// counts a deliberate mistake, and "auto" never picks a CPU device such as
// lavapipe. Skipped where no Vulkan device exists.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <optional>

#include "backends/vulkan/vulkan_device.h"
#include "runtime/simulation_internals.h"
#include "test_support.h"
#include "xpbd_params.h"

namespace sinew {
namespace {

// Sets an environment variable for the life of the object, then restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) setenv(name, value, 1);
    else unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_) setenv(name_, old_->c_str(), 1);
    else unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

bool validation_requested() {
  const char* v = std::getenv("SINEW_VULKAN_VALIDATION");
  return v && std::string(v) == "1";
}

class VulkanBackend : public ::testing::Test {
 protected:
  void SetUp() override {
    auto devices = list_vulkan_devices();
    if (!devices) GTEST_SKIP() << devices.error().message();
    devices_ = *devices;
  }
  std::vector<VulkanDeviceInfo> devices_;
};

std::unique_ptr<Device> make(const std::string& selector = "") {
  auto device = create_device({.backend = "vulkan", .device = selector, .quiet = true});
  EXPECT_TRUE(device.ok()) << device.error().message();
  return device.ok() ? std::move(*device) : nullptr;
}

// n particles: x = (i, 2i, 3i) / n with inverse mass 1 (every 5th pinned), v = 0.
std::vector<float> particles(std::uint32_t n) {
  std::vector<float> x;
  for (std::uint32_t i = 0; i < n; ++i) {
    const float s = float(i) / float(n);
    x.insert(x.end(), {s, 2 * s, 3 * s, i % 5 == 0 ? 0.0f : 1.0f});
  }
  return x;
}

// `frames` predicts, each after a barrier, then update_velocity; returns x and v.
std::vector<float> predict_chain(Device& device, std::uint32_t n, int frames) {
  const std::vector<float> x0 = particles(n);
  BufferHandle x = *device.create_buffer(x0.size() * 4, "x"), prev = *device.create_buffer(x0.size() * 4, "prev"),
               v = *device.create_buffer(x0.size() * 4, "v");
  EXPECT_TRUE(device.write_buffer(x, 0, x0.data(), x0.size() * 4).ok());
  FrameProgram program;
  const kernels::PredictParams predict{1.0f / 240.0f, 0.3f, -9.81f, 0.1f, n, 0, 0, 0};
  for (int f = 0; f < frames; ++f) {
    program.dispatch(Kernel::xpbd_predict, n, {x, prev, v}, predict);
    program.barrier();
  }
  program.dispatch(Kernel::xpbd_update_velocity, n, {x, prev, v}, kernels::UpdateVelocityParams{240.0f, n, 1.0f / 240.0f, 0});
  auto prepared = device.create_program(program);
  EXPECT_TRUE(prepared.ok()) << prepared.error().message();
  if (!prepared.ok()) return {};
  EXPECT_TRUE(device.run_program(*prepared).ok());
  EXPECT_TRUE(device.run_program(*prepared).ok());  // a replay continues where the first run ended
  std::vector<float> out(2 * x0.size());
  EXPECT_TRUE(device.read_buffer(x, 0, out.data(), x0.size() * 4).ok());
  EXPECT_TRUE(device.read_buffer(v, 0, out.data() + x0.size(), x0.size() * 4).ok());
  return out;
}

TEST_F(VulkanBackend, EmbeddedKernelsMakePipelinesOnEveryDevice) {
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    auto device = make(std::to_string(i));
    ASSERT_TRUE(device);
    EXPECT_NE(device->device_name().find(devices_[i].name), std::string::npos) << device->device_name();
    BufferHandle b[6];
    for (auto& h : b) h = *device->create_buffer(256, "b");
    FrameProgram p;
    p.dispatch(Kernel::xpbd_predict, 4, {b[0], b[1], b[2]}, kernels::PredictParams{});
    p.barrier();
    p.dispatch(Kernel::xpbd_solve_distance, 0, {b[0], b[1], b[2], b[3], b[4], b[5]}, kernels::SolveParams{});
    p.dispatch(Kernel::xpbd_solve_volume, 0, {b[0], b[1], b[2], b[3], b[4], b[5]}, kernels::SolveParams{});
    p.barrier();
    p.dispatch(Kernel::xpbd_update_velocity, 4, {b[0], b[1], b[2]}, kernels::UpdateVelocityParams{});
    auto prepared = device->create_program(p);
    ASSERT_TRUE(prepared.ok()) << devices_[i].name << ": " << prepared.error().message();
    EXPECT_TRUE(device->run_program(*prepared).ok());
    // Every kernel of the table has SPIR-V and makes a pipeline (made, not run).
    for (std::size_t k = 0; k < kernel_count; ++k) {
      const auto kernel = static_cast<Kernel>(k);
      const FrameProgram q = test::single_dispatch_program(kernel, b[0]);
      auto made = device->create_program(q);
      EXPECT_TRUE(made.ok()) << devices_[i].name << ", " << kernel_name(kernel) << ": " << made.error().message();
    }
  }
}

TEST_F(VulkanBackend, DeviceSelection) {
  EXPECT_TRUE(make(devices_[0].name));
  EXPECT_TRUE(make("0"));
  auto missing = create_device({.backend = "vulkan", .device = "no such device 42", .quiet = true});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message().find("no such device 42"), std::string::npos) << missing.error().message();
  EXPECT_NE(missing.error().message().find(devices_[0].name), std::string::npos) << "lists the devices";
  EXPECT_FALSE(create_device({.backend = "vulkan", .device = "999", .quiet = true}).ok());
  {
    ScopedEnv env("SINEW_VULKAN_DEVICE", "no such device 7");
    auto from_env = create_device({.backend = "vulkan", .quiet = true});
    ASSERT_FALSE(from_env.ok());
    EXPECT_NE(from_env.error().message().find("no such device 7"), std::string::npos);
    EXPECT_TRUE(make("0")) << "options.device wins over the environment";
  }
}

TEST_F(VulkanBackend, MisuseComesBackAsErrors) {
  auto device = make();
  ASSERT_TRUE(device);
  EXPECT_FALSE(device->create_buffer(0, "empty").ok());
  BufferHandle b = *device->create_buffer(100, "hundred");
  float data[32] = {};
  const Status past_end = device->write_buffer(b, 96, data, 8);
  ASSERT_FALSE(past_end.ok());
  EXPECT_NE(past_end.error().message().find("hundred"), std::string::npos);
  EXPECT_FALSE(device->read_buffer(BufferHandle{77}, 0, data, 4).ok());
  EXPECT_FALSE(device->run_program(ProgramHandle{5}).ok());
  FrameProgram wrong;
  wrong.dispatch(Kernel::xpbd_predict, 1, {b, b}, kernels::PredictParams{});
  EXPECT_FALSE(device->create_program(wrong).ok());
}

TEST_F(VulkanBackend, RecordedFrameWithBarriersMatchesTheCpuBitwise) {
  auto cpu = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(cpu.ok());
  auto device = make();
  ASSERT_TRUE(device);
  const std::uint32_t n = 1000;  // not a multiple of 64: the last group is partly idle
  const std::vector<float> want = predict_chain(**cpu, n, 50);
  const std::vector<float> got = predict_chain(*device, n, 50);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) ASSERT_EQ(got[i], want[i]) << "word " << i;
}

TEST_F(VulkanBackend, StagedCopiesAgreeWithMappedMemory) {
  std::unique_ptr<Device> staged;
  {
    ScopedEnv env("SINEW_VULKAN_STAGING", "1");
    staged = make();
  }
  ASSERT_TRUE(staged);
  EXPECT_NE(staged->device_name().find("staged copies"), std::string::npos) << staged->device_name();
  // Partial writes and reads at offsets, and a buffer bigger than the first staging buffer.
  const std::size_t big = 3u << 20;
  std::vector<std::uint8_t> bytes(big);
  for (std::size_t i = 0; i < big; ++i) bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
  BufferHandle b = *staged->create_buffer(big, "big");
  std::vector<std::uint8_t> zeros(64, 1);
  ASSERT_TRUE(staged->read_buffer(b, big - 64, zeros.data(), 64).ok());
  EXPECT_EQ(zeros, std::vector<std::uint8_t>(64, 0)) << "new buffers are zero-filled";
  ASSERT_TRUE(staged->write_buffer(b, 0, bytes.data(), big).ok());
  ASSERT_TRUE(staged->write_buffer(b, 12, bytes.data() + 100, 20).ok());
  std::vector<std::uint8_t> back(big);
  ASSERT_TRUE(staged->read_buffer(b, 0, back.data(), big).ok());
  std::copy(bytes.begin() + 100, bytes.begin() + 120, bytes.begin() + 12);
  EXPECT_EQ(back, bytes);
  auto mapped = make();
  ASSERT_TRUE(mapped);
  EXPECT_EQ(predict_chain(*staged, 300, 7), predict_chain(*mapped, 300, 7));
}

TEST_F(VulkanBackend, CubeSceneRunsCleanUnderValidationWithKernelTimes) {
  const std::uint64_t before = vulkan_validation_messages();
  TetBodyDesc body;
  body.mesh = test::box_mesh(4, 4, 4, 0.25);
  ASSERT_TRUE(body.set_elastic(1e5, 0.4).ok());
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] > 1.0 - 1e-9) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 2, .iterations = 3};
  scene.tet_bodies.push_back(body);
  ScopedEnv stamps("SINEW_VULKAN_TIMESTAMPS", "1");  // off by default on CPU devices such as lavapipe
  auto sim = Simulation::create(scene, {.backend = "vulkan", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  for (int f = 0; f < 5; ++f) ASSERT_TRUE(sim->step().ok());
  std::vector<float> x;
  ASSERT_TRUE(sim->read_positions(x).ok());
  for (float c : x) ASSERT_TRUE(std::isfinite(c));
  EXPECT_EQ(vulkan_validation_messages(), before) << "the validation layer reported problems (printed above)";
  if (validation_requested()) {
    EXPECT_NE(sim->device_name().find("validation on"), std::string::npos);
  }

  // The frame's statistics carry the device times of the frame just run.
  const DeviceTimes& times = sim->last_frame().device;
  if (!times.timed) GTEST_SKIP() << "this queue writes no timestamps";
  std::size_t dispatches = 0;
  double summed = 0.0;
  for (std::size_t k = 0; k < kernel_count; ++k) {
    const auto kernel = static_cast<Kernel>(k);
    EXPECT_GE(times.kernel_ms[k], 0.0) << kernel_name(kernel);
    EXPECT_EQ(times.dispatches[k], SimulationInternals::program(*sim).dispatch_count(kernel)) << kernel_name(kernel);
    dispatches += times.dispatches[k];
    summed += times.kernel_ms[k];
  }
  EXPECT_EQ(dispatches, SimulationInternals::program(*sim).dispatch_count());
  EXPECT_GT(times.span_ms, 0.0);
  EXPECT_GT(summed, 0.0);
  // The device's own record of the last run is the same.
  DeviceTimes again;
  SINEW_ASSERT_OK(SimulationInternals::device(*sim).last_run_times(again));
  EXPECT_EQ(again.span_ms, times.span_ms);
}

TEST_F(VulkanBackend, ValidationLayerCountsADeliberateMistake) {
  if (!validation_requested()) GTEST_SKIP() << "SINEW_VULKAN_VALIDATION=1 is not set (CTest sets it)";
  const std::uint64_t before = vulkan_validation_messages();
  auto seen = vulkan_validation_self_test({});
  if (!seen.ok() && seen.error().message().find("not installed") != std::string::npos)
    GTEST_SKIP() << seen.error().message();
  ASSERT_TRUE(seen.ok()) << seen.error().message();
  EXPECT_GE(*seen, 1u) << "the layer reported nothing for a buffer without usage flags";
  EXPECT_EQ(vulkan_validation_messages(), before) << "deliberate messages are not counted as problems";
}

TEST_F(VulkanBackend, AutoNeverPicksACpuDevice) {
  auto device = create_device({.backend = "auto", .quiet = true});
  ASSERT_TRUE(device.ok()) << device.error().message();
  if ((*device)->backend_name() != "vulkan") return;  // OpenCL GPU or the CPU backend
  const std::string name = (*device)->device_name();
  EXPECT_EQ(name.find("llvmpipe"), std::string::npos) << name;
  EXPECT_EQ(name.find("(CPU,"), std::string::npos) << name;
  bool gpu = false;
  for (const auto& d : devices_) gpu = gpu || (d.gpu && name.find(d.name) != std::string::npos);
  EXPECT_TRUE(gpu) << name;
}

TEST_F(VulkanBackend, AutoFallsBackToCpuWithoutAGpu) {
  for (const auto& d : devices_)
    if (d.gpu) GTEST_SKIP() << "this machine has a Vulkan GPU: " << d.name;
  auto device = create_device({.backend = "auto", .quiet = true});
  ASSERT_TRUE(device.ok());
  EXPECT_NE((*device)->backend_name(), "vulkan");
}

}  // namespace
}  // namespace sinew
