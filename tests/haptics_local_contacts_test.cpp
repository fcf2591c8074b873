// The local contact model (sinew/haptics/local_contacts.h): the proxy
// solve against compliant planes, the planes a frame publishes, and a probe
// pressed into a tissue block through a real haptic loop, rendered with and
// without the model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "haptics_block_scene.h"
#include "haptics_test_support.h"
#include "sinew/haptics/local_contact_builder.h"
#include "sinew/haptics/local_contacts.h"
#include "sinew/haptics/tool_bridge.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace sinew::test {
namespace {

using haptics::LocalContact;
using haptics::LocalContactModel;
using haptics::solve_local_contacts;

LocalContact plane(const Vec3& normal, double gap, double stiffness, double force = 0.0) {
  LocalContact c;
  c.normal = normal;
  c.gap = gap;
  c.stiffness = stiffness;
  c.force = force;
  return c;
}

TEST(LocalContactSolve, FreeSpaceLeavesTheProxyOnTheDevice) {
  LocalContactModel m;
  const Vec3 a{0.01, -0.02, 0.03};
  auto s = solve_local_contacts(m, a, 500.0);
  EXPECT_EQ(s.proxy, a);
  EXPECT_EQ(norm3(s.force), 0.0);
  EXPECT_EQ(s.energy, 0.0);
  EXPECT_EQ(s.active, 0u);
  // A plane the device has not reached pushes nothing either.
  m.count = 1;
  m.contacts[0] = plane({0, 0, 1}, 0.001, 200.0);
  s = solve_local_contacts(m, a, 500.0);
  EXPECT_EQ(s.proxy, a);
  EXPECT_EQ(s.active, 0u);
  EXPECT_TRUE(s.converged);
}

TEST(LocalContactSolve, OnePlaneRendersTheSeriesStiffness) {
  const double k_c = 500.0, k = 200.0, depth = 0.004;
  LocalContactModel m;
  m.count = 1;
  m.contacts[0] = plane({0, 0, 1}, 0.0, k);  // the tool's surface on the plane at x0 = 0
  const auto s = solve_local_contacts(m, {0.0, 0.0, -depth}, k_c);
  const double series = k_c * k / (k_c + k);
  EXPECT_NEAR(s.force[2], series * depth, 1e-12);
  EXPECT_NEAR(s.force[0], 0.0, 1e-15);
  EXPECT_NEAR(s.proxy[2], -depth * k_c / (k_c + k), 1e-12);
  EXPECT_NEAR(s.energy, 0.5 * series * depth * depth, 1e-12);
  EXPECT_EQ(s.active, 1u);
  // Sliding along the plane moves the proxy with the device; pushing into
  // it moves the proxy by K / (K + k).
  EXPECT_NEAR(s.sensitivity[0], 1.0, 1e-12);
  EXPECT_NEAR(s.sensitivity[8], k_c / (k_c + k), 1e-12);
}

TEST(LocalContactSolve, AtThePublishedPoseTheModelGivesThePhysicsForce) {
  // The physics found 0.3 N on a plane of 250 N/m with the tool at x0; the
  // device sits where the coupling balances it, x0 - F n / K.
  const double k_c = 500.0, k = 250.0, f = 0.3;
  LocalContactModel m;
  m.count = 1;
  m.tool_position = {0.1, 0.2, 0.3};
  m.contacts[0] = plane({0, 1, 0}, -f / k, k, f);
  const auto s = solve_local_contacts(m, {0.1, 0.2 - f / k_c, 0.3}, k_c);
  EXPECT_NEAR(s.force[1], f, 1e-12);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(s.proxy[i], m.tool_position[i], 1e-12);
}

TEST(LocalContactSolve, ACornerPushesBackAlongBothNormals) {
  const double k_c = 500.0, k = 300.0;
  LocalContactModel m;
  m.count = 2;
  m.contacts[0] = plane({1, 0, 0}, 0.0, k);
  m.contacts[1] = plane({0, 1, 0}, 0.0, k);
  const auto s = solve_local_contacts(m, {-0.002, -0.003, 0.001}, k_c);
  const double series = k_c * k / (k_c + k);
  EXPECT_NEAR(s.force[0], series * 0.002, 1e-12);
  EXPECT_NEAR(s.force[1], series * 0.003, 1e-12);
  EXPECT_NEAR(s.force[2], 0.0, 1e-15);
  EXPECT_EQ(s.active, 2u);
}

TEST(LocalContactSolve, TheForceIsMinusTheGradientOfTheEnergy) {
  // Three oblique planes, some active: F = -dV/da (a conservative rendering
  // within a frame), checked by central differences.
  LocalContactModel m;
  m.count = 3;
  m.contacts[0] = plane({0, 0, 1}, -0.001, 150.0, 0.15);
  m.contacts[1] = plane({0.6, 0, 0.8}, 0.0005, 400.0);
  m.contacts[2] = plane({0, -0.8, 0.6}, 0.0002, 90.0);
  const double k_c = 500.0, h = 1e-7;
  for (const Vec3& a : {Vec3{0.0, 0.0, 0.0}, Vec3{-0.002, 0.001, -0.003}, Vec3{0.001, 0.002, -0.001}}) {
    const auto s = solve_local_contacts(m, a, k_c);
    EXPECT_TRUE(s.converged);
    for (int i = 0; i < 3; ++i) {
      Vec3 p = a, q = a;
      p[i] += h;
      q[i] -= h;
      const double grad = (solve_local_contacts(m, p, k_c).energy - solve_local_contacts(m, q, k_c).energy) / (2 * h);
      EXPECT_NEAR(s.force[i], -grad, 1e-6) << "component " << i;
    }
  }
}

TEST(LocalContactSolve, AContactWithoutStiffnessIsSkipped) {
  LocalContactModel m;
  m.count = 1;
  m.contacts[0] = plane({0, 0, 1}, -0.01, 0.0);
  const auto s = solve_local_contacts(m, {0, 0, 0}, 500.0);
  EXPECT_EQ(s.active, 0u);
  EXPECT_EQ(norm3(s.force), 0.0);
}

// The press rig: the tissue block (haptics_block_scene.h) and a horizontal capsule probe driven by a scripted device
// through a HapticLoop (1 kHz on a virtual clock) and a HapticToolBridge
// (60 Hz frames): the device comes down at 20 mm/s from 2 mm above the
// top, presses 4 mm in, then holds.
constexpr double kTop = kBlockTop, kRadius = 0.005, kStart = 0.002, kSpeed = 0.020, kDepth = 0.004;
constexpr double kYoung = kBlockYoung, kPoisson = kBlockPoisson;
const Quat kHorizontal{M_SQRT1_2, 0.0, 0.0, M_SQRT1_2};  // the capsule's y axis along x

SceneDesc press_scene() {
  SceneDesc scene = block_press_scene();
  ToolDesc probe;
  probe.radius = kRadius;
  probe.half_height = 0.01;
  probe.mass = 0.3;
  probe.inertia = {1e-4, 1e-4, 1e-4};
  probe.position = {0.0, 0.0, kTop + kStart + kRadius};
  probe.rotation = kHorizontal;
  probe.gravity = false;
  scene.tools.push_back(probe);
  return scene;
}

struct PressRun {
  std::vector<TickRecord> ticks;
  double final_contact_force = 0.0;  // the physics' push on the probe at the end [N]
  LocalContactModel last_model{};
};

// The device's height below the block's top [m] at time t [s] (<= 0: above).
double device_depth(double t) {
  const double travel = std::min(kSpeed * std::max(t - 0.05, 0.0), kStart + kDepth);
  return travel - kStart;
}

PressRun run_press(bool local_contacts, double seconds) {
  PressRun out;
  const SceneDesc scene = press_scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  EXPECT_TRUE(sim.ok()) << (sim.ok() ? "" : sim.error().message());
  if (!sim.ok()) return out;
  VirtualClock clock{0};
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  ScriptedDevice device([](double t) {
    ScriptedPose p;
    p.position = {0.0, 0.0, kTop + kRadius - device_depth(t)};
    p.rotation = kHorizontal;
    return p;
  });
  HapticLoopSettings hs;
  hs.realtime = false;
  hs.coupling.damping = 3.0;
  hs.local_contacts = local_contacts;
  hs.telemetry_capacity = 4096;
  auto loop = HapticLoop::create(hs, device, snapshots, feedback, clock);
  EXPECT_TRUE(loop.ok());
  HapticToolBridge bridge(0, snapshots, feedback, clock);
  EXPECT_TRUE(bridge.set_damping(20.0, 2e-3).ok());
  if (local_contacts) {
    auto builder = haptics::LocalContactBuilder::create(scene, sim->info(), 0);
    EXPECT_TRUE(builder.ok()) << (builder.ok() ? "" : builder.error().message());
    EXPECT_TRUE(bridge.set_local_contacts(std::move(*builder)).ok());
  }
  EXPECT_TRUE(device.start(0).ok());
  EXPECT_TRUE(bridge.publish(*sim).ok());
  const int frames = int(std::lround(seconds * 60.0));
  for (int f = 1; f <= frames; ++f) {
    const std::int64_t end = std::llround(f * 1e9 / 60.0);
    for (std::int64_t t = (clock.now_ns() / kMs + 1) * kMs; t <= end; t += kMs) {
      clock.set(t);
      (void)(*loop)->tick();
    }
    clock.set(end);
    EXPECT_TRUE(bridge.apply_feedback(*sim).ok());
    EXPECT_TRUE(sim->step().ok());
    EXPECT_TRUE(bridge.publish(*sim).ok());
  }
  EXPECT_TRUE((*loop)->copy_telemetry(out.ticks).ok());
  out.final_contact_force = sim->tools().state(*sim->tools().tool(0))->contact_force[2];
  out.last_model = bridge.last_local_contacts();
  return out;
}

double seconds_of(const TickRecord& r) { return double(r.start_ns) * 1e-9; }

// The first tick at or after time t whose rendered push (+z) exceeds `force`.
double first_push(const PressRun& run, double t, double force) {
  for (const auto& r : run.ticks)
    if (seconds_of(r) >= t && r.force[2] > force) return seconds_of(r);
  return INFINITY;
}

TEST(LocalContactBuilder, PublishesTheSurfaceUnderTheProbeWithTheFramesForce) {
  const SceneDesc scene = press_scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok());
  auto b = haptics::LocalContactBuilder::create(scene, sim->info(), 0);
  ASSERT_TRUE(b.ok()) << b.error().message();
  // The flat-punch stiffness 2 r E / (1 - nu^2).
  EXPECT_NEAR(b->body_stiffness()[0], 2 * kRadius * kYoung / (1 - kPoisson * kPoisson), 1e-9);
  std::vector<float> x;
  ASSERT_TRUE(sim->read_positions(x).ok());
  ToolState tool;
  tool.position = scene.tools[0].position;
  tool.rotation = scene.tools[0].rotation;
  auto m = b->build(x, tool);
  ASSERT_GE(m.count, 1u);
  // Nearest first: the block's top, 2 mm below the probe, facing up.
  EXPECT_NEAR(m.contacts[0].normal[2], 1.0, 1e-6);
  EXPECT_NEAR(m.contacts[0].gap, kStart, 1e-6);
  EXPECT_EQ(m.contacts[0].force, 0.0);
  EXPECT_EQ(m.contacts[0].friction, scene.tools[0].dynamic_friction);
  // Pressed 1 mm in with the physics pushing 0.2 N up: the model carries it.
  tool.position[2] = kTop + kRadius - 0.001;
  tool.contact_force = {0.0, 0.0, 0.2};
  m = b->build(x, tool);
  ASSERT_GE(m.count, 1u);
  double fz = 0;
  for (std::uint64_t i = 0; i < m.count; ++i) fz += m.contacts[i].force * m.contacts[i].normal[2];
  EXPECT_NEAR(fz, 0.2, 1e-6);
  const auto s = solve_local_contacts(m, {tool.position[0], tool.position[1], tool.position[2] - 0.2 / 500.0}, 500.0);
  EXPECT_NEAR(s.force[2], 0.2, 1e-6);
  // Far from the tissue: nothing.
  tool.position[2] = 0.1;
  tool.contact_force = {};
  EXPECT_EQ(b->build(x, tool).count, 0u);
}

TEST(LocalContactBuilder, BadSettingsAndToolsAreNamed) {
  SceneDesc scene = press_scene();
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok());
  auto expect_error = [&](const haptics::LocalContactSettings& s, std::size_t tool, const char* what) {
    auto b = haptics::LocalContactBuilder::create(scene, sim->info(), tool, s);
    ASSERT_FALSE(b.ok()) << what;
    EXPECT_NE(b.error().message().find(what), std::string::npos) << b.error().message();
  };
  expect_error({.margin = 0.0}, 0, "margin");
  expect_error({.margin = NAN}, 0, "margin");
  expect_error({.stiffness = -1.0}, 0, "stiffness");
  expect_error({.touch_distance = INFINITY}, 0, "touch_distance");
  expect_error({.max_normal_angle = 4.0}, 0, "max_normal_angle");
  expect_error({.max_contacts = 0}, 0, "max_contacts");
  expect_error({.max_contacts = 9}, 0, "max_contacts");
  expect_error({}, 1, "past the scene's 1 tools");
  // A body with hand-set compliances has no E to estimate from.
  SceneDesc handset = press_scene();
  handset.tet_bodies[0].material = TetMaterial::none;
  handset.tet_bodies[0].youngs_modulus = 0.0;
  auto b = haptics::LocalContactBuilder::create(handset, sim->info(), 0, {});
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message().find("tet_bodies[0]"), std::string::npos);
  EXPECT_TRUE(haptics::LocalContactBuilder::create(handset, sim->info(), 0, {.stiffness = 100.0}).ok());
  // A bridge refuses a builder made for another tool.
  VirtualClock clock;
  SnapshotChannel sc;
  FeedbackChannel fc;
  HapticToolBridge bridge(1, sc, fc, clock);
  EXPECT_FALSE(bridge.set_local_contacts(*haptics::LocalContactBuilder::create(scene, sim->info(), 0)).ok());
}

// Contact: the device's lowest point reaches the block's top.
const double kContactTime = 0.05 + kStart / kSpeed;

TEST(LocalContactPress, TheForceRisesWithinATickOfContactAndSettlesOnThePhysics) {
  const PressRun run = run_press(true, 0.9);
  ASSERT_FALSE(run.ticks.empty());
  // Before contact nothing is rendered: the proxy is the device.
  double before = 0.0;
  for (const auto& r : run.ticks)
    if (seconds_of(r) < kContactTime - 0.001) before = std::max(before, norm3(r.force));
  EXPECT_LT(before, 1e-9);
  // After contact the push rises at once (within 2 ms).
  const double onset = first_push(run, kContactTime, 1e-3);
  std::printf("local model: contact at %.3f s, push > 1 mN at %.3f s\n", kContactTime, onset);
  EXPECT_LE(onset - kContactTime, 0.002 + 1e-9);
  // Held: the rendered force settles on the physics' contact force, without
  // oscillating by more than 5% of it once there.
  const double f_end = run.ticks.back().force[2];
  std::printf("local model: rendered %.4f N, the physics' contact force %.4f N at the end\n", f_end,
              run.final_contact_force);
  ASSERT_GT(run.final_contact_force, 0.05);
  EXPECT_NEAR(f_end, run.final_contact_force, 0.05 * run.final_contact_force);
  const double hold = 0.05 + (kStart + kDepth) / kSpeed;
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& r : run.ticks)
    if (seconds_of(r) > hold + 0.2) {
      lo = std::min(lo, r.force[2]);
      hi = std::max(hi, r.force[2]);
    }
  std::printf("local model: held force within [%.4f, %.4f] N\n", lo, hi);
  EXPECT_LE(hi - lo, 0.05 * f_end);
  // Pressing in, the push never falls back by more than 5% of the held
  // force from one tick to the next (the frames' models join smoothly).
  double drop = 0.0;
  for (std::size_t k = 1; k < run.ticks.size(); ++k)
    if (seconds_of(run.ticks[k]) > kContactTime && seconds_of(run.ticks[k]) < hold)
      drop = std::max(drop, run.ticks[k - 1].force[2] - run.ticks[k].force[2]);
  std::printf("local model: largest fall of the push while pressing %.4f N\n", drop);
  EXPECT_LE(drop, 0.05 * f_end);
}

TEST(LocalContactPress, TheRenderingCreatesNoEnergyOverAnyHundredTicks) {
  // The energy the hand put in over a window (work against the commanded
  // force, zero-order hold) minus what the coupling and the planes store
  // more at its end must not be negative: nothing handed back that was not put in.
  const PressRun run = run_press(true, 0.9);
  ASSERT_GT(run.ticks.size(), 200u);
  const auto& t = run.ticks;
  std::vector<double> put_in(t.size(), 0.0);  // cumulative
  for (std::size_t k = 1; k < t.size(); ++k) {
    double w = 0.0;
    for (int i = 0; i < 3; ++i) w -= t[k - 1].force[i] * (t[k].device_position[i] - t[k - 1].device_position[i]);
    put_in[k] = put_in[k - 1] + w;
  }
  double worst = INFINITY;
  for (std::size_t k = 100; k < t.size(); ++k) {
    const double created = (t[k].contact_energy - t[k - 100].contact_energy) - (put_in[k] - put_in[k - 100]);
    worst = std::min(worst, -created);
  }
  std::printf("local model: least energy kept over a 100-tick window %.3e J\n", worst);
  EXPECT_GE(worst, -1e-6);
}

TEST(LocalContactPress, WithoutTheModelTheHandFeelsTheLagNotTheTissue) {
  // The same press rendered by the spring to the interpolated tool: before
  // contact the hand already feels the coupling's pull towards the tool
  // lagging behind it, and the push overshoots the tissue's held force; with
  // the model the hand feels nothing until contact and then the tissue,
  // within 5% of the held force.
  const PressRun with = run_press(true, 0.6), without = run_press(false, 0.6);
  auto overshoot = [](const PressRun& run) {
    double peak = 0.0;
    for (const auto& r : run.ticks) peak = std::max(peak, r.force[2]);
    return peak / run.ticks.back().force[2] - 1.0;
  };
  auto before_contact = [](const PressRun& run) {
    double f = 0.0;
    for (const auto& r : run.ticks)
      if (seconds_of(r) < kContactTime) f = std::max(f, norm3(r.force));
    return f;
  };
  std::printf("before contact: %.3f N with the local model, %.3f N without; overshoot of the held force: %.1f%% "
              "with, %.1f%% without\n",
              before_contact(with), before_contact(without), 100 * overshoot(with), 100 * overshoot(without));
  EXPECT_LE(overshoot(with), 0.05);
  EXPECT_GT(overshoot(without), overshoot(with));
  EXPECT_GT(before_contact(without), 0.1);
}

}  // namespace
}  // namespace sinew::test
