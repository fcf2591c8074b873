// damping_test.cpp — the two damping parameters of a body (include/sinew/scene.h):
// velocity damping k [1/s] and constraint (stiffness-proportional) damping
// tau [s] of XPBD eq. 26 (Macklin, Müller, Chentanez, MIG 2016). Each decays
// motion at the rate its documentation predicts, neither ever adds energy,
// and bad values are errors naming the parameter. On every backend.
//
// Predictions for a mass m on a spring k (omega^2 = k / m), from the damped
// oscillator x'' + 2 sigma x' + omega^2 x = 0, amplitude ~ exp(-sigma t):
//  - velocity damping k_v: a drag force -k_v m v, so sigma = k_v / 2;
//  - constraint damping tau: XPBD's beta is a damping coefficient along the
//    constraint gradient, beta = tau k here, so sigma = beta / (2 m) =
//    tau omega^2 / 2.
// Implicit Euler damps by itself too (~omega^2 h / 2 for small h): each test
// measures that in an undamped run and compares the difference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "test_support.h"

namespace sinew {
namespace {

class Damping : public test::BackendTest {};

constexpr double kMass = 0.01;   // [kg]
constexpr double kOmega = 20.0;  // [rad/s]: 3.2 Hz
constexpr double kRest = 0.1;    // [m]
constexpr double kStretch = 0.01;  // initial stretch [m]

// A particle on a spring to a pinned one, along x, released stretched, no
// gravity: a one-dimensional oscillator (the distance constraint stays
// linear along its line), `substeps` of 1 iteration per 60 Hz frame.
SceneDesc spring(double velocity_damping, double stiffness_damping, int substeps = 100) {
  SceneDesc scene;
  scene.gravity = {0, 0, 0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = substeps, .iterations = 1};
  LineBodyDesc body;
  body.vertices = {{0, 0, 0}, {kRest, 0, 0}};
  body.initial_vertices = {{0, 0, 0}, {kRest + kStretch, 0, 0}};
  body.masses = {1.0, kMass};
  body.segments = {{0, 1}};
  body.compliance = 1.0 / (kOmega * kOmega * kMass);  // alpha = 1 / k [m/N]
  body.pinned = {0};
  body.velocity_damping = velocity_damping;
  body.stiffness_damping = stiffness_damping;
  scene.line_bodies.push_back(body);
  return scene;
}

struct Trace {
  std::vector<double> stretch;  // [m] per frame
  std::vector<double> energy;   // kinetic + spring [J] per frame
};

Trace run(const SceneDesc& scene, const std::string& backend, int frames) {
  Trace t;
  auto sim = test::create_or_skip(scene, backend);
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  if (!sim.ok()) return t;
  std::vector<float> x, v;
  const double k = kOmega * kOmega * kMass;
  for (int f = 0; f < frames; ++f) {
    EXPECT_TRUE(sim->step().ok());
    EXPECT_TRUE(sim->read_positions(x).ok());
    EXPECT_TRUE(sim->read_velocities(v).ok());
    const double s = double(x[4]) - x[0] - kRest;
    const double speed2 = double(v[4]) * v[4] + double(v[5]) * v[5] + double(v[6]) * v[6];
    t.stretch.push_back(s);
    t.energy.push_back(0.5 * kMass * speed2 + 0.5 * k * s * s);
  }
  return t;
}

// The decay rate sigma [1/s] of the amplitude: a least-squares line through
// log |peak| against time, over the peaks of |stretch| (local maxima).
double decay_rate(const std::vector<double>& s, double dt) {
  double n = 0, st = 0, sy = 0, stt = 0, sty = 0;
  for (std::size_t i = 1; i + 1 < s.size(); ++i) {
    const double a = std::abs(s[i]);
    // Peaks down to a tenth of the start: below that, float rounding of the
    // positions (~1e-8 m per substep) becomes a visible part of the motion.
    if (a < std::abs(s[i - 1]) || a < std::abs(s[i + 1]) || a < 0.1 * kStretch) continue;
    const double t = double(i + 1) * dt, y = std::log(a);
    n += 1, st += t, sy += y, stt += t * t, sty += t * y;
  }
  if (n < 4) return std::nan("");
  return -(n * sty - st * sy) / (n * stt - st * st);
}

TEST_P(Damping, VelocityDampingDecaysTheOscillationAtHalfItsRate) {
  const double k_v = 3.0;  // [1/s]: predicted sigma 1.5 1/s
  const Trace undamped = run(spring(0.0, 0.0), GetParam(), 150);
  const Trace damped = run(spring(k_v, 0.0), GetParam(), 150);
  const double sigma0 = decay_rate(undamped.stretch, 1.0 / 60.0), sigma = decay_rate(damped.stretch, 1.0 / 60.0);
  EXPECT_NEAR(sigma - sigma0, k_v / 2, 0.05 * k_v / 2) << "measured " << sigma << ", undamped " << sigma0;
  std::printf("[ damping  ] %s velocity damping %.1f 1/s: decay %.4f 1/s (+%.4f undamped), predicted %.4f\n",
              GetParam().c_str(), k_v, sigma - sigma0, sigma0, k_v / 2);
}

TEST_P(Damping, ConstraintDampingDecaysTheOscillationAtTauOmegaSquaredOverTwo) {
  const double tau = 0.004;  // [s]: predicted sigma = tau omega^2 / 2 = 0.8 1/s
  const Trace undamped = run(spring(0.0, 0.0), GetParam(), 150);
  const Trace damped = run(spring(0.0, tau), GetParam(), 150);
  const double sigma0 = decay_rate(undamped.stretch, 1.0 / 60.0), sigma = decay_rate(damped.stretch, 1.0 / 60.0);
  const double predicted = tau * kOmega * kOmega / 2;
  EXPECT_NEAR(sigma - sigma0, predicted, 0.05 * predicted) << "measured " << sigma << ", undamped " << sigma0;
  std::printf("[ damping  ] %s constraint damping %.3f s: decay %.4f 1/s (+%.4f undamped), predicted %.4f\n",
              GetParam().c_str(), tau, sigma - sigma0, sigma0, predicted);
}

TEST_P(Damping, NeverAddsEnergy) {
  // From light to extreme (gamma = tau / h up to 600), each kind alone and
  // both: the oscillator's energy never rises from frame to frame (a
  // relative 1e-6 of float rounding allowed), and damping takes more than
  // the integrator alone does. 10 substeps: with 100, a substep's spring
  // correction of a nearly settled oscillator is ~1 ulp of its 0.1 m
  // position, and the rounding, not the physics, moves its energy.
  const Trace undamped = run(spring(0.0, 0.0, 10), GetParam(), 60);
  for (auto [k_v, tau] : {std::pair{0.5, 0.0}, std::pair{50.0, 0.0}, std::pair{0.0, 1e-3}, std::pair{0.0, 1.0},
                          std::pair{5.0, 0.01}}) {
    const Trace t = run(spring(k_v, tau, 10), GetParam(), 60);
    ASSERT_EQ(t.energy.size(), 60u);
    for (std::size_t f = 1; f < t.energy.size(); ++f)
      ASSERT_LE(t.energy[f], t.energy[f - 1] * (1 + 1e-6) + 1e-15)
          << "frame " << f << ", velocity damping " << k_v << ", stiffness damping " << tau;
    EXPECT_LT(t.energy.back(), undamped.energy.back()) << "velocity damping " << k_v << ", stiffness damping " << tau;
  }
}

TEST_P(Damping, VelocityDampingLeavesTheStaticSagUnchanged) {
  // The spring hung vertically under gravity at one substep per frame: it
  // comes to rest stretched by m g / k, damped or not. (Damping gravity's
  // impulse along with the velocity balanced d m g instead: 39% less
  // stretch at k_v = 30 1/s, d = exp(-k_v h) = 0.61.)
  const double k = kOmega * kOmega * kMass;
  const double expected = kMass * 9.81 / k;  // [m]
  for (double velocity_damping : {0.0, 30.0}) {
    SceneDesc scene = spring(velocity_damping, 0.0, 1);
    scene.gravity = {0, -9.81, 0};
    auto& body = scene.line_bodies[0];
    body.vertices = {{0, 0, 0}, {0, -kRest, 0}};
    body.initial_vertices.clear();
    auto sim = test::create_or_skip(scene, GetParam());
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    for (int f = 0; f < 300; ++f) ASSERT_TRUE(sim->step().ok());
    std::vector<float> x;
    ASSERT_TRUE(sim->read_positions(x).ok());
    EXPECT_NEAR(-double(x[5]) - kRest, expected, 0.005 * expected) << "velocity_damping " << velocity_damping;
  }
}

TEST_P(Damping, VelocityDampingGivesFallsATerminalSpeed) {
  // A free tet falling from rest under gravity with drag k: v = g/k (1 - e^-kt).
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 1};
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 1, .ny = 1, .nz = 1, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
  body.velocity_damping = 2.0;
  scene.tet_bodies.push_back(body);
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  for (int f = 0; f < 60; ++f) ASSERT_TRUE(sim->step().ok());
  std::vector<float> v;
  ASSERT_TRUE(sim->read_velocities(v).ok());
  const double expected = -9.81 / 2.0 * (1 - std::exp(-2.0 * 1.0));
  for (std::size_t p = 0; p < v.size() / 4; ++p) {
    EXPECT_NEAR(v[4 * p + 1], expected, 0.01 * std::abs(expected)) << "particle " << p;
    EXPECT_EQ(v[4 * p + 3], 0.0f) << "read_velocities' w is 0";
  }
}

TEST_P(Damping, BadValuesAreErrorsNamingTheParameter) {
  for (double bad : {-1.0, std::nan(""), double(INFINITY)}) {
    SceneDesc scene = spring(bad, 0.0);
    auto made = test::create_or_skip(scene, GetParam());
    ASSERT_FALSE(made.ok());
    EXPECT_NE(made.error().message().find("line_bodies[0].velocity_damping"), std::string::npos)
        << made.error().message();
    scene = spring(0.0, bad);
    made = test::create_or_skip(scene, GetParam());
    ASSERT_FALSE(made.ok());
    EXPECT_NE(made.error().message().find("line_bodies[0].stiffness_damping"), std::string::npos)
        << made.error().message();
  }
  SceneDesc tet;
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 1, .ny = 1, .nz = 1});
  body.stiffness_damping = -0.1;
  tet.tet_bodies.push_back(body);
  auto made = test::create_or_skip(tet, GetParam());
  ASSERT_FALSE(made.ok());
  EXPECT_NE(made.error().message().find("tet_bodies[0].stiffness_damping"), std::string::npos);
}

TEST_P(Damping, BodiesWithDifferentDampingGetTheirOwnBlocks) {
  // Two blocks, one damped: the damped one settles, the undamped one keeps
  // swinging; the colours of each block are counted once per block.
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 1};
  for (double tau : {0.0, 0.05}) {
    TetBodyDesc body;
    body.mesh = *make_tet_grid(
        {.nx = 6, .ny = 2, .nz = 2, .origin = {0, 0, tau > 0 ? 0.1 : 0.0}, .cell_size = {0.01, 0.01, 0.01}});
    EXPECT_TRUE(body.set_elastic(2e4, 0.3).ok());
    body.stiffness_damping = tau;
    for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
      if (body.mesh.vertices[v][0] < 1e-9) body.pinned.push_back(v);
    scene.tet_bodies.push_back(body);
  }
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  std::vector<double> tip[2];
  std::vector<float> x;
  const std::uint32_t corner = 6;  // vertex (6, 0, 0): the free end
  for (int f = 0; f < 90; ++f) {
    ASSERT_TRUE(sim->step().ok());
    ASSERT_TRUE(sim->read_positions(x).ok());
    for (int b = 0; b < 2; ++b) tip[b].push_back(x[4 * (sim->info().tet_body_first_particle[b] + corner) + 1]);
  }
  auto swing = [](const std::vector<double>& y) {  // peak-to-peak over the last 30 frames
    const auto [lo, hi] = std::minmax_element(y.end() - 30, y.end());
    return *hi - *lo;
  };
  EXPECT_LT(swing(tip[1]), 0.2 * swing(tip[0])) << "damped " << swing(tip[1]) << " m, undamped " << swing(tip[0]);
}

INSTANTIATE_TEST_SUITE_P(Backends, Damping, ::testing::ValuesIn(test::backends()), test::backend_name);

}  // namespace
}  // namespace sinew
