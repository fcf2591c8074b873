// The passivity observer (Hannaford and Ryu 2002) and the 3-DOF mode, on a
// virtual clock: a spring-damper coupling against a resting tool while the
// device goes in and out stays passive; the sampled spring alone is active
// by exactly K/2 sum |dx|^2 per closed cycle; a tool that leads the hand
// (an environment that makes energy) is flagged, in translation and in
// rotation; a 3-DOF device gets exactly zero torque and exchanges no
// rotational energy, while the tool still gets the coupling torque; the
// passivity controller damps what an active environment gives out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "haptics_test_support.h"

namespace {

using namespace sinew::test;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRest = 0.5;       // [s] device and tool at rest while the watchdog ramps the gain up
constexpr double kAmplitude = 0.005;  // [m] in and out
constexpr double kTurn = 0.2;       // [rad] about z
constexpr double kOmega = 2 * kPi * 2.0;  // 2 Hz

Quat about_z(double angle) { return {std::cos(angle / 2), 0.0, 0.0, std::sin(angle / 2)}; }

// In and out along x and a turn about z, from rest and back to it every half second.
ScriptedPose in_and_out(double t) {
  const double s = t < kRest ? 0.0 : 0.5 * (1.0 - std::cos(kOmega * (t - kRest)));
  ScriptedPose p;
  p.position = {kAmplitude * s, 0.0, 0.0};
  p.rotation = about_z(kTurn * s);
  return p;
}

struct LoopRun {
  std::vector<TickRecord> ticks;
  HapticCounters counters;
  double most_feedback_torque = 0.0;    // |CouplingFeedback::torque| [N m]
  double most_angular_impulse = 0.0;    // |CouplingFeedback::angular_impulse| [N m s]
};

// The loop against a tool resting at the origin for `seconds`.
LoopRun against_resting_tool(HapticDevice& device, const HapticLoopSettings& settings, double seconds) {
  VirtualRig rig(device, settings);
  LoopRun run;
  const int n = static_cast<int>(seconds * 1000.0 + 0.5);
  for (int i = 0; i < n; ++i) run.ticks.push_back(rig.step());
  run.counters = rig.loop->counters();
  return run;
}

TEST(HapticsPassivity, SpringDamperAgainstARestingToolStaysPassive) {
  ScriptedDevice device(in_and_out);
  const LoopRun run = against_resting_tool(device, {}, kRest + 5.0);  // 10 cycles
  double least = 0.0, least_window = 0.0;
  for (const TickRecord& r : run.ticks) {
    least = std::min(least, r.passivity_energy);
    least_window = std::min(least_window, r.window_energy);
    EXPECT_FALSE(r.flags & kPassivityViolation) << "tick " << r.tick;
  }
  EXPECT_EQ(run.counters.passivity_violations, 0u);
  EXPECT_GE(least, -1e-12) << "the cumulative energy never went below zero";
  EXPECT_GT(run.counters.passivity_energy, 0.0) << "the damper dissipated";
  // The spring gave back what it stored within a window: a window alone
  // would have called that created energy.
  EXPECT_LT(least_window, -1e-3);
  EXPECT_DOUBLE_EQ(run.counters.min_window_energy, least_window);
  std::printf("passive coupling: E = %.4g J after 10 cycles, least E %.3g J, least window (100 ticks) %.4g J\n",
              run.counters.passivity_energy, least, least_window);
}

// A pure spring (B = 0) held between ticks: the observer reads exactly the
// sampled-data activity, -K/2 sum |dx|^2 - K_r/2 sum |dtheta|^2 after each
// closed cycle, and flags the ticks once that passes the tolerance.
TEST(HapticsPassivity, SampledSpringIsActiveByHalfKSumOfSquaredSteps) {
  HapticLoopSettings settings;
  settings.coupling.damping = 0.0;
  settings.coupling.rotational_damping = 0.0;
  settings.passivity.tolerance = 1e-4;
  ScriptedDevice device(in_and_out);
  const LoopRun run = against_resting_tool(device, settings, kRest + 5.001);  // to the end of the 10th cycle
  const double k = settings.coupling.stiffness, kr = settings.coupling.rotational_stiffness;
  double squares = 0.0, turn_squares = 0.0;
  std::uint64_t first_violation = 0;
  int cycles_checked = 0;
  for (std::size_t i = 1; i < run.ticks.size(); ++i) {
    const double t0 = static_cast<double>(i - 1) * 1e-3, t1 = static_cast<double>(i) * 1e-3;
    const double dx = in_and_out(t1).position[0] - in_and_out(t0).position[0];
    const double dtheta = kTurn * (in_and_out(t1).position[0] - in_and_out(t0).position[0]) / kAmplitude;
    squares += dx * dx;
    turn_squares += dtheta * dtheta;
    const TickRecord& r = run.ticks[i];
    if ((r.flags & kPassivityViolation) && first_violation == 0) first_violation = r.tick;
    // Back at rest after each whole cycle (every 500 ticks from the start of the motion).
    if (t1 > kRest && static_cast<long>(std::lround((t1 - kRest) * 1000.0)) % 500 == 0) {
      const double expected = -0.5 * k * squares - 0.5 * kr * turn_squares;
      EXPECT_NEAR(r.passivity_energy, expected, 1e-9 * std::abs(expected) + 1e-15) << "t = " << t1;
      ++cycles_checked;
    }
  }
  EXPECT_EQ(cycles_checked, 10);
  const double total = run.counters.passivity_energy;
  EXPECT_LT(total, -settings.passivity.tolerance) << "the leak outgrew the tolerance";
  EXPECT_GT(run.counters.passivity_violations, 0u);
  EXPECT_GT(first_violation, 0u);
  // Before the first flagged tick the energy was above -tolerance, from it on below.
  EXPECT_GE(run.ticks[first_violation - 2].passivity_energy, -settings.passivity.tolerance);
  EXPECT_LT(run.ticks[first_violation - 1].passivity_energy, -settings.passivity.tolerance);
  std::printf("sampled spring (B = 0): E = %.4g J after 10 cycles (-K/2 sum dx^2 - K_r/2 sum dtheta^2 = %.4g J), "
              "%llu ticks flagged, first at tick %llu\n",
              total, -0.5 * k * squares - 0.5 * kr * turn_squares,
              static_cast<unsigned long long>(run.counters.passivity_violations),
              static_cast<unsigned long long>(first_violation));
}

// A tool that leads the hand by a phase `lead` (as a motor would drive it)
// pushes the hand along its motion: the environment gives out energy it
// never received. In translation (`turn` false) or in rotation about z.
LoopRun leading_tool(const HapticLoopSettings& settings, bool turn, double lead) {
  const double amplitude = turn ? 0.5 : kAmplitude;  // [rad] or [m]
  auto pose_at = [=](double t, double phase) {
    ScriptedPose p;
    const double s = t < kRest ? 0.0 : amplitude * std::sin(kOmega * (t - kRest) + phase);
    if (turn)
      p.rotation = about_z(s);
    else
      p.position = {s, 0.0, 0.0};
    return p;
  };
  ScriptedDevice device([=](double t) { return pose_at(t, 0.0); });
  VirtualRig rig(device, settings);
  LoopRun run;
  for (int i = 0; i < static_cast<int>((kRest + 2.5) * 1000.0); ++i) {
    // The tool's state at the next snapshot (published by step() when a frame is due).
    const double t = rig.clock.now_ns() * 1e-9;
    const ScriptedPose p = pose_at(t, t < kRest ? 0.0 : lead);
    const double rate = t < kRest ? 0.0 : amplitude * kOmega * std::cos(kOmega * (t - kRest) + lead);
    rig.tool.position = p.position;
    rig.tool.rotation = p.rotation;
    rig.tool.velocity = turn ? Vec3{0, 0, 0} : Vec3{rate, 0, 0};
    rig.tool.angular_velocity = turn ? Vec3{0, 0, rate} : Vec3{0, 0, 0};
    run.ticks.push_back(rig.step());
    CouplingFeedback fb;
    EXPECT_TRUE(rig.feedback.try_read(fb, 4));
    run.most_feedback_torque = std::max(run.most_feedback_torque, norm3(fb.torque));
    run.most_angular_impulse = std::max(run.most_angular_impulse, norm3(fb.angular_impulse));
  }
  run.counters = rig.loop->counters();
  return run;
}

TEST(HapticsPassivity, ToolLeadingTheHandIsFlagged) {
  const LoopRun run = leading_tool({}, false, 0.8);
  std::uint64_t flagged = 0;
  for (const TickRecord& r : run.ticks) flagged += (r.flags & kPassivityViolation) ? 1 : 0;
  EXPECT_GT(run.counters.passivity_violations, 100u);
  EXPECT_EQ(flagged, run.counters.passivity_violations);
  EXPECT_LT(run.counters.passivity_energy, -0.02) << "energy given out over 5 cycles";
  std::printf("tool leading the hand by 0.8 rad (translation): E = %.4g J after 5 cycles, %llu ticks flagged\n",
              run.counters.passivity_energy, static_cast<unsigned long long>(run.counters.passivity_violations));
}

// 6 DOF: a turning tool that leads the hand's turn is flagged through the
// torque term. 3 DOF: the device is commanded exactly zero torque, so no
// rotational energy crosses the port (none flagged), while the feedback
// still carries the coupling torque to the tool.
TEST(HapticsPassivity, ThreeDofDeviceGetsNoTorqueButTheToolDoes) {
  const LoopRun six = leading_tool({}, true, 0.8);
  EXPECT_GT(six.counters.passivity_violations, 100u);
  EXPECT_LT(six.counters.passivity_energy, -0.005);
  double most_torque = 0.0;
  for (const TickRecord& r : six.ticks) most_torque = std::max(most_torque, norm3(r.torque));
  EXPECT_GT(most_torque, 0.01);

  HapticLoopSettings three;
  three.degrees_of_freedom = 3;
  const LoopRun run = leading_tool(three, true, 0.8);
  for (const TickRecord& r : run.ticks) {
    ASSERT_EQ(r.torque, (Vec3{0.0, 0.0, 0.0})) << "tick " << r.tick;
    ASSERT_EQ(r.passivity_energy, 0.0) << "tick " << r.tick;  // no force either: the device only turns
  }
  EXPECT_EQ(run.counters.passivity_violations, 0u);
  EXPECT_GT(run.most_feedback_torque, 0.01) << "the coupling torque still goes to the tool [N m]";
  EXPECT_GT(run.most_angular_impulse, 5e-4) << "[N m s]";
  std::printf("turning tool leading by 0.8 rad: 6 DOF E = %.4g J (%llu ticks flagged); 3 DOF E = 0, none flagged, "
              "feedback torque up to %.4g N m, angular impulse up to %.4g N m s\n",
              six.counters.passivity_energy, static_cast<unsigned long long>(six.counters.passivity_violations),
              run.most_feedback_torque, run.most_angular_impulse);
}

TEST(HapticsPassivity, ThreeDofDeviceIsCommandedExactlyZeroTorque) {
  // The device itself (not only the telemetry) sees zero torque each tick.
  HapticLoopSettings three;
  three.degrees_of_freedom = 3;
  ScriptedDevice device([](double t) {
    ScriptedPose p;
    p.rotation = about_z(t < kRest ? 0.0 : 0.5);
    return p;
  });
  VirtualRig rig(device, three);
  for (int i = 0; i < 1000; ++i) {
    rig.step();
    ASSERT_EQ(device.last_torque(), (Vec3{0.0, 0.0, 0.0}));
  }
  EXPECT_EQ(device.commands(), 1000u);
  CouplingFeedback fb;
  ASSERT_TRUE(rig.feedback.try_read(fb, 4));
  EXPECT_LT(fb.torque[2], -0.01) << "the coupling's torque on the device side, handed to the tool";
}

// The passivity controller: against the tool that leads the hand, its
// damper dissipates what the environment gives out, so the cumulative
// energy stays near zero; against a passive rendering it never engages.
TEST(HapticsPassivity, ControllerDampsWhatTheEnvironmentCreates) {
  const LoopRun off = leading_tool({}, false, 0.8);
  HapticLoopSettings settings;
  settings.passivity.controller = true;
  settings.passivity.max_damping = 50.0;
  const LoopRun on = leading_tool(settings, false, 0.8);
  std::uint64_t damped = 0;
  for (const TickRecord& r : on.ticks) damped += (r.flags & kPassivityDamping) ? 1 : 0;
  EXPECT_GT(damped, 100u);
  EXPECT_LT(on.counters.passivity_violations, off.counters.passivity_violations / 10);
  EXPECT_GT(on.counters.passivity_energy, -0.01);
  std::printf("passivity controller (max 50 N s/m) against the leading tool: E = %.4g J (off: %.4g J), %llu ticks "
              "flagged (off: %llu), damper on in %llu ticks\n",
              on.counters.passivity_energy, off.counters.passivity_energy,
              static_cast<unsigned long long>(on.counters.passivity_violations),
              static_cast<unsigned long long>(off.counters.passivity_violations),
              static_cast<unsigned long long>(damped));

  ScriptedDevice plain_device(in_and_out), controlled_device(in_and_out);
  const LoopRun plain = against_resting_tool(plain_device, {}, kRest + 2.0);
  const LoopRun controlled = against_resting_tool(controlled_device, settings, kRest + 2.0);
  ASSERT_EQ(plain.ticks.size(), controlled.ticks.size());
  for (std::size_t i = 0; i < plain.ticks.size(); ++i) {
    ASSERT_FALSE(controlled.ticks[i].flags & kPassivityDamping) << "tick " << i + 1;
    ASSERT_EQ(controlled.ticks[i].force, plain.ticks[i].force) << "tick " << i + 1;
    ASSERT_EQ(controlled.ticks[i].torque, plain.ticks[i].torque) << "tick " << i + 1;
  }
}

TEST(HapticsPassivity, BadSettingsAreNamed) {
  HapticLoopSettings s;
  s.degrees_of_freedom = 4;
  auto e = check(s);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message().find("degrees_of_freedom"), std::string::npos);
  s = {};
  s.passivity.window = 0;
  e = check(s);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message().find("passivity.window"), std::string::npos);
  s = {};
  s.passivity.tolerance = std::nan("");
  e = check(s);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message().find("passivity.tolerance"), std::string::npos);
  s = {};
  s.passivity.max_damping = -1.0;
  e = check(s);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message().find("passivity.max_damping"), std::string::npos);
  s = {};
  s.passivity.max_rotational_damping = std::numeric_limits<double>::infinity();
  e = check(s);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message().find("passivity.max_rotational_damping"), std::string::npos);
}

}  // namespace
