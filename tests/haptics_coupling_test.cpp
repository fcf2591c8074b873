// The virtual coupling (Colgate, Stanley, Brown 1995): the formula and its
// sign by hand, and passivity over a closed scripted cycle against a static
// contact, on a virtual clock.
#include <gtest/gtest.h>

#include <cmath>

#include "haptics_test_support.h"
#include "sinew/haptics/virtual_coupling.h"

namespace {

using namespace sinew::test;

TEST(HapticsCoupling, SpringDamperByHandAndItsSign) {
  CouplingParams p;
  p.stiffness = 400.0;
  p.damping = 2.0;
  p.rotational_stiffness = 0.1;
  p.rotational_damping = 0.01;
  VirtualCoupling c(p);
  DeviceSample d;
  d.position = {0.0, 0.0, 0.0};
  d.velocity = {0.1, 0.0, 0.0};
  RenderedTool t;
  t.mode = RenderMode::interpolated;
  t.position = {0.002, -0.001, 0.0};
  t.velocity = {0.0, 0.05, 0.0};
  const double a = 0.1;  // the tool turned 0.1 rad about z relative to the device
  t.rotation = {std::cos(a / 2), 0.0, 0.0, std::sin(a / 2)};
  t.angular_velocity = {0.0, 0.0, 1.0};
  const CouplingOutput o = c.raw(d, t);
  // F_device = K (x_tool - x_dev) + B (v_tool - v_dev): the hand is pulled towards the tool.
  EXPECT_NEAR(o.raw_force[0], 400.0 * 0.002 + 2.0 * (0.0 - 0.1), 1e-12);
  EXPECT_NEAR(o.raw_force[1], 400.0 * -0.001 + 2.0 * 0.05, 1e-12);
  EXPECT_NEAR(o.raw_force[2], 0.0, 1e-12);
  EXPECT_NEAR(o.raw_torque[2], 0.1 * a + 0.01 * 1.0, 1e-12);
  EXPECT_NEAR(o.raw_torque[0], 0.0, 1e-12);
  // Through the chain at gain 1, below every limit: unchanged.
  CouplingParams loose = p;
  loose.max_force_change = 100;
  loose.max_torque_change = 100;
  VirtualCoupling c2(loose);
  const CouplingOutput e = c2.evaluate(d, t, 1.0);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(e.force[k], o.raw_force[k]);
  // No tool state: no force.
  const CouplingOutput none = c2.evaluate(d, RenderedTool{}, 1.0);
  EXPECT_EQ(none.raw_force, (Vec3{0, 0, 0}));
}

// Energy delivered to the device over whole cycles of a circle of radius A
// at f Hz, centred `depth` below a static tool (pressed into it throughout):
// the exact work of the zero-order-hold force along the device's path,
// sum over ticks of F_k . (x(t_{k+1}) - x(t_k)).
double cycle_energy(double damping, int cycles, double* dissipation_scale = nullptr) {
  const double A = 0.002, f = 2.0, depth = 0.003, w = 2 * M_PI * f;
  auto path = [=](double t) {
    ScriptedPose p;
    p.position = {A * std::cos(w * t), -depth + A * std::sin(w * t), 0.0};
    return p;
  };
  ScriptedDevice device(path);
  HapticLoopSettings s;
  s.coupling.damping = damping;
  VirtualRig rig(device, s);  // the tool sits at the origin, at rest: a static contact
  rig.run(1000);              // the watchdog ramps up; 1 s = 2 whole cycles
  double energy = 0.0;
  const int ticks = static_cast<int>(std::lround(cycles / f * 1000));
  for (int i = 0; i < ticks; ++i) {
    const double t0 = ns_to_seconds(rig.clock.now_ns());
    const TickRecord r = rig.step();
    EXPECT_DOUBLE_EQ(r.gain, 1.0);
    EXPECT_FALSE(r.flags & (kClamped | kSlewLimited)) << "the limits stay out of it";
    const Vec3 x0 = path(t0).position, x1 = path(t0 + 0.001).position;
    for (int k = 0; k < 3; ++k) energy += r.force[k] * (x1[k] - x0[k]);
  }
  // Sampling a spring adds K T / 2 of negative damping: per cycle about
  // (K T / 2) * integral |v|^2 dt = (K T / 2) (A w)^2 / f.
  if (dissipation_scale) *dissipation_scale = cycles * (A * w) * (A * w) / f;
  return energy;
}

TEST(HapticsCoupling, PassiveOverAClosedCycleAgainstAStaticContact) {
  const CouplingParams defaults;
  double scale = 0.0;
  const double e = cycle_energy(defaults.damping, 5, &scale);
  // Passive: the device gives energy to the coupling, never the reverse
  // (bound: 1 uJ over 5 cycles, against ~2.4e-4 J dissipated).
  EXPECT_LT(e, 1e-6) << "energy delivered to the device [J]";
  // The expected dissipation, (B - K T / 2) per unit of integral |v|^2 dt:
  const double k_t_2 = defaults.stiffness * 0.001 / 2;
  EXPECT_NEAR(e, -(defaults.damping - k_t_2) * scale, 0.1 * defaults.damping * scale);
  // The bound has teeth: without damping the sampled spring is active by
  // about K T / 2 and breaks it.
  const double active = cycle_energy(0.0, 5);
  EXPECT_GT(active, 1e-5);
  EXPECT_NEAR(active, k_t_2 * scale, 0.1 * k_t_2 * scale);
  std::printf("[ measured ] energy to the device over 5 cycles: %.3g J with B = %.3g N s/m, %.3g J with B = 0 "
              "(K T / 2 predicts %.3g J)\n", e, defaults.damping, active, k_t_2 * scale);
}

}  // namespace
