// The safety chain (clamp keeping direction, per-tick change limit, NaN to
// zero) and the watchdog (fade on stale snapshots, recovery), on a virtual clock.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "haptics_test_support.h"
#include "sinew/haptics/force_safety.h"
#include "sinew/haptics/virtual_coupling.h"
#include "sinew/haptics/watchdog.h"

namespace {

using namespace sinew::test;

TEST(HapticsSafety, ClampKeepsTheDirection) {
  SafetyFilter f(3.3, 1e9);  // no slew limit
  std::uint32_t flags = 0;
  const Vec3 raw{30.0, -40.0, 120.0};  // |raw| = 130 N
  const Vec3 out = f.apply(raw, 1.0, flags);
  EXPECT_NEAR(norm3(out), 3.3, 1e-12);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(out[k], raw[k] * 3.3 / 130.0, 1e-12) << "same direction, component " << k;
  EXPECT_TRUE(flags & kClamped);
  // Below the clamp nothing changes.
  flags = 0;
  const Vec3 small = f.apply({1.0, 2.0, -2.0}, 1.0, flags);
  EXPECT_EQ(small, (Vec3{1.0, 2.0, -2.0}));
  EXPECT_FALSE(flags & kClamped);
}

TEST(HapticsSafety, PerTickChangeLimitHolds) {
  SafetyFilter f(3.3, 0.25);
  std::uint32_t flags = 0;
  const Vec3 target{0.0, 3.0, 4.0};  // |target| = 5 N: clamped to 3.3 N along (0, 0.6, 0.8)
  Vec3 prev{0, 0, 0};
  int ticks = 0;
  while (norm3(prev) < 3.3 - 1e-12 && ticks < 100) {
    const Vec3 out = f.apply(target, 1.0, flags);
    const Vec3 d{out[0] - prev[0], out[1] - prev[1], out[2] - prev[2]};
    EXPECT_LE(norm3(d), 0.25 + 1e-12) << "tick " << ticks;
    EXPECT_LE(norm3(out), 3.3 + 1e-12);
    EXPECT_NEAR(out[1] * 0.8, out[2] * 0.6, 1e-12) << "on the way along the clamped direction";
    prev = out;
    ++ticks;
  }
  EXPECT_EQ(ticks, 14) << "3.3 N at 0.25 N per tick takes ceil(13.2) ticks";
  EXPECT_TRUE(flags & kSlewLimited);
  // Reversal: still at most 0.25 N per tick.
  const Vec3 back = f.apply({0.0, -3.0, -4.0}, 1.0, flags);
  EXPECT_NEAR(norm3(back), 3.3 - 0.25, 1e-12);
}

TEST(HapticsSafety, NonFiniteGivesZeroForce) {
  SafetyFilter f(3.3, 0.25);
  std::uint32_t flags = 0;
  for (int i = 0; i < 20; ++i) f.apply({0.0, 2.0, 0.0}, 1.0, flags);
  ASSERT_NEAR(f.last()[1], 2.0, 1e-12);
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    flags = 0;
    const Vec3 out = f.apply({1.0, bad, 0.0}, 1.0, flags);
    EXPECT_EQ(out, (Vec3{0, 0, 0})) << "at once, not slewed down";
    EXPECT_TRUE(flags & kNonFinite);
  }
  // A NaN gain is a zero gain.
  flags = 0;
  const Vec3 g = f.apply({0.1, 0.0, 0.0}, std::nan(""), flags);
  EXPECT_EQ(g, (Vec3{0, 0, 0}));
}

TEST(HapticsSafety, NaNFromTheDeviceGivesZeroForceThroughTheLoop) {
  // A device that reports NaN positions every 100th tick.
  ScriptedDevice device([](double t) {
    ScriptedPose p;
    p.position = {0.0, -0.004, 0.0};  // 4 mm below the tool: 2 N up
    const long long k = std::llround(t * 1000.0);  // the tick, when t is a tick's time
    if (k > 500 && k % 100 == 0 && std::abs(t - double(k) / 1000.0) < 1e-9) p.position[1] = std::nan("");
    return p;
  });
  VirtualRig rig(device);
  rig.run(400);  // ramp up through the watchdog
  int nan_ticks = 0;
  for (int i = 0; i < 600; ++i) {
    const TickRecord r = rig.step();
    if (r.flags & kNonFinite) {
      ++nan_ticks;
      EXPECT_EQ(r.force, (Vec3{0, 0, 0})) << "tick " << r.tick;
      EXPECT_EQ(device.last_force(), (Vec3{0, 0, 0}));
    }
  }
  EXPECT_GT(nan_ticks, 0);
  EXPECT_EQ(rig.loop->counters().non_finite, static_cast<std::uint64_t>(nan_ticks)) << "counted";
}

// 1 rad about z.
constexpr Quat kTurned{0.8775825618903728, 0.0, 0.0, 0.479425538604203};

// Ticks after a NaN rotation reached the loop: zero force and torque at
// once, every one of them flagged and counted as non-finite.
void expect_zero_and_counted(VirtualRig& rig, ScriptedDevice& device) {
  const std::uint64_t before = rig.loop->counters().non_finite;
  for (int i = 0; i < 100; ++i) {
    const TickRecord r = rig.step();
    EXPECT_TRUE(r.flags & kNonFinite) << "tick " << r.tick;
    EXPECT_EQ(r.force, (Vec3{0, 0, 0})) << "tick " << r.tick;
    EXPECT_EQ(device.last_force(), (Vec3{0, 0, 0})) << "tick " << r.tick;
    EXPECT_EQ(device.last_torque(), (Vec3{0, 0, 0})) << "tick " << r.tick;
  }
  EXPECT_EQ(rig.loop->counters().non_finite - before, 100u) << "counted";
}

TEST(HapticsSafety, NaNToolRotationGivesZeroForceAndTorque) {
  // The device turned 1 rad from the tool and 4 mm below it: 2 N and
  // K_r x 1 rad of torque. Then the physics publishes a NaN rotation: the
  // interpolated rotation must stay NaN (not become the identity, which
  // would be a 1 rad twist) so the chain zeroes force and torque.
  ScriptedDevice device([](double) {
    ScriptedPose p;
    p.position = {0.0, -0.004, 0.0};
    p.rotation = kTurned;
    return p;
  });
  VirtualRig rig(device);
  rig.run(400);
  ASSERT_GT(norm3(device.last_torque()), 0.01) << "the twist is rendered";
  ASSERT_EQ(rig.loop->counters().non_finite, 0u);
  rig.tool.rotation = {std::nan(""), 0.0, 0.0, 0.0};
  rig.run(20);  // a frame with the NaN rotation is published (60 Hz)
  expect_zero_and_counted(rig, device);
}

TEST(HapticsSafety, NaNDeviceRotationGivesZeroForceAndTorque) {
  // The tool turned 1 rad and 4 mm above the device; the device's
  // rotation turns NaN after 0.4 s (a scripted device, and a null device
  // with a NaN pose): not the identity, zero force and torque.
  ScriptedDevice device([](double t) {
    ScriptedPose p;
    p.position = {0.0, -0.004, 0.0};
    if (t > 0.4) p.rotation = {0.0, std::nan(""), 0.0, 0.0};
    return p;
  });
  VirtualRig rig(device);
  rig.tool.rotation = kTurned;
  rig.run(400);
  ASSERT_GT(norm3(device.last_torque()), 0.01) << "the twist is rendered";
  ASSERT_EQ(rig.loop->counters().non_finite, 0u);
  rig.run(2);
  expect_zero_and_counted(rig, device);

  NullDevice null_device({.position = {0.0, -0.004, 0.0}, .rotation = {std::nan(""), 0.0, 0.0, 0.0}});
  VirtualRig null_rig(null_device);
  null_rig.tool.rotation = kTurned;
  for (int i = 0; i < 400; ++i) {
    const TickRecord r = null_rig.step();
    EXPECT_TRUE(r.flags & kNonFinite) << "tick " << r.tick;
    EXPECT_EQ(r.force, (Vec3{0, 0, 0})) << "tick " << r.tick;
  }
  EXPECT_EQ(null_rig.loop->counters().non_finite, 400u);
}

TEST(HapticsWatchdog, FadesAndRecoversLinearly) {
  WatchdogParams p;
  p.stale_after = 0.05;
  p.fade_time = 0.1;
  p.recover_time = 0.2;
  Watchdog w(p);
  EXPECT_DOUBLE_EQ(w.gain(), 0.0) << "starts faded";
  for (int i = 0; i < 200; ++i) w.update(0.0, 0.0, 0.001);
  EXPECT_NEAR(w.gain(), 1.0, 1e-12) << "0.2 s to recover";
  for (int i = 0; i < 50; ++i) w.update(0.06, 0.0, 0.001);
  EXPECT_NEAR(w.gain(), 0.5, 1e-12) << "half of the 0.1 s fade";
  EXPECT_TRUE(w.stale());
  EXPECT_EQ(w.stalls(), 1u);
  for (int i = 0; i < 50; ++i) w.update(0.06, 0.0, 0.001);
  EXPECT_NEAR(w.gain(), 0.0, 1e-12);
  w.update(0.0, 1.0, 0.001);
  EXPECT_TRUE(w.stale()) << "a stale device sample counts too";
  w.update(std::nan(""), 0.0, 0.001);
  EXPECT_TRUE(w.stale()) << "a NaN age is stale";
}

TEST(HapticsWatchdog, InjectedStallFadesTheForceToZeroWithinTheConfiguredTimeAndRecovers) {
  // The device sits 4 mm below a static tool: the coupling pushes it up
  // with K x 4 mm = 2 N. The physics publishes at 60 Hz, then stalls.
  NullDevice device({.position = {0.0, -0.004, 0.0}});
  HapticLoopSettings settings;
  settings.watchdog = {.stale_after = 0.05, .device_stale_after = 0.01, .fade_time = 0.1, .recover_time = 0.25};
  VirtualRig rig(device, settings);
  const double full = settings.coupling.stiffness * 0.004;
  TickRecord r = rig.run(1000);
  ASSERT_NEAR(r.force[1], full, 1e-9) << "full force once recovered";
  ASSERT_DOUBLE_EQ(r.gain, 1.0);

  // Stall: no more snapshots after the last one.
  rig.publishing = false;
  const std::int64_t last_stamp = rig.tool.stamp_ns;
  const std::int64_t zero_by = last_stamp + seconds_to_ns(0.05 + 0.1) + kMs;  // stale_after + fade_time (+ a tick)
  double prev = r.force[1];
  bool reached_zero = false;
  while (rig.clock.now_ns() <= zero_by + 20 * kMs) {
    r = rig.step();
    EXPECT_LE(r.force[1], prev + 1e-12) << "never rises while stale";
    prev = r.force[1];
    if (r.start_ns < last_stamp + seconds_to_ns(0.05)) {
      EXPECT_NEAR(r.force[1], full, 1e-9) << "not yet stale at " << r.start_ns;
    }
    if (r.start_ns >= zero_by) {
      EXPECT_EQ(r.force[1], 0.0) << "zero within stale_after + fade_time, at " << r.start_ns;
      reached_zero = true;
    }
  }
  EXPECT_TRUE(reached_zero);
  EXPECT_EQ(rig.loop->counters().stalls, 1u);
  EXPECT_GT(rig.loop->counters().stale_ticks, 0u);

  // Resume: back to full force within recover_time (+ a tick).
  rig.publishing = true;
  const std::int64_t resumed = rig.clock.now_ns();
  while (rig.clock.now_ns() < resumed + seconds_to_ns(0.25) + 2 * kMs) r = rig.step();
  EXPECT_NEAR(r.force[1], full, 1e-9) << "recovered";
  EXPECT_DOUBLE_EQ(r.gain, 1.0);
}

TEST(HapticsSafety, ParametersAreChecked) {
  auto says = [](const sinew::Status& s, const char* what) {
    return !s.ok() && s.error().message().find(what) != std::string::npos;
  };
  CouplingParams c;
  c.stiffness = -1;
  EXPECT_TRUE(says(check(c), "coupling.stiffness"));
  c = {};
  c.damping = std::nan("");
  EXPECT_TRUE(says(check(c), "coupling.damping"));
  c = {};
  c.max_force = 0;
  EXPECT_TRUE(says(check(c), "coupling.max_force"));
  c = {};
  c.max_force_change = -0.1;
  EXPECT_TRUE(says(check(c), "coupling.max_force_change"));
  WatchdogParams w;
  w.fade_time = 0;
  EXPECT_TRUE(says(check(w), "watchdog.fade_time"));
  EXPECT_TRUE(check(CouplingParams{}).ok());
  EXPECT_TRUE(check(WatchdogParams{}).ok());
}

}  // namespace
