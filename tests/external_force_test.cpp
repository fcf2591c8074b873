// Per-particle external forces (SceneDesc::external_forces,
// Simulation::set_particle_forces), on every built backend, against
// physics: a constant total force F on a free body gives it momentum F T
// and moves its centre of mass by F T^2 / (2 M) (to the substeps'
// discretisation); forces act for one frame; pinned particles ignore them;
// the impulse is damped like any velocity; the residual-driven mode's
// re-assembled frame keeps the force stage; GPU backends agree with the CPU,
// kernel by kernel and scene by scene. Bad input is an error naming it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <variant>
#include <vector>

#include "agreement_support.h"
#include "compiler/scene_compiler.h"
#include "runtime/simulation_internals.h"
#include "test_support.h"

namespace sinew {
namespace {

class ExternalForce : public test::BackendTest {};

constexpr double kFrame = 1.0 / 60.0;  // [s]

std::vector<float> positions(const Simulation& sim) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  return x;
}

std::vector<float> velocities(const Simulation& sim) {
  std::vector<float> v;
  EXPECT_TRUE(sim.read_velocities(v).ok());
  return v;
}

// What the body's particles add up to, in double from the read-back floats.
struct BodySums {
  double mass = 0.0;                     // M [kg]
  std::array<double, 3> momentum{};      // sum m v [kg m/s]
  std::array<double, 3> centre{};        // sum m x / M [m]
};

BodySums sums(const Simulation& sim) {
  const std::vector<float> x = positions(sim), v = velocities(sim);
  BodySums s;
  for (std::size_t p = 0; p < x.size() / 4; ++p) {
    if (x[4 * p + 3] <= 0.0f) continue;  // immovable: no mass to count
    const double m = 1.0 / double(x[4 * p + 3]);
    s.mass += m;
    for (int k = 0; k < 3; ++k) {
      s.momentum[k] += m * v[4 * p + k];
      s.centre[k] += m * x[4 * p + k];
    }
  }
  for (double& c : s.centre) c /= s.mass;
  return s;
}

double norm(const std::array<double, 3>& a) { return std::hypot(a[0], a[1], a[2]); }

// A free soft box (no pins) floating without gravity, forces on.
SceneDesc free_box(int substeps, int iterations) {
  TetBodyDesc body;
  body.mesh = test::box_mesh(3, 3, 3, 0.01);
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver = {.time_step = kFrame, .substeps = substeps, .iterations = iterations};
  scene.tet_bodies.push_back(body);
  scene.external_forces = true;
  return scene;
}

// The total force F spread evenly over the particles (not by mass: the
// light corner particles accelerate faster, so the constraints must pass
// momentum between particles, and the test sees whether they conserve it).
std::vector<float> spread(const std::array<double, 3>& total, std::size_t particles) {
  std::vector<float> f(3 * particles);
  for (std::size_t p = 0; p < particles; ++p)
    for (int k = 0; k < 3; ++k) f[3 * p + k] = static_cast<float>(total[k] / double(particles));
  return f;
}

TEST_P(ExternalForce, ConstantForceGivesMomentumFTAndMovesTheCentreOfMassFT2Over2M) {
  const int substeps = 4, frames = 30;
  const std::array<double, 3> F{0.02, -0.01, 0.005};  // [N] on a 27 g box: ~0.8 m/s^2
  auto sim = test::create_or_skip(free_box(substeps, 2), GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const BodySums start = sums(*sim);
  const std::vector<float> f = spread(F, sim->info().particles);
  for (int frame = 0; frame < frames; ++frame) {
    SINEW_ASSERT_OK(sim->set_particle_forces(f));  // forces act for one frame: set them every frame
    SINEW_ASSERT_OK(sim->step());
  }
  const BodySums end = sums(*sim);
  const double T = frames * kFrame, M = start.mass;
  // Every substep adds h f / m to each particle's velocity (the floats
  // handed over sum to F within ~1e-7), and the constraints only pass
  // momentum between particles, up to the rounding of float positions:
  // ~ulp(0.1 m) / h = 4e-6 m/s per particle and substep, times 0.4 g, in
  // random directions over 64 particles and 120 substeps, ~1e-5 of F T
  // (measured 2.3e-5, the same bits on cpu, PoCL and lavapipe). 1e-4 of
  // |F| T is above that and far below a lost or doubled substep (1 / 120).
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(end.momentum[k], F[k] * T, 1e-4 * norm(F) * T) << "momentum component " << k;
  // The centre of mass: the constraints' mass-weighted corrections do not
  // move it, so it follows symplectic Euler with the acceleration F / M:
  // after n = frames x substeps substeps of h it moved a h^2 n (n + 1) / 2
  // = (F T^2 / (2 M)) (1 + 1 / n). So it matches F T^2 / (2 M) within the
  // discretisation error 1 / n relative (n = 120: 0.8%), and that discrete
  // value within 1e-4 (float rounding, as for the momentum; measured 2.6e-5).
  const double n = double(frames) * substeps;
  for (int k = 0; k < 3; ++k) {
    const double moved = end.centre[k] - start.centre[k];
    const double continuous = F[k] * T * T / (2.0 * M);
    const double scale = norm(F) * T * T / (2.0 * M);
    EXPECT_NEAR(moved, continuous, (1.0 / n + 1e-4) * scale) << "centre of mass, component " << k;
    EXPECT_NEAR(moved, continuous * (1.0 + 1.0 / n), 1e-4 * scale) << "centre of mass, component " << k;
  }
  std::printf("[ force    ] %s: momentum error %.2e of F T; centre of mass moved %.6e m (F T^2 / 2M %.6e m)\n",
              GetParam().c_str(),
              std::hypot(end.momentum[0] - F[0] * T, end.momentum[1] - F[1] * T, end.momentum[2] - F[2] * T) /
                  (norm(F) * T),
              std::hypot(end.centre[0] - start.centre[0], end.centre[1] - start.centre[1],
                         end.centre[2] - start.centre[2]),
              norm(F) * T * T / (2.0 * M));
}

TEST_P(ExternalForce, ForcesActForOneFrameAndACallReplacesTheLast) {
  const std::array<double, 3> F{0.0, 0.03, -0.01};  // [N]
  auto sim = test::create_or_skip(free_box(3, 2), GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const std::size_t n = sim->info().particles;
  // The second call replaces the first: one frame under F, not 3 F.
  SINEW_ASSERT_OK(sim->set_particle_forces(spread({2 * F[0], 2 * F[1], 2 * F[2]}, n)));
  SINEW_ASSERT_OK(sim->set_particle_forces(spread(F, n)));
  SINEW_ASSERT_OK(sim->step());
  const BodySums one = sums(*sim);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(one.momentum[k], F[k] * kFrame, 1e-4 * norm(F) * kFrame) << k;
  // Frames without a call add nothing: the momentum stays. The constraints
  // pass it between particles up to the rounding of float positions,
  // ~ulp(3 cm) / h = 7e-7 m/s per particle and substep, times 0.4 g, in
  // random directions over 64 particles and 9 substeps: ~1e-8 kg m/s, 2e-5
  // of what one frame's force gave (measured 9e-9); 1e-4 of it is the
  // tolerance, a frame with the force still on would add 1.
  for (int frame = 0; frame < 3; ++frame) SINEW_ASSERT_OK(sim->step());
  const BodySums later = sums(*sim);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(later.momentum[k], one.momentum[k], 1e-4 * norm(F) * kFrame) << "component " << k;
  // And the body keeps drifting at the velocity the one frame gave it.
  EXPECT_GT(std::abs(later.centre[1] - one.centre[1]), 0.5 * 3 * kFrame * F[1] * kFrame / one.mass);
}

TEST_P(ExternalForce, ForceMovesOnlyItsParticleAndNotPinnedOnes) {
  // A body so soft (E ~ 1e-6 Pa) that its constraints barely act within a
  // frame: each particle takes only its own force, through the device's
  // particle order (reverse Cuthill-McKee, which the API hides).
  TetBodyDesc body;
  body.mesh = test::box_mesh(3, 3, 3, 0.01);
  body.distance_compliance = 1e6;  // [1/Pa]
  body.volume_compliance = 1e6;
  body.pinned = {5};
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver = {.time_step = kFrame, .substeps = 5, .iterations = 1};
  scene.tet_bodies.push_back(body);
  scene.external_forces = true;
  auto compiled = compile_scene(scene);
  ASSERT_TRUE(compiled.ok()) << compiled.error().message();
  ASSERT_FALSE(compiled->order.identity()) << "the test must see a permuted device order";
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const std::size_t n = sim->info().particles;
  std::vector<float> f(3 * n, 0.0f);
  f[3 * 2 + 0] = 1e-3f;    // particle 2 [N]
  f[3 * 40 + 2] = -5e-4f;  // particle 40
  f[3 * 5 + 1] = 9.0f;     // particle 5, pinned: ignored
  const std::vector<float> x0 = positions(*sim);
  SINEW_ASSERT_OK(sim->set_particle_forces(f));
  SINEW_ASSERT_OK(sim->step());
  const std::vector<float> v = velocities(*sim), x = positions(*sim);
  // Five substeps each add h f / m: v = dt f / m. The constraints take
  // ~1e-9 of it back (their alpha~ = alpha / h^2 dwarfs w |grad C|^2).
  for (std::size_t p : {std::size_t{2}, std::size_t{40}})
    for (int k = 0; k < 3; ++k) {
      const double expected = kFrame * f[3 * p + k] / (1.0 / x0[4 * p + 3]);
      EXPECT_NEAR(v[4 * p + k], expected, 1e-5 * (std::abs(expected) + 1e-3)) << "particle " << p << " component " << k;
    }
  for (std::size_t p = 0; p < n; ++p) {
    if (p == 2 || p == 40) continue;
    for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(v[4 * p + k]), 1e-7) << "particle " << p << " component " << k;
  }
  for (int k = 0; k < 4; ++k) EXPECT_EQ(x[4 * 5 + k], x0[4 * 5 + k]) << "the pinned particle moved";
}

TEST_P(ExternalForce, ImpulsePassesThroughTheVelocityDamping) {
  // One free particle, velocity damping k: each substep v = d (v + h a)
  // with d = exp(-k h), so after n substeps v = h a d (1 - d^n) / (1 - d)
  // (where gravity's impulse, not damped, would give h g (1 - d^n) / (1 - d)).
  const double k = 30.0, m = 0.2, force = 0.4;  // [1/s], [kg], [N]
  const int substeps = 6;
  LineBodyDesc dot;
  dot.vertices = {{0.0, 0.0, 0.0}};
  dot.masses = {m};
  dot.velocity_damping = k;
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver = {.time_step = kFrame, .substeps = substeps, .iterations = 1};
  scene.line_bodies.push_back(dot);
  scene.external_forces = true;
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  SINEW_ASSERT_OK(sim->set_particle_forces(std::vector<float>{0.0f, 0.0f, float(force)}));
  SINEW_ASSERT_OK(sim->step());
  const double h = kFrame / substeps, d = std::exp(-k * h), a = force / m;
  const double expected = h * a * d * (1.0 - std::pow(d, substeps)) / (1.0 - d);
  EXPECT_NEAR(velocities(*sim)[2], expected, 1e-5 * expected);
}

TEST_P(ExternalForce, ProgramHasTheForceStageOnlyWhenTheSceneAsksForIt) {
  SceneDesc scene = free_box(3, 2);
  auto with = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(with.ok()) << with.error().message();
  const FrameProgram& program = SimulationInternals::program(*with);
  EXPECT_EQ(program.dispatch_count(Kernel::xpbd_external_force), 3u) << "one per substep";
  scene.external_forces = false;
  auto without = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(without.ok()) << without.error().message();
  EXPECT_EQ(SimulationInternals::program(*without).dispatch_count(Kernel::xpbd_external_force), 0u);
  EXPECT_EQ(SimulationInternals::program(*with).dispatch_count(),
            SimulationInternals::program(*without).dispatch_count() + 3u);
}

// The residual-driven mode cuts the frame program into per-substep pieces
// (program/solve_programs.h); the force stage rides in front of each
// substep's predict. With a tolerance met at the first check, the
// re-assembled frame is bitwise the fixed one.
TEST_P(ExternalForce, ResidualModeAppliesTheForcesLikeTheFixedMode) {
  SceneDesc fixed = free_box(3, 2);
  SceneDesc residual = fixed;
  residual.solver.residual_tolerance = 1e30;  // met at the first check: `iterations` sweeps, as fixed
  std::vector<float> x[2];
  int r = 0;
  for (const SceneDesc* scene : {&fixed, &residual}) {
    auto sim = test::create_or_skip(*scene, GetParam());
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    const std::size_t n = sim->info().particles;
    std::vector<float> f(3 * n);
    for (std::size_t p = 0; p < n; ++p) f[3 * p + p % 3] = 1e-3f * float(1 + p % 5);  // uneven: the body deforms
    for (int frame = 0; frame < 10; ++frame) {
      if (frame % 3 != 2) SINEW_ASSERT_OK(sim->set_particle_forces(f));
      SINEW_ASSERT_OK(sim->step());
    }
    if (scene == &residual) {
      EXPECT_EQ(sim->last_frame().stop, SolveStop::converged);
      // Each substep: the forces, a barrier, then its predict.
      const auto& commands = SimulationInternals::program(*sim).commands();
      int forces = 0;
      for (std::size_t c = 0; c < commands.size(); ++c) {
        const auto* d = std::get_if<Dispatch>(&commands[c]);
        if (!d || d->kernel != Kernel::xpbd_external_force) continue;
        ++forces;
        ASSERT_LT(c + 2, commands.size());
        const auto* next = std::get_if<Dispatch>(&commands[c + 2]);
        EXPECT_TRUE(std::holds_alternative<Barrier>(commands[c + 1]));
        EXPECT_TRUE(next && next->kernel == Kernel::xpbd_predict) << "the forces of a substep precede its predict";
      }
      EXPECT_EQ(forces, 3);
    }
    x[r++] = positions(*sim);
  }
  ASSERT_EQ(x[0].size(), x[1].size());
  EXPECT_EQ(0, std::memcmp(x[0].data(), x[1].data(), x[0].size() * sizeof(float)));
}

TEST_P(ExternalForce, BadInputIsAnErrorNamingIt) {
  SceneDesc scene = free_box(2, 1);
  scene.external_forces = false;
  auto off = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(off.ok()) << off.error().message();
  const std::size_t n = off->info().particles;
  Status s = off->set_particle_forces(std::vector<float>(3 * n, 0.0f));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::bad_parameter);
  EXPECT_NE(s.error().message().find("SceneDesc::external_forces"), std::string::npos) << s.error().message();

  scene.external_forces = true;
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  for (std::size_t size : {std::size_t{0}, 3 * n - 1, 4 * n}) {
    s = sim->set_particle_forces(std::vector<float>(size, 0.0f));
    ASSERT_FALSE(s.ok()) << size << " floats";
    EXPECT_EQ(s.error().code(), ErrorCode::bad_parameter);
    EXPECT_NE(s.error().message().find(std::to_string(3 * n)), std::string::npos) << s.error().message();
  }
  // A non-finite value names its particle; the forces set before stay.
  const std::array<double, 3> F{0.01, 0.0, 0.0};
  SINEW_ASSERT_OK(sim->set_particle_forces(spread(F, n)));
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    std::vector<float> f(3 * n, 0.0f);
    f[3 * 17 + 1] = bad;
    s = sim->set_particle_forces(f);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code(), ErrorCode::bad_parameter);
    EXPECT_NE(s.error().message().find("particle 17"), std::string::npos) << s.error().message();
  }
  SINEW_ASSERT_OK(sim->step());
  EXPECT_NEAR(sums(*sim).momentum[0], F[0] * kFrame, 1e-4 * F[0] * kFrame) << "the valid call's forces acted";
}

// Scene by scene: a pinned block pushed by forces that change every frame,
// against the CPU reference (on "cpu": one thread against the team). The
// GPU kernels round like the CPU ones (no fused multiply-add), so PoCL and
// lavapipe agree bitwise; 1e-6 of the block's size leaves room for a GPU
// whose sqrt or division differs in the last bit, grown over 60 frames.
TEST_P(ExternalForce, BackendsAgreeWithTheCpuAfter60Frames) {
  TetBodyDesc body;
  body.mesh = test::box_mesh(4, 3, 3, 0.01);
  SINEW_ASSERT_OK(body.set_elastic(3e4, 0.45));
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver = {.time_step = kFrame, .substeps = 4, .iterations = 3};
  scene.tet_bodies.push_back(body);
  scene.external_forces = true;
  std::vector<float> x[2];
  for (int run = 0; run < 2; ++run) {
    auto sim = run == 0 ? test::create_or_skip(scene, "cpu", 1) : test::create_or_skip(scene, GetParam());
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    const std::size_t n = sim->info().particles;
    std::mt19937 rng(7);  // the same forces on both runs
    std::uniform_real_distribution<float> u(-2e-3f, 2e-3f);  // [N]
    for (int frame = 0; frame < 60; ++frame) {
      std::vector<float> f(3 * n);
      for (float& c : f) c = u(rng);
      if (frame % 4 != 3) SINEW_ASSERT_OK(sim->set_particle_forces(f));
      SINEW_ASSERT_OK(sim->step());
    }
    x[run] = positions(*sim);
  }
  ASSERT_EQ(x[0].size(), x[1].size());
  double worst = 0.0;
  std::size_t differ = 0;
  for (std::size_t i = 0; i < x[0].size(); i += 4) {
    worst = std::max(worst, std::hypot(double(x[0][i]) - x[1][i], double(x[0][i + 1]) - x[1][i + 1],
                                       double(x[0][i + 2]) - x[1][i + 2]));
    differ += std::memcmp(&x[0][i], &x[1][i], 16) != 0 ? 1 : 0;
  }
  const double size = 0.04;  // [m], the block's longest side
  EXPECT_LT(worst, 1e-6 * size) << "largest position difference " << worst << " m";
  std::printf("[ agree    ] forces, 60 frames, %s vs cpu: %zu of %zu particles differ bitwise, largest %.3e m\n",
              GetParam().c_str(), differ, x[0].size() / 4, worst);
}

// Kernel by kernel: xpbd_external_force on random particles (some pinned)
// and forces, against the CPU reference; NaN-poisoned nothing (it only
// updates velocities in place), tolerance as agreement_support.h's.
TEST_P(ExternalForce, KernelAgreesWithTheCpuReference) {
  if (GetParam() == "cpu") GTEST_SKIP() << "the CPU kernel is the reference";
  std::mt19937 rng(std::random_device{}());
  const std::uint32_t n = 1000 + rng() % 100;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> v(4 * n), f(4 * n);
  for (float& c : v) c = u(rng);
  for (float& c : f) c = 10.0f * u(rng);
  test::KernelCase c{Kernel::xpbd_external_force, n,
                     {{test::random_particles(rng, n), false, 4}, {f, false, 4}, {v, false, 4}}, {}};
  c.params = test::bytes_of(kernels::ExternalForceParams{1.0f / 240.0f, n, 0, 0});
  const auto ref = test::run_on("cpu", c), gpu = test::run_on(GetParam(), c);
  test::expect_agree(c, ref, gpu, "external_force");
  test::report_difference(c, ref, gpu, "external_force");
  // Pinned particles (w = 0) keep their velocity; the others changed.
  ASSERT_EQ(ref.size(), 3u);
  std::size_t changed = 0;
  for (std::uint32_t p = 0; p < n; ++p) {
    const bool pinned = c.bindings[0].data[4 * p + 3] == 0.0f;
    const bool same = std::memcmp(&ref[2][4 * p], &v[4 * p], 16) == 0;
    if (pinned) {
      EXPECT_TRUE(same) << "pinned particle " << p;
    }
    changed += same ? 0 : 1;
  }
  EXPECT_GT(changed, n / 2);
}

INSTANTIATE_TEST_SUITE_P(Backends, ExternalForce, ::testing::ValuesIn(test::backends()), test::backend_name);

}  // namespace
}  // namespace sinew
