// xPBD physics on every built backend: rest stays bitwise at rest, the
// hanging chain matches its closed-form stretch, free fall matches the
// integrator, a compliance-0 constraint is projected exactly, volume is kept.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "cpu/xpbd_kernels.h"
#include "runtime/simulation_internals.h"
#include "test_support.h"

namespace sinew {
namespace {

class Xpbd : public test::BackendTest {};

Simulation make(const SceneDesc& scene, const std::string& backend) {
  auto sim = test::create_or_skip(scene, backend);
  EXPECT_TRUE(sim.ok()) << sim.error().message();
  return std::move(sim).value();
}

std::vector<float> positions(const Simulation& sim) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  return x;
}

TEST_P(Xpbd, MeshAtRestWithoutGravityStaysBitwiseAtRest) {
  auto armadillo = read_tetgen(test::data_path("meshes/tet/armadillo_4k.node"));
  ASSERT_TRUE(armadillo.ok()) << armadillo.error().message();
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 2, .iterations = 3};
  TetBodyDesc box;
  box.mesh = test::box_mesh(4, 3, 5, 0.01);
  box.pinned = {0, 7};
  scene.tet_bodies.push_back(box);
  TetBodyDesc arm;
  arm.mesh = *armadillo;
  arm.distance_compliance = 0.0;  // rigid constraints too must not drift
  scene.tet_bodies.push_back(arm);

  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const std::vector<float> start = positions(*sim);
  for (int f = 0; f < 100; ++f) SINEW_ASSERT_OK(sim->step());
  const std::vector<float> end = positions(*sim);
  ASSERT_EQ(start.size(), end.size());
  EXPECT_EQ(0, std::memcmp(start.data(), end.data(), start.size() * sizeof(float)))
      << "positions changed although every constraint is at rest and there is no gravity";
  std::vector<float> v;
  SINEW_ASSERT_OK(sim->read_velocities(v));
  for (float c : v) ASSERT_EQ(c, 0.0f);
}

TEST_P(Xpbd, HangingChainStretchesByAlphaKmg) {
  // N+1 particles of mass m hang from a pinned top particle; link k counted
  // from the bottom carries the weight of k particles: stretch alpha*k*m*g.
  // One substep of many iterations is a converged implicit Euler step
  // (omega h ~ 1.7 here), which damps the chain's oscillation so it settles.
  // (Many substeps of few iterations damp far less and keep it bouncing; and
  // a stiffer link would stretch by only a few float ulps of its position.)
  const int links = 10;
  const double m = 0.1, alpha = 1e-3, rest = 0.1, g = 9.81;
  LineBodyDesc chain;
  for (int i = 0; i <= links; ++i) {
    chain.vertices.push_back({0.0, -rest * i, 0.0});
    chain.masses.push_back(m);
    if (i > 0) chain.segments.push_back({std::uint32_t(i - 1), std::uint32_t(i)});
  }
  chain.compliance = alpha;
  chain.pinned = {0};
  SceneDesc scene;
  scene.gravity = {0.0, -g, 0.0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = 50};
  scene.line_bodies.push_back(chain);
  Simulation sim = make(scene, GetParam());
  for (int f = 0; f < 600; ++f) SINEW_ASSERT_OK(sim.step());
  const std::vector<float> x = positions(sim);
  for (int k = 1; k <= links; ++k) {
    // Link k from the bottom joins particles links-k (upper) and links-k+1.
    const int upper = links - k, lower = links - k + 1;
    const double len = std::abs(double(x[4 * upper + 1]) - double(x[4 * lower + 1]));
    const double expected = alpha * k * m * g;
    EXPECT_NEAR(len - rest, expected, 0.01 * expected) << "link " << k << " from the bottom";
  }
}

TEST_P(Xpbd, FreeFallFollowsTheIntegrator) {
  // One free particle: each substep v += h g, x += h v, so after n substeps
  // y = -g h^2 n (n + 1) / 2 and v = -g h n (symplectic Euler). Velocities
  // are derived from float positions, (x - prev) / h, so each substep adds
  // about ulp(x) / h of noise: 1e-3 relative is far above that and far below
  // the 1% an off-by-one substep would cause.
  LineBodyDesc p;
  p.vertices = {{0.0, 0.0, 0.0}};
  p.masses = {1.0};
  SceneDesc scene;
  scene.solver = {.time_step = 0.01, .substeps = 4, .iterations = 1};
  scene.line_bodies.push_back(p);
  Simulation sim = make(scene, GetParam());
  for (int f = 0; f < 25; ++f) SINEW_ASSERT_OK(sim.step());
  const double h = 0.01 / 4, n = 100, g = 9.81;
  const double y = -g * h * h * n * (n + 1) / 2, vy = -g * h * n;
  const std::vector<float> x = positions(sim);
  EXPECT_NEAR(x[1], y, 1e-3 * std::abs(y));
  EXPECT_EQ(x[0], 0.0f);
  std::vector<float> v;
  SINEW_ASSERT_OK(sim.read_velocities(v));
  EXPECT_NEAR(v[1], vy, 1e-3 * std::abs(vy));
}

TEST_P(Xpbd, RigidPendulumKeepsItsLengthEveryFrame) {
  // A bob on a rigid link (compliance 0) swinging from a pinned pivot: one
  // iteration projects the single constraint exactly, so after every frame
  // the length is the rest length to float rounding, while the bob swings.
  LineBodyDesc pendulum;
  pendulum.vertices = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  pendulum.masses = {1.0, 0.5};
  pendulum.segments = {{0, 1}};
  pendulum.pinned = {0};
  SceneDesc scene;
  scene.solver = {.time_step = 0.01, .substeps = 1, .iterations = 1};
  scene.line_bodies.push_back(pendulum);
  Simulation sim = make(scene, GetParam());
  for (int f = 0; f < 30; ++f) {
    SINEW_ASSERT_OK(sim.step());
    const std::vector<float> x = positions(sim);
    EXPECT_NEAR(std::hypot(x[4], x[5], x[6]), 1.0, 2e-6) << "frame " << f;
  }
  EXPECT_LT(positions(sim)[5], -0.1f) << "the bob should have swung down";
}

TEST_P(Xpbd, VolumeConstraintsKeepTheVolume) {
  // A soft block (stiff volume, compliant edges) hanging from its top face
  // sags visibly but keeps its total volume.
  TetBodyDesc body;
  body.mesh = test::box_mesh(6, 6, 6, 0.01);
  body.distance_compliance = 1.0 / 5e3;
  body.volume_compliance = 0.0;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] > 0.06 - 1e-9) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 2};
  scene.tet_bodies.push_back(body);
  Simulation sim = make(scene, GetParam());
  for (int f = 0; f < 60; ++f) SINEW_ASSERT_OK(sim.step());
  const std::vector<float> x = positions(sim);
  double volume = 0.0, lowest = 0.0;
  for (const auto& t : body.mesh.tets) {
    auto p = [&](int k) { return kernels::double4{x[4 * t[k]], x[4 * t[k] + 1], x[4 * t[k] + 2], 0}; };
    volume += kernels::tet_volume(p(0), p(1), p(2), p(3));
  }
  for (std::size_t i = 0; i < x.size(); i += 4) lowest = std::min(lowest, double(x[i + 1]));
  EXPECT_LT(lowest, -1e-3) << "the block should sag by more than a millimetre";
  EXPECT_NEAR(volume, 0.06 * 0.06 * 0.06, 0.01 * 0.06 * 0.06 * 0.06);
}

TEST_P(Xpbd, ProgramHoldsOnlyTheStagesTheSceneUses) {
  LineBodyDesc chain;
  chain.vertices = {{0, 0, 0}, {0, -1, 0}, {0, -2, 0}};
  chain.masses = {1, 1, 1};
  chain.segments = {{0, 1}, {1, 2}};
  SceneDesc scene;
  scene.solver = {.time_step = 0.01, .substeps = 3, .iterations = 2};
  scene.line_bodies.push_back(chain);
  Simulation sim = make(scene, GetParam());
  const FrameProgram& prog = SimulationInternals::program(sim);
  EXPECT_EQ(prog.dispatch_count(Kernel::xpbd_solve_volume), 0u) << "a chain has no volume constraints";
  EXPECT_EQ(prog.dispatch_count(Kernel::xpbd_predict), 3u);
  // substeps x iterations x colours, plus one measuring pass per frame.
  EXPECT_EQ(prog.dispatch_count(Kernel::xpbd_solve_distance), 3u * 2u * sim.info().distance_colors + 1u);
  scene.solver.measure_errors = false;
  EXPECT_EQ(SimulationInternals::program(make(scene, GetParam())).dispatch_count(Kernel::xpbd_solve_distance),
            3u * 2u * sim.info().distance_colors);
  EXPECT_EQ(sim.info().distance_colors, 2u) << "two links sharing a particle need two colours";

  TetBodyDesc body;
  body.mesh = test::box_mesh(2, 2, 2, 0.1);
  body.distance_constraints = false;
  SceneDesc tets;
  tets.tet_bodies.push_back(body);
  Simulation volume_only = make(tets, GetParam());
  EXPECT_EQ(SimulationInternals::program(volume_only).dispatch_count(Kernel::xpbd_solve_distance), 0u);
  EXPECT_EQ(volume_only.info().distance_constraints, 0u);
  EXPECT_EQ(volume_only.info().volume_constraints, 48u);
}

// The statistics are reduced on the device (double-float terms, fixed
// order): they equal double-precision sums over the read-back state to
// ~1e-13 (the volume from the boundary surface, the definition from the
// tets), and are the same bits on every backend.
TEST_P(Xpbd, DeviceStatisticsEqualDoubleSumsOfTheStateAndAgreeAcrossBackends) {
  TetBodyDesc body;
  body.mesh = test::box_mesh(6, 3, 3, 0.01);
  body.density = 1000.0;
  SINEW_ASSERT_OK(body.set_elastic(2e4, 0.4));
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 2};
  scene.tet_bodies.push_back(body);
  Simulation sim = make(scene, GetParam());
  Simulation reference = make(scene, "cpu");
  for (int f = 0; f < 20; ++f) {
    SINEW_ASSERT_OK(sim.step());
    SINEW_ASSERT_OK(reference.step());
  }
  std::vector<float> x = positions(sim), v;
  SINEW_ASSERT_OK(sim.read_velocities(v));
  double ke = 0.0, volume = 0.0, rest = 0.0;
  for (std::size_t p = 0; p < x.size() / 4; ++p)
    if (x[4 * p + 3] > 0.0f)
      ke += 0.5 / x[4 * p + 3] * (double(v[4 * p]) * v[4 * p] + double(v[4 * p + 1]) * v[4 * p + 1] +
                                  double(v[4 * p + 2]) * v[4 * p + 2]);
  for (const auto& t : body.mesh.tets) {
    const auto at = [&](int k) { return kernels::double4{x[4 * t[k]], x[4 * t[k] + 1], x[4 * t[k] + 2], 0.0}; };
    const auto rest_at = [&](int k) {
      const Vec3d& r = body.mesh.vertices[t[k]];
      return kernels::double4{r[0], r[1], r[2], 0.0};
    };
    volume += kernels::tet_volume(at(0), at(1), at(2), at(3));
    rest += kernels::tet_volume(rest_at(0), rest_at(1), rest_at(2), rest_at(3));
  }
  const FrameStats& s = sim.last_frame();
  EXPECT_GT(s.kinetic_energy, 1e-6) << "the block is moving";
  EXPECT_NEAR(s.kinetic_energy, ke, 1e-12 * ke);
  EXPECT_NE(s.volume_change, 0.0);
  EXPECT_NEAR(s.volume_change, volume / rest - 1.0, 1e-12);
  EXPECT_GT(s.residual_rms, 0.0);
  EXPECT_GE(s.max_residual, s.residual_rms);
  const FrameStats& r = reference.last_frame();
  EXPECT_EQ(s.kinetic_energy, r.kinetic_energy);
  EXPECT_EQ(s.volume_change, r.volume_change);
  EXPECT_EQ(s.residual_rms, r.residual_rms);
  EXPECT_EQ(s.max_residual, r.max_residual);
  EXPECT_LT(s.read_back_bytes, 100u) << "a few words per frame, not the state";
}

TEST_P(Xpbd, FrameStatsReportTheErrors) {
  // Kinetic energy of a falling particle is m v^2 / 2 of its velocity.
  LineBodyDesc p;
  p.vertices = {{0.0, 0.0, 0.0}};
  p.masses = {2.0};
  SceneDesc fall;
  fall.line_bodies.push_back(p);
  Simulation sim = make(fall, GetParam());
  for (int f = 0; f < 10; ++f) SINEW_ASSERT_OK(sim.step());
  std::vector<float> v;
  SINEW_ASSERT_OK(sim.read_velocities(v));
  EXPECT_NEAR(sim.last_frame().kinetic_energy, 0.5 * 2.0 * double(v[1]) * v[1], 1e-9);
  EXPECT_GT(sim.last_frame().kinetic_energy, 1.0);

  // The residual of a stiff block shrinks as iterations converge the solve.
  auto residual_after = [&](int iterations) {
    TetBodyDesc body;
    body.mesh = test::box_mesh(3, 6, 3, 0.01);
    EXPECT_TRUE(body.set_elastic(1e5, 0.3).ok());
    for (std::uint32_t k = 0; k < body.mesh.vertices.size(); ++k)
      if (body.mesh.vertices[k][1] > 0.06 - 1e-9) body.pinned.push_back(k);
    SceneDesc scene;
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = iterations};
    scene.tet_bodies.push_back(body);
    Simulation s = make(scene, GetParam());
    for (int f = 0; f < 5; ++f) EXPECT_TRUE(s.step().ok());
    EXPECT_NE(s.last_frame().volume_change, 0.0) << "the block deforms";
    EXPECT_LT(std::abs(s.last_frame().volume_change), 0.05);
    return s.last_frame().residual_rms;
  };
  const double few = residual_after(2), many = residual_after(64);
  EXPECT_GT(few, 0.0);
  EXPECT_LT(many, 0.5 * few) << "64 iterations should leave less residual than 2";

  // Without measurement, nothing is measured.
  fall.solver.measure_errors = false;
  Simulation quiet = make(fall, GetParam());
  SINEW_ASSERT_OK(quiet.step());
  EXPECT_EQ(quiet.last_frame().kinetic_energy, 0.0);
}

TEST_P(Xpbd, BodyStartingCompressedRecoversItsRestVolume) {
  // Rest shape a 4 cm cube; it starts squashed to half its height.
  TetBodyDesc body;
  body.mesh = test::box_mesh(4, 4, 4, 0.01);
  SINEW_ASSERT_OK(body.set_elastic(1e5, 0.3));
  for (Vec3d p : body.mesh.vertices) body.initial_vertices.push_back({p[0], 0.5 * p[1], p[2]});
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 2};
  scene.tet_bodies.push_back(body);
  Simulation sim = make(scene, GetParam());
  auto top = [&] {
    const std::vector<float> x = positions(sim);
    float y = -1.0f;
    for (std::size_t i = 1; i < x.size(); i += 4) y = std::max(y, x[i]);
    return y;
  };
  EXPECT_FLOAT_EQ(top(), 0.02f) << "the body starts at its initial, squashed positions";
  for (int f = 0; f < 120; ++f) SINEW_ASSERT_OK(sim.step());
  EXPECT_GT(top(), 0.03f) << "it springs back up";
  EXPECT_NEAR(sim.last_frame().volume_change, 0.0, 0.05);
}

TEST_P(Xpbd, ConvergedStepDampsLikeImplicitEuler) {
  // A mass on a spring (one distance constraint of compliance alpha to a
  // pinned particle), released stretched, no gravity. One constraint is
  // solved exactly by one iteration, so each substep is an implicit Euler
  // step; in the scaled state (omega x, v) implicit Euler is a rotation
  // shrunk by 1/sqrt(1 + omega^2 h^2), so the energy after n substeps is
  // exactly E0 / (1 + omega^2 h^2)^n.
  const double m = 1.0, alpha = 0.01, rest = 0.5, stretch = 0.05;
  const double omega = std::sqrt(1.0 / (alpha * m));
  for (int substeps : {1, 4}) {
    LineBodyDesc spring;
    spring.vertices = {{0.0, 0.0, 0.0}, {rest, 0.0, 0.0}};
    spring.initial_vertices = {{0.0, 0.0, 0.0}, {rest + stretch, 0.0, 0.0}};
    spring.masses = {1.0, m};
    spring.segments = {{0, 1}};
    spring.compliance = alpha;
    spring.pinned = {0};
    SceneDesc scene;
    scene.gravity = {0.0, 0.0, 0.0};
    scene.solver = {.time_step = 1.0 / 60.0, .substeps = substeps, .iterations = 1};
    scene.line_bodies.push_back(spring);
    Simulation sim = make(scene, GetParam());
    const double e0 = 0.5 * stretch * stretch / alpha;
    const int frames = 30;
    for (int f = 0; f < frames; ++f) SINEW_ASSERT_OK(sim.step());
    const std::vector<float> x = positions(sim);
    const double c = std::hypot(double(x[4]), double(x[5]), double(x[6])) - rest;
    const double energy = sim.last_frame().kinetic_energy + 0.5 * c * c / alpha;
    const double h = scene.solver.time_step / substeps;
    const double expected = e0 * std::pow(1.0 + omega * omega * h * h, -frames * substeps);
    EXPECT_NEAR(energy, expected, 0.01 * expected) << substeps << " substeps";
    EXPECT_LT(energy, 0.9 * e0) << "the oscillator must have lost energy";
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, Xpbd, ::testing::ValuesIn(test::backends()), test::backend_name);

TEST(XpbdCpu, SameResultWithOneAndTwoThreads) {
  // Colour order fixes the order of every update, so the split of a colour
  // across threads cannot change a bit of the result.
  TetBodyDesc body;
  body.mesh = test::box_mesh(20, 20, 20, 0.005);
  SINEW_ASSERT_OK(body.set_elastic(2e4, 0.45));
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 2, .iterations = 3};
  scene.tet_bodies.push_back(body);
  std::vector<float> result[2];
  for (int threads : {1, 2}) {
    auto sim = test::create_or_skip(scene, "cpu", threads);
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    for (int f = 0; f < 20; ++f) SINEW_ASSERT_OK(sim->step());
    SINEW_ASSERT_OK(sim->read_positions(result[threads - 1]));
  }
  ASSERT_EQ(result[0].size(), result[1].size());
  EXPECT_EQ(0, std::memcmp(result[0].data(), result[1].data(), result[0].size() * sizeof(float)));
  // And the scene did move: the test compares something.
  auto initial = test::create_or_skip(scene, "cpu", 1);
  std::vector<float> x0;
  SINEW_ASSERT_OK(initial->read_positions(x0));
  EXPECT_NE(0, std::memcmp(x0.data(), result[0].data(), x0.size() * sizeof(float)));
}

}  // namespace
}  // namespace sinew
