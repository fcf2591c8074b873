// fault_injection_test.cpp — a device that fails (tests/faulty_device.h):
// every failure of allocation, upload, read-back, program creation,
// submission or wait, at creation or in a frame, is an error that names it;
// none is swallowed; the Simulation steps on once the device works again
// (a buffer that failed to grow, or a program that failed to build, is tried
// again the next frame), with finite positions and no device object more
// than an undisturbed run.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "faulty_device.h"
#include "mesh_contact_support.h"
#include "runtime/simulation_internals.h"
#include "test_support.h"

namespace sinew {
namespace {

using test::FaultyDevice;

// Mesh collision reads positions back and uploads contacts every frame;
// with the solve and the statistics, every kind of call happens in a frame.
// With topology changes, a removal patches constraints and surfaces on the device.
SceneDesc scene() {
  SceneDesc s = test::dropped_blocks_scene(ContactSchedule::colored);
  s.topology_changes = true;
  return s;
}

struct Made {
  Result<Simulation> sim;
  FaultyDevice* device;
};

Made make(const std::string& backend, FaultyDevice::Call call = FaultyDevice::Call::submit, std::uint64_t nth = 0) {
  auto real = create_device({.backend = backend, .quiet = true});
  EXPECT_TRUE(real.ok()) << real.error().message();
  auto faulty = std::make_unique<FaultyDevice>(std::move(*real));
  FaultyDevice* device = faulty.get();
  if (nth > 0) device->arm(call, nth);
  Made made{SimulationInternals::create(scene(), std::move(faulty)), device};
  device->disarm();  // a fault that did not come while creating comes no more
  return made;
}

bool finite(const Simulation& sim) {
  std::vector<float> x;
  if (!sim.read_positions(x).ok()) return false;
  for (float v : x)
    if (!std::isfinite(v)) return false;
  return true;
}

bool names_the_fault(const Status& s) {
  return !s.ok() && s.error().message().find(FaultyDevice::tag()) != std::string::npos;
}

class FaultInjection : public test::BackendTest {};

TEST_P(FaultInjection, AFaultWhileCreatingIsANamedError) {
  for (FaultyDevice::Call call : FaultyDevice::kCalls)
    for (std::uint64_t nth : {1, 3, 10}) {
      Made made = make(GetParam(), call, nth);
      const std::string what = std::string(FaultyDevice::name(call)) + " #" + std::to_string(nth);
      // A fault that fired fails the creation with its name; one that never
      // came (fewer such calls) leaves a working Simulation.
      EXPECT_EQ(made.device->fired(), !made.sim.ok()) << what;
      if (!made.sim.ok()) {
        EXPECT_TRUE(names_the_fault(made.sim.error())) << what << ": " << made.sim.error().message();
      } else {
        EXPECT_TRUE(made.sim->step().ok()) << what;
      }
    }
}

TEST_P(FaultInjection, AFaultInAFrameIsReportedAndTheSimulationStepsOn) {
  constexpr int kFrames = 4;
  Made clean = make(GetParam());
  ASSERT_TRUE(clean.sim.ok()) << clean.sim.error().message();
  for (int f = 0; f < kFrames; ++f) SINEW_ASSERT_OK(clean.sim->step());
  const DeviceObjects reference = SimulationInternals::device(*clean.sim).objects();

  for (FaultyDevice::Call call : FaultyDevice::kCalls)
    for (std::uint64_t nth : {1, 2, 5}) {
      const std::string what = std::string(FaultyDevice::name(call)) + " #" + std::to_string(nth);
      Made made = make(GetParam());
      ASSERT_TRUE(made.sim.ok()) << made.sim.error().message();
      made.device->arm(call, nth);
      int done = 0, failed = 0;
      for (int f = 0; f < kFrames + 1 && done < kFrames; ++f) {
        const Status s = made.sim->step();
        if (s.ok()) {
          ++done;
          EXPECT_FALSE(made.device->fired() && failed == 0) << what << ": a fault was swallowed";
        } else {
          ++failed;
          EXPECT_TRUE(names_the_fault(s)) << what << ": " << s.error().message();
          EXPECT_TRUE(made.device->fired()) << what;
        }
      }
      EXPECT_LE(failed, 1) << what << ": one fault, one failed frame";
      EXPECT_EQ(done, kFrames) << what << ": the Simulation steps on after the fault";
      EXPECT_EQ(made.sim->last_frame().frame, std::uint64_t(kFrames)) << what << ": a failed frame is not counted";
      EXPECT_TRUE(finite(*made.sim)) << what;
      // Nothing leaked: as many buffers and programs as the undisturbed run
      // (their sizes may differ: the contacts that grew them were not the same).
      const DeviceObjects after = SimulationInternals::device(*made.sim).objects();
      EXPECT_EQ(after.buffers, reference.buffers) << what;
      EXPECT_EQ(after.programs, reference.programs) << what;
    }
}

// A removal under a device fault is a named error; the Simulation steps on
// and a later removal works.
TEST_P(FaultInjection, AFaultInARemovalIsReportedAndTheSimulationStepsOn) {
  std::set<std::string> fired;
  for (FaultyDevice::Call call : FaultyDevice::kCalls)
    for (std::uint64_t nth : {1, 3}) {
      const std::string what = std::string(FaultyDevice::name(call)) + " #" + std::to_string(nth);
      Made made = make(GetParam());
      ASSERT_TRUE(made.sim.ok()) << made.sim.error().message();
      SINEW_ASSERT_OK(made.sim->step());
      made.device->arm(call, nth);
      const std::vector<std::uint32_t> first{0, 1, 2};
      auto removed = made.sim->remove_tets(0, first);
      EXPECT_EQ(made.device->fired(), !removed.ok()) << what << ": a fault is never swallowed";
      if (!removed.ok()) {
        fired.insert(what);
        EXPECT_TRUE(names_the_fault(removed.error())) << what << ": " << removed.error().message();
      }
      made.device->disarm();
      for (int f = 0; f < 2; ++f) EXPECT_TRUE(made.sim->step().ok()) << what << " frame " << f;
      const std::vector<std::uint32_t> second{10, 11};
      EXPECT_TRUE(made.sim->remove_tets(0, second).ok()) << what;
      EXPECT_TRUE(made.sim->step().ok()) << what;
      EXPECT_TRUE(finite(*made.sim)) << what;
    }
  // A removal uploads the patched constraints and builds the program again.
  EXPECT_TRUE(fired.count("write_buffer #1")) << "an upload's fault came inside the removal";
  EXPECT_TRUE(fired.count("create_program #1")) << "a program build's fault came inside the removal";
}

INSTANTIATE_TEST_SUITE_P(Backends, FaultInjection, ::testing::ValuesIn(test::backends()), test::backend_name);

}  // namespace
}  // namespace sinew
