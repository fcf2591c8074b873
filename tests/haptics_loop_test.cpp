// The haptic loop on a virtual clock: no allocation in a tick after warm-up
// (counted by a replaced operator new), the feedback impulse integral, the
// physics-side bridge (the tool gets minus the frame's mean device force),
// the thread machinery, telemetry and parameter errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <thread>

#include "support/allocation_counter.h"
#include "haptics_test_support.h"
#include "sinew/haptics/replay_device.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/simulation.h"

namespace {

using namespace sinew::test;
using sinew::support::allocation_count;

ScriptedPose wiggle(double t) {
  ScriptedPose p;
  p.position = {0.01 * std::sin(3 * t), -0.002 + 0.001 * std::cos(5 * t), 0.0};
  p.rotation = {std::cos(0.1 * t), 0.0, std::sin(0.1 * t), 0.0};
  return p;
}

TEST(HapticsLoop, TickAllocatesNothingAfterWarmUp) {
  ScriptedDevice scripted(wiggle);
  NullDevice null_device({.position = {0, -0.001, 0}});
  auto replay = ReplayDevice::create({{0.0, {0, 0, 0}, {1, 0, 0, 0}, 0}, {0.5, {0.01, 0, 0}, {1, 0, 0, 0}, 1},
                                      {1.0, {0.0, -0.01, 0}, {1, 0, 0, 0}, 0}},
                                     0, /*loop=*/true);
  ASSERT_TRUE(replay.ok());
  HapticDevice* devices[] = {&scripted, &null_device, &*replay};
  for (HapticDevice* device : devices) {
    HapticLoopSettings settings;
    settings.telemetry_capacity = 256;  // wraps many times below
    VirtualRig rig(*device, settings);
    rig.tool.velocity = {0.01, 0, 0};
    rig.run(100);  // warm-up
    const std::uint64_t before = allocation_count();
    for (int i = 0; i < 5000; ++i) {
      rig.tool.position[0] = 1e-6 * i;  // the stand-in physics moves the tool
      rig.step();                       // snapshot publication (every 16-17 ticks) + tick
    }
    const std::uint64_t after = allocation_count();
    EXPECT_EQ(after - before, 0u) << device->name() << ": allocations in 5000 ticks";
    EXPECT_EQ(rig.loop->counters().ticks, 5100u);
  }
}

TEST(HapticsLoop, AllocationCounterCounts) {
  // The counter is live in this executable (so the zero above means something).
  const std::uint64_t before = allocation_count();
  void* p = ::operator new(64);  // a direct call: never elided, unlike a new-expression
  ::operator delete(p);
  EXPECT_EQ(allocation_count() - before, 1u);
}

TEST(HapticsLoop, FeedbackIsTheZeroOrderHoldIntegralOfTheDeviceForce) {
  ScriptedDevice device(wiggle);
  VirtualRig rig(device);
  Vec3 integral{0, 0, 0}, prev{0, 0, 0};
  for (int i = 0; i < 700; ++i) {
    const TickRecord r = rig.step();
    if (i > 0)
      for (int k = 0; k < 3; ++k) integral[k] += prev[k] * 0.001;
    prev = r.force;
  }
  CouplingFeedback fb;
  ASSERT_TRUE(rig.feedback.try_read(fb));
  EXPECT_EQ(fb.ticks, 700u);
  EXPECT_EQ(fb.time_ns, 699 * kMs);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(fb.impulse[k], integral[k], 1e-15);
    EXPECT_EQ(fb.force[k], prev[k]);
  }
  EXPECT_GT(norm3(fb.force), 0.1) << "the coupling did push";
}

// A tool alone in space (no gravity: the hand carries it), coupled to a null
// device 1 cm to its side. Physics frames of 4 ms (250 Hz): every 4 ticks
// the bridge applies minus the mean device force, steps, publishes.
TEST(HapticsLoop, BridgeDrivesTheToolWithMinusTheMeanDeviceForce) {
  sinew::SceneDesc scene;
  scene.gravity = {0, 0, 0};
  scene.solver = {.time_step = 0.004, .substeps = 1, .iterations = 1};
  sinew::ToolDesc tool;
  tool.mass = 0.5;
  tool.gravity = false;
  scene.tools.push_back(tool);
  auto sim = sinew::Simulation::create(scene, {.backend = "cpu", .threads = 1, .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();

  NullDevice device({.position = {0.01, 0.0, 0.0}});
  HapticLoopSettings settings;
  settings.coupling.damping = 5.0;  // well damped so the tool settles within the test
  VirtualRig rig(device, settings);
  HapticToolBridge bridge(0, rig.snapshots, rig.feedback, rig.clock);
  ASSERT_TRUE(bridge.publish(*sim).ok());

  std::vector<TickRecord> ticks;
  double farthest = 0.0;
  std::int64_t prev_fb_time = -1;
  int checked = 0;
  for (int frame = 0; frame < 1500; ++frame) {  // 6 s
    for (int i = 0; i < 4; ++i) ticks.push_back(rig.loop->tick()), rig.clock.advance(kMs);
    ASSERT_TRUE(bridge.apply_feedback(*sim).ok());
    if (prev_fb_time >= 0) {
      // Mean of the device forces held over [previous reading, this reading).
      Vec3 mean{0, 0, 0};
      int n = 0;
      for (const TickRecord& r : ticks)
        if (r.start_ns >= prev_fb_time && r.start_ns < bridge.last_feedback().time_ns) {
          for (int k = 0; k < 3; ++k) mean[k] += r.force[k];
          ++n;
        }
      ASSERT_EQ(n, 4);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(bridge.last_tool_force()[k], -mean[k] / n, 1e-12);
      ++checked;
    }
    prev_fb_time = bridge.last_feedback().time_ns;
    ASSERT_TRUE(sim->step().ok());
    ASSERT_TRUE(bridge.publish(*sim).ok());
    auto s = sim->tool_state(0);
    farthest = std::max(farthest, s->position[0]);
    if (ticks.size() > 64) ticks.erase(ticks.begin(), ticks.begin() + 32);
  }
  EXPECT_GT(checked, 1000);
  auto s = sim->tool_state(0);
  EXPECT_NEAR(s->position[0], 0.01, 2e-4) << "the coupling pulled the tool to the device";
  EXPECT_NEAR(s->position[1], 0.0, 1e-6);
  EXPECT_LT(farthest, 0.02) << "no runaway";
  EXPECT_EQ(bridge.frames_without_feedback(), 0u);
  EXPECT_EQ(bridge.published(), 1501u);
}

TEST(HapticsLoop, BridgeStaysWithinTheClampWhenTheLoopIsRecreated) {
  // A static tool 4 mm above a null device: the coupling holds 2 N for 2 s,
  // so the feedback's impulse integral reaches about 3.5 N s. Then a new
  // HapticLoop on the same feedback channel starts its integral at 0: the
  // bridge must not difference the two loops' integrals (-875 N).
  sinew::SceneDesc scene;
  scene.gravity = {0, 0, 0};
  scene.tools.push_back({});
  auto sim = sinew::Simulation::create(scene, {.backend = "cpu", .threads = 1, .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  NullDevice device({.position = {0.0, -0.004, 0.0}});
  HapticLoopSettings settings;
  VirtualRig rig(device, settings);
  HapticToolBridge bridge(0, rig.snapshots, rig.feedback, rig.clock);
  const double clamp = settings.coupling.max_force;
  auto frames = [&](int n) {
    for (int frame = 0; frame < n; ++frame) {
      rig.run(4);  // 4 ticks, snapshots at 60 Hz: the tool stays put
      ASSERT_TRUE(bridge.apply_feedback(*sim).ok());
      ASSERT_LE(norm3(bridge.last_tool_force()), clamp + 1e-9) << "frame " << frame;
    }
  };
  frames(500);  // 2 s
  ASSERT_NEAR(bridge.last_tool_force()[1], -settings.coupling.stiffness * 0.004, 1e-9) << "2 N held";
  ASSERT_GT(bridge.last_feedback().impulse[1], 3.0);

  rig.loop.reset();
  HapticLoopSettings again = settings;
  again.realtime = false;
  auto made = HapticLoop::create(again, device, rig.snapshots, rig.feedback, rig.clock);
  ASSERT_TRUE(made.ok());
  rig.loop = std::move(*made);
  frames(500);  // the new loop ramps up to 2 N again
  EXPECT_NEAR(bridge.last_tool_force()[1], -settings.coupling.stiffness * 0.004, 1e-9);
  EXPECT_EQ(bridge.frames_without_feedback(), 0u);
}

TEST(HapticsLoop, BridgeAppliesNothingWithoutNewTicks) {
  sinew::SceneDesc scene;
  scene.tools.push_back({});
  auto sim = sinew::Simulation::create(scene, {.backend = "cpu", .threads = 1, .quiet = true});
  ASSERT_TRUE(sim.ok());
  VirtualClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  HapticToolBridge bridge(0, snapshots, feedback, clock);
  ASSERT_TRUE(bridge.apply_feedback(*sim).ok());
  EXPECT_EQ(bridge.frames_without_feedback(), 1u);
  EXPECT_EQ(bridge.last_tool_force(), (Vec3{0, 0, 0}));
  EXPECT_FALSE(bridge.set_damping(-1.0, 0.0).ok());
  EXPECT_FALSE(bridge.set_damping(0.0, std::nan("")).ok());
  EXPECT_TRUE(bridge.set_damping(2.0, 0.0).ok());
  HapticToolBridge wrong(3, snapshots, feedback, clock);
  EXPECT_FALSE(wrong.publish(*sim).ok()) << "a bad tool index is an error";
}

TEST(HapticsLoop, ThreadRunsOnAVirtualClockAndReportsItsScheduling) {
  NullDevice device;
  VirtualClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  HapticLoopSettings settings;
  settings.realtime = false;
  settings.zero_cpu_latency = false;  // a test leaves the machine's power management alone
  settings.telemetry_capacity = 100;
  bool started_on_loop_thread = false;
  std::thread::id loop_thread;
  settings.on_thread_start = [&] {
    started_on_loop_thread = true;
    loop_thread = std::this_thread::get_id();
  };
  auto loop = HapticLoop::create(settings, device, snapshots, feedback, clock);
  ASSERT_TRUE(loop.ok());
  ASSERT_TRUE((*loop)->start().ok());
  EXPECT_TRUE((*loop)->running());
  EXPECT_FALSE((*loop)->start().ok()) << "already running";
  EXPECT_EQ((*loop)->tick().tick, 0u) << "no manual tick while the thread runs";
  std::vector<TickRecord> out;
  EXPECT_FALSE((*loop)->copy_telemetry(out).ok()) << "the ring is read only after stop";
  while ((*loop)->counters().ticks < 1000) std::this_thread::yield();
  (*loop)->stop();
  EXPECT_FALSE((*loop)->running());
  EXPECT_TRUE(started_on_loop_thread);
  EXPECT_NE(loop_thread, std::this_thread::get_id());
  const SchedulingReport& r = (*loop)->scheduling();
  EXPECT_NE(r.requested.find("SCHED_OTHER"), std::string::npos) << r.describe();
  EXPECT_FALSE(r.policy.empty());
  EXPECT_EQ(r.cpu_latency, "not requested");
  // On a virtual clock every tick wakes exactly at its deadline, 1 ms apart.
  ASSERT_TRUE((*loop)->copy_telemetry(out).ok());
  ASSERT_EQ(out.size(), 100u);
  for (std::size_t i = 1; i < out.size(); ++i) {
    EXPECT_EQ(out[i].tick, out[i - 1].tick + 1);
    EXPECT_EQ(out[i].start_ns - out[i - 1].start_ns, kMs);
    EXPECT_EQ(out[i].scheduled_ns, out[i].start_ns);
  }
  EXPECT_EQ((*loop)->counters().missed_deadlines, 0u);
  EXPECT_EQ(device.commands(), (*loop)->counters().ticks + 1) << "every tick, and zero force at stop";
}

// A device at a fixed pose that keeps the first kKept forces commanded
// after arm() (preallocated: the loop thread writes, the test reads after stop()).
class RecordingDevice final : public HapticDevice {
 public:
  static constexpr int kKept = 64;
  explicit RecordingDevice(const Vec3& position) : position_(position) {}
  [[nodiscard]] std::string name() const override { return "recording"; }
  [[nodiscard]] double update_rate_hz() const override { return 1000.0; }
  bool sample(std::int64_t now_ns, DeviceSample& out) noexcept override {
    out = {};
    out.sequence = ++sequence_;
    out.time_ns = now_ns;
    out.position = position_;
    return true;
  }
  void command(const Vec3& force, const Vec3&, std::int64_t) noexcept override {
    if (kept_ < kKept) forces_[kept_++] = force;
  }
  void arm() { kept_ = 0; }
  [[nodiscard]] int kept() const { return kept_; }
  [[nodiscard]] const Vec3& force(int i) const { return forces_[i]; }

 private:
  Vec3 position_;
  std::uint64_t sequence_ = 0;
  std::array<Vec3, kKept> forces_{};
  int kept_ = 0;
};

TEST(HapticsLoop, RestartRampsTheGainUpAgainAfterAStop) {
  // The loop thread on a virtual clock, stopped, 1 s of virtual time later
  // restarted with a fresh snapshot: the first tick after the restart must
  // not take the stopped second as its dt (gain straight to 1, a missed
  // deadline). The device sits 4 mm below the tool: K x 4 mm = 2 N at full gain.
  RecordingDevice device({0.0, -0.004, 0.0});
  VirtualClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  HapticLoopSettings settings;
  settings.realtime = false;
  auto loop = HapticLoop::create(settings, device, snapshots, feedback, clock);
  ASSERT_TRUE(loop.ok());
  HapticSnapshot tool;
  tool.sequence = 1;
  tool.stamp_ns = clock.now_ns();
  snapshots.publish(tool);
  ASSERT_TRUE((*loop)->start().ok());
  while ((*loop)->counters().ticks < 100) std::this_thread::yield();
  (*loop)->stop();
  const std::uint64_t before = (*loop)->counters().ticks;
  ASSERT_EQ((*loop)->counters().missed_deadlines, 0u);

  clock.advance(1000 * kMs);  // stopped for 1 s
  tool.sequence = 2;
  tool.stamp_ns = clock.now_ns();
  snapshots.publish(tool);
  device.arm();
  ASSERT_TRUE((*loop)->start().ok());
  while ((*loop)->counters().ticks < before + RecordingDevice::kKept) std::this_thread::yield();
  (*loop)->stop();
  EXPECT_EQ((*loop)->counters().missed_deadlines, 0u) << "the stopped time is no missed deadline";
  ASSERT_EQ(device.kept(), RecordingDevice::kKept);
  // The k-th tick after the restart (1 ms apart, the snapshot at most 40 ms
  // old: fresh): gain k T / recover_time, force 2 N x gain.
  const double full = settings.coupling.stiffness * 0.004;
  for (int k = 1; k <= 40; ++k)
    EXPECT_NEAR(device.force(k - 1)[1], full * k * 0.001 / settings.watchdog.recover_time, 1e-9)
        << "tick " << k << " after the restart";
}

// A device that, from inside the tick (its sample()), tries what an SDK
// servo callback racing the application thread would: copy the telemetry
// ring and tick again while a tick is writing it.
class MeddlingDevice final : public HapticDevice {
 public:
  [[nodiscard]] std::string name() const override { return "meddling"; }
  [[nodiscard]] double update_rate_hz() const override { return 1000.0; }
  bool sample(std::int64_t now_ns, DeviceSample& out) noexcept override {
    if (loop && !inside) {
      inside = true;
      copied = loop->copy_telemetry(telemetry);
      nested_tick = loop->tick().tick;
      inside = false;
    }
    out = {};
    out.sequence = ++sequence_;
    out.time_ns = now_ns;
    return true;
  }
  void command(const Vec3&, const Vec3&, std::int64_t) noexcept override {}
  HapticLoop* loop = nullptr;
  bool inside = false;
  sinew::Status copied;
  std::uint64_t nested_tick = 99;
  std::vector<TickRecord> telemetry;

 private:
  std::uint64_t sequence_ = 0;
};

TEST(HapticsLoop, CopyTelemetryAndTickAreRefusedWhileATickIsInProgress) {
  MeddlingDevice device;
  VirtualRig rig(device);
  device.loop = rig.loop.get();
  const TickRecord r = rig.step();
  EXPECT_EQ(r.tick, 1u);
  EXPECT_FALSE(device.copied.ok()) << "no copy of the ring while a tick writes it";
  if (!device.copied.ok()) {
    EXPECT_NE(device.copied.error().message().find("tick() is in progress"), std::string::npos);
  }
  EXPECT_EQ(device.nested_tick, 0u) << "an overlapping tick is skipped";
  EXPECT_EQ(rig.loop->counters().ticks, 1u);
  device.loop = nullptr;
  std::vector<TickRecord> out;
  ASSERT_TRUE(rig.loop->copy_telemetry(out).ok()) << "between ticks the copy is allowed";
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].tick, 1u);
  EXPECT_EQ(rig.loop->tick().tick, 2u) << "and ticks go on after a copy";
}

TEST(HapticsLoop, RealtimeRequestIsReportedNotAssumed) {
  // A real clock here (nothing is timed): on a virtual clock the loop never
  // sleeps, and a SCHED_FIFO thread that never sleeps would hog a core.
  NullDevice device;
  MonotonicClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  HapticLoopSettings settings;
  settings.realtime = true;
  settings.realtime_priority = 10;
  settings.zero_cpu_latency = false;
  auto loop = HapticLoop::create(settings, device, snapshots, feedback, clock);
  ASSERT_TRUE(loop.ok());
  ASSERT_TRUE((*loop)->start().ok());
  (*loop)->stop();
  const SchedulingReport& r = (*loop)->scheduling();
  EXPECT_NE(r.requested.find("SCHED_FIFO priority 10"), std::string::npos);
  // Either it was granted, or the report says why not.
  if (r.realtime())
    EXPECT_EQ(r.priority, 10) << r.describe();
  else
    EXPECT_NE(r.error.find("SCHED_FIFO"), std::string::npos) << r.describe();
  std::printf("[ measured ] scheduling obtained here: %s\n", r.describe().c_str());
}

TEST(HapticsLoop, TelemetryRingKeepsTheNewest) {
  NullDevice device;
  HapticLoopSettings settings;
  settings.telemetry_capacity = 10;
  VirtualRig rig(device, settings);
  rig.run(25);
  std::vector<TickRecord> out;
  ASSERT_TRUE(rig.loop->copy_telemetry(out).ok());
  ASSERT_EQ(out.size(), 10u);
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i].tick, 16 + i);
}

TEST(HapticsLoop, ImpossibleSettingsAreErrors) {
  NullDevice device;
  VirtualClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  auto says = [&](HapticLoopSettings s, const char* what) {
    auto made = HapticLoop::create(s, device, snapshots, feedback, clock);
    return !made.ok() && made.error().message().find(what) != std::string::npos;
  };
  HapticLoopSettings s;
  s.rate_hz = 0;
  EXPECT_TRUE(says(s, "rate_hz"));
  s.rate_hz = -1000;
  EXPECT_TRUE(says(s, "rate_hz"));
  s.rate_hz = std::nan("");
  EXPECT_TRUE(says(s, "rate_hz"));
  s.rate_hz = 0.5;  // below 1 Hz
  EXPECT_TRUE(says(s, "rate_hz"));
  s.rate_hz = 1e-12;  // a period of 10^21 ns does not fit the int64 clock
  EXPECT_TRUE(says(s, "rate_hz"));
  s.rate_hz = 2e6;
  EXPECT_TRUE(says(s, "rate_hz"));
  s = {};
  s.rate_hz = 1.0;
  EXPECT_TRUE(HapticLoop::create(s, device, snapshots, feedback, clock).ok()) << "1 Hz is the lowest rate";
  s = {};
  s.realtime_priority = 0;
  EXPECT_TRUE(says(s, "realtime_priority"));
  s = {};
  s.coupling.stiffness = -500;
  EXPECT_TRUE(says(s, "coupling.stiffness"));
  s = {};
  s.coupling.max_force = std::nan("");
  EXPECT_TRUE(says(s, "coupling.max_force"));
  s = {};
  s.watchdog.stale_after = -1;
  EXPECT_TRUE(says(s, "watchdog.stale_after"));
  s = {};
  s.telemetry_capacity = 0;
  EXPECT_TRUE(says(s, "telemetry_capacity"));
  // Too large to allocate: an error, not an exception out of create().
  for (std::size_t too_many : {kMaxTelemetryCapacity + 1, std::numeric_limits<std::size_t>::max()}) {
    s.telemetry_capacity = too_many;
    EXPECT_NO_THROW(EXPECT_TRUE(says(s, "telemetry_capacity")) << too_many);
  }
  s = {};
  s.interpolation.extrapolation_horizon = -0.1;
  EXPECT_TRUE(says(s, "extrapolation_horizon"));
}

}  // namespace
