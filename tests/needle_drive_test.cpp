// needle_drive_test.cpp — what a needle feels and how a force moves it
// (issue 13, part 4; NeedleDrive, Simulation::apply_needle_force,
// NeedleState::reaction_force): a kinematic needle pushing a free pad feels
// the momentum it gives it, one holding a hanging thread feels its weight; a
// force-driven needle pushed more gently than its puncture force rests on
// the pad with the push balanced, one led by a virtual coupling punctures
// once the coupling's pull passes the puncture force and then follows its
// target into the pad; the calls' errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "test_support.h"

namespace sinew::test {
namespace {

class NeedleDriveTest : public BackendTest {};

constexpr double kCell = 0.002;
// Where the straight needle stands over the pad: off the grid's lines.
constexpr double kOverX = 0.0007, kOverZ = 0.0009;

// A soft pad 12 x 10 x 12 mm (2 mm cells, top at y = 0, centred on the y
// axis), its bottom pinned (`pinned`) or free, and a straight needle 10 mm
// long standing on its tip 0.2 mm over the pad's top (tail up, its origin
// at its middle). No gravity unless set; 60 frames per second of 8
// substeps with 10 sweeps.
SceneDesc pad_and_needle(bool pinned, NeedleDrive drive) {
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 8;
  scene.solver.iterations = 10;
  auto mesh = make_tet_grid({.nx = 6, .ny = 5, .nz = 6, .origin = {-3 * kCell, -5 * kCell, -3 * kCell},
                             .cell_size = {kCell, kCell, kCell}});
  TetBodyDesc pad;
  pad.mesh = *mesh;
  (void)pad.set_elastic(3e4, 0.45);
  pad.velocity_damping = pinned ? 5.0 : 0.0;  // a free pad keeps its momentum
  if (pinned)
    for (std::uint32_t k = 0; k <= 6; ++k)
      for (std::uint32_t i = 0; i <= 6; ++i) pad.pinned.push_back(i + 7 * 6 * k);  // j = 0: the bottom
  scene.tet_bodies.push_back(pad);
  NeedleDesc needle;
  needle.curve = {{0.0, 0.005, 0.0}, {0.0, -0.005, 0.0}};
  needle.position = {kOverX, 0.0052, kOverZ};
  // A point's resistance in xPBD is bounded by its mass per h^2 and the
  // sweeps (about 12 N/m here, whatever E), so a puncture force much above
  // 10 mN is never reached before the dented tets turn inside out.
  needle.puncture_force = 0.01;
  needle.drive = drive;
  needle.gravity = false;
  scene.needles.push_back(needle);
  return scene;
}

double length(const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// A kinematic needle pushes a free pad (no gravity, no damping) down at
// 60 mm/s without puncturing it: the impulse it feels, summed over the
// frames, is the momentum the pad gains (its elastic forces conserve
// momentum). On every backend.
TEST_P(NeedleDriveTest, AKinematicNeedleFeelsTheMomentumItGivesAFreePad) {
  SceneDesc scene = pad_and_needle(false, NeedleDrive::kinematic);
  scene.needles[0].puncture_force = 1e3;  // pushes, never punctures
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const double dt = scene.solver.time_step;
  std::array<double, 3> felt{0.0, 0.0, 0.0};
  for (int f = 0; f < 20; ++f) {
    SINEW_ASSERT_OK(sim->set_needle_pose(0, {kOverX, 0.0052 - 0.001 * (f + 1), kOverZ}, {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    auto state = sim->needle_state(0);
    SINEW_ASSERT_OK(state);
    ASSERT_TRUE(state->punctures.empty());
    for (int k = 0; k < 3; ++k) felt[k] += state->reaction_force[k] * dt;
  }
  std::vector<float> x, v;
  SINEW_ASSERT_OK(sim->read_positions(x));
  SINEW_ASSERT_OK(sim->read_velocities(v));
  std::array<double, 3> momentum{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < x.size() / 4; ++i)
    for (int k = 0; k < 3; ++k) momentum[k] += double(v[4 * i + k]) / double(x[4 * i + 3]);
  std::printf("[%s] the needle felt an impulse of (%.4e, %.4e, %.4e) N s; the pad gained (%.4e, %.4e, %.4e) kg m/s\n",
              GetParam().c_str(), felt[0], felt[1], felt[2], momentum[0], momentum[1], momentum[2]);
  ASSERT_LT(momentum[1], -1e-4);  // it was pushed down
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(felt[k], -momentum[k], 0.01 * length(momentum)) << k;
}

// A kinematic needle held still with its thread (61 vertices of 10 mg)
// hanging from its tail under gravity: once the thread has settled, the
// needle feels the thread's weight. On every backend.
TEST_P(NeedleDriveTest, ANeedleHoldingAHangingThreadFeelsItsWeight) {
  SceneDesc scene;
  scene.gravity = {0.0, -9.81, 0.0};
  scene.solver.substeps = 8;
  scene.solver.iterations = 10;
  NeedleDesc needle;
  needle.curve = {{0.0, -0.005, 0.0}, {0.0, 0.005, 0.0}};  // tail down, tip up
  LineBodyDesc thread;
  double mass = 0.0;
  for (int i = 0; i <= 60; ++i) {
    thread.vertices.push_back({0.002 * i, -0.005, 0.0});  // starts sideways: it swings down
    thread.masses.push_back(1e-5);
    mass += 1e-5;
    if (i < 60) thread.segments.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1)});
  }
  thread.velocity_damping = 5.0;
  scene.line_bodies.push_back(thread);
  needle.thread = 0;
  scene.needles.push_back(needle);
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  std::array<double, 3> average{0.0, 0.0, 0.0};
  for (int f = 0; f < 240; ++f) {
    SINEW_ASSERT_OK(sim->set_needle_pose(0, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    auto state = sim->needle_state(0);
    SINEW_ASSERT_OK(state);
    if (f >= 180)
      for (int k = 0; k < 3; ++k) average[k] += state->reaction_force[k] / 60.0;
  }
  const double weight = mass * 9.81;
  std::printf("[%s] the needle feels (%.6f, %.6f, %.6f) N; the thread weighs %.6f N\n", GetParam().c_str(), average[0],
              average[1], average[2], weight);
  EXPECT_NEAR(average[1], -weight, 0.02 * weight);
  EXPECT_NEAR(average[0], 0.0, 0.02 * weight);
  EXPECT_NEAR(average[2], 0.0, 0.02 * weight);
}

// A kinematic needle dents the pad 0.8 mm without puncturing it and is
// pulled back up: its tip leaves the dent the way it came, which is no exit
// (before the fix, the tip's path up through a tilted neighbour of the
// dented triangle was taken for leaving the pad, and an exit puncture held
// a needle that had never entered).
TEST(NeedleDrive, ATipPulledBackOutOfADentMakesNoPuncture) {
  SceneDesc scene = pad_and_needle(true, NeedleDrive::kinematic);
  scene.needles[0].puncture_force = 1.0;  // pushes, never punctures
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  for (int f = 0; f < 40; ++f) {
    const double down = 1e-4 * (f < 20 ? f + 1 : 40 - f - 1);  // 1 mm down in 20 frames, back up in 20
    SINEW_ASSERT_OK(sim->set_needle_pose(0, {kOverX, 0.0052 - down, kOverZ}, {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    auto state = sim->needle_state(0);
    SINEW_ASSERT_OK(state);
    EXPECT_TRUE(state->punctures.empty()) << "frame " << f;
  }
}

// A hand holding a force-driven needle (a virtual coupling, as a haptic
// device drives one): a spring-damper pulling its origin to `target` plus a
// constant push, and a torsional spring-damper keeping it upright. (A needle
// pushed along its axis with nothing holding its orientation is an inverted
// pendulum on its tip: it tips over, as a pencil would.) The gains keep the
// explicit coupling stable: sqrt(k / m) dt and c dt / m (and the angular
// ones with the least inertia) below 2.
struct Hand {
  double stiffness = 0.0, damping = 0.0;                 // [N/m], [N s/m]
  double angular_stiffness = 0.005, angular_damping = 3e-4;  // [N m/rad], [N m s/rad]
  std::array<double, 3> push{0.0, 0.0, 0.0};             // [N]
  Status drive(Simulation& sim, const std::array<double, 3>& target) const {
    auto s = sim.needle_state(0);
    if (!s.ok()) return s.error();
    const double sign = s->rotation[0] < 0.0 ? -1.0 : 1.0;  // the rotation vector ~ 2 (x, y, z) near upright
    std::array<double, 3> force{}, torque{};
    for (int k = 0; k < 3; ++k) {
      force[k] = push[k] + stiffness * (target[k] - s->position[k]) - damping * s->velocity[k];
      torque[k] = -angular_stiffness * 2.0 * sign * s->rotation[k + 1] - angular_damping * s->angular_velocity[k];
    }
    return sim.apply_needle_force(0, force, torque);
  }
};

// A force-driven needle pushed down with 4 mN, less than its puncture force,
// through a damper (the hand): it dents the pad without puncturing it, comes
// to rest, and the pad pushes back with the push.
TEST(NeedleDrive, AForceDrivenNeedlePushedGentlyRestsOnThePad) {
  const SceneDesc scene = pad_and_needle(true, NeedleDrive::force);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const double push = 0.004;
  Hand hand;
  hand.damping = 2.0;
  hand.push = {0.0, -push, 0.0};
  std::array<double, 3> reaction{0.0, 0.0, 0.0};
  double speed = 0.0, tip_force = 0.0;
  Simulation::NeedleState state;
  for (int f = 0; f < 150; ++f) {
    SINEW_ASSERT_OK(hand.drive(*sim, {0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    auto s = sim->needle_state(0);
    SINEW_ASSERT_OK(s);
    state = *s;
    ASSERT_TRUE(state.punctures.empty()) << "frame " << f;
    if (f >= 120) {
      for (int k = 0; k < 3; ++k) reaction[k] += state.reaction_force[k] / 30.0;
      speed = std::max(speed, length(state.velocity));
      tip_force += state.tip_force / 30.0;
    }
  }
  const double tip = state.position[1] - 0.005;  // the needle stayed upright (checked below)
  std::printf("resting: the pad pushes back with (%.6f, %.6f, %.6f) N (tip force %.6f N), the tip %.3f mm deep, "
              "at most %.4f mm/s\n",
              reaction[0], reaction[1], reaction[2], tip_force, -tip * 1e3, speed * 1e3);
  EXPECT_NEAR(reaction[1], push, 0.02 * push);
  EXPECT_NEAR(tip_force, push, 0.05 * push);
  EXPECT_LT(std::hypot(reaction[0], reaction[2]), 0.05 * push);
  EXPECT_LT(speed, 1e-4);
  EXPECT_LT(tip, 0.0);  // it dents the pad
  EXPECT_GT(tip, -0.002);
  EXPECT_GT(std::abs(state.rotation[0]), std::cos(0.05));  // within 0.1 rad of upright
}

// A force-driven needle led by the hand's spring to a target descending at
// 3.6 mm/s: the spring's pull builds up while the tip dents the pad; the
// needle punctures once its push passes puncture_force, then follows the
// target into the pad, its puncture held on its shaft.
TEST(NeedleDrive, AForceDrivenNeedleLedByACouplingPuncturesAndFollows) {
  const SceneDesc scene = pad_and_needle(true, NeedleDrive::force);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  Hand hand;
  hand.stiffness = 20.0;  // sqrt(k / m) dt = 0.53
  hand.damping = 1.0;     // c dt / m = 0.83
  int punctured = -1;
  double push_before = 0.0, target = 0.0;
  Simulation::NeedleState state;
  for (int f = 0; f < 150; ++f) {
    target = 0.0052 - 6e-5 * (f + 1);
    SINEW_ASSERT_OK(hand.drive(*sim, {kOverX, target, kOverZ}));
    SINEW_ASSERT_OK(sim->step());
    auto after = sim->needle_state(0);
    SINEW_ASSERT_OK(after);
    if (punctured < 0 && !after->punctures.empty()) punctured = f, push_before = std::max(state.tip_force, after->tip_force);
    state = *after;
  }
  std::vector<float> x;
  SINEW_ASSERT_OK(sim->read_positions(x));
  for (float c : x) ASSERT_TRUE(std::isfinite(c));
  std::printf("coupled: punctured at frame %d after a push of %.4f N; the needle ends %.3f mm from its target, "
              "its tip %.2f mm deep\n",
              punctured, push_before, std::abs(state.position[1] - target) * 1e3, -(state.position[1] - 0.005) * 1e3);
  ASSERT_GE(punctured, 0);
  EXPECT_GE(push_before, scene.needles[0].puncture_force);
  ASSERT_EQ(state.punctures.size(), 1u);
  EXPECT_FALSE(state.punctures[0].exit);
  EXPECT_LT(std::abs(state.position[1] - target), 1e-3);
  EXPECT_LT(state.position[1] - 0.005, -0.005);  // the tip 5 mm into the pad at least
}

// The drives' calls and settings are checked and named.
TEST(NeedleDrive, BadCallsAndSettingsAreNamed) {
  auto kinematic = Simulation::create(pad_and_needle(true, NeedleDrive::kinematic), {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(kinematic);
  const Status push_kinematic = kinematic->apply_needle_force(0, {0.0, -1.0, 0.0}, {0.0, 0.0, 0.0});
  ASSERT_FALSE(push_kinematic.ok());
  EXPECT_NE(push_kinematic.error().message().find("is kinematic"), std::string::npos)
      << push_kinematic.error().message();
  auto force = Simulation::create(pad_and_needle(true, NeedleDrive::force), {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(force);
  const Status pose_force = force->set_needle_pose(0, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0});
  ASSERT_FALSE(pose_force.ok());
  EXPECT_NE(pose_force.error().message().find("is force-driven"), std::string::npos) << pose_force.error().message();
  const Status nan_force = force->apply_needle_force(0, {0.0, NAN, 0.0}, {0.0, 0.0, 0.0});
  ASSERT_FALSE(nan_force.ok());
  EXPECT_NE(nan_force.error().message().find("apply_needle_force: force"), std::string::npos)
      << nan_force.error().message();
  const Status bad_index = force->apply_needle_force(1, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  ASSERT_FALSE(bad_index.ok());
  EXPECT_NE(bad_index.error().message().find("index 1 is not a needle"), std::string::npos)
      << bad_index.error().message();
  // A torque far too large for the needle's inertia in one frame.
  SINEW_ASSERT_OK(force->apply_needle_force(0, {0.0, 0.0, 0.0}, {0.0, 0.0, 1e3}));
  const Status spun = force->step();
  ASSERT_FALSE(spun.ok());
  EXPECT_NE(spun.error().message().find("would turn by"), std::string::npos) << spun.error().message();

  const auto error_of = [](const SceneDesc& scene) {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    return sim.ok() ? std::string() : sim.error().message();
  };
  SceneDesc scene = pad_and_needle(true, NeedleDrive::force);
  scene.needles[0].mass = 0.0;
  EXPECT_NE(error_of(scene).find("needles[0].mass"), std::string::npos) << error_of(scene);
  scene = pad_and_needle(true, NeedleDrive::force);
  scene.needles[0].inertia[2] = -1.0;
  EXPECT_NE(error_of(scene).find("needles[0].inertia[2]"), std::string::npos) << error_of(scene);
  scene = pad_and_needle(true, NeedleDrive::kinematic);
  scene.needles[0].mass = 0.0;  // a kinematic needle has no mass to check
  EXPECT_EQ(error_of(scene), "");
}

INSTANTIATE_TEST_SUITE_P(Backends, NeedleDriveTest, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
