// divergence_test.cpp — the divergence checks (sinew/divergence.h) on every
// backend: a healthy run is never flagged; a kinematic target thrown 10 m in
// one frame (a haptic device's glitch) is energy growth the frame's loads
// cannot explain; NaN velocities are non-finite; inverted tets are counted
// as the host counts them; a Neo-Hookean block past its Courant limit is
// found; each policy does what it says: report (and log), stop with
// ErrorCode::diverged, roll back bitwise to the last good frame (also after
// a frame that failed half-way, a stage's error or the device's, and keeping
// a topology change made before).
#include <limits>
#include <utility>

#include "faulty_device.h"
#include "robustness_scenes.h"
#include "runtime/simulation_internals.h"
#include "sinew/log.h"

namespace sinew {
namespace {

using test::drive;
using test::same_bits;
using test::snapshot;

class DivergenceTest : public test::BackendTest {
 protected:
  void TearDown() override { set_log_callback({}); }
  // Captures the log's warnings while the test runs.
  void capture_log() {
    set_log_callback([this](LogLevel level, std::string_view text) {
      if (level == LogLevel::warning) warnings_.emplace_back(text);
    });
  }
  std::vector<std::string> warnings_;
};

// The glitch: the target jumps 10 m away for one frame.
void throw_target(Simulation& sim) {
  auto target = sim.tools().target(0);
  ASSERT_TRUE(target.ok());
  SINEW_ASSERT_OK(sim.tools().set_position(*target, {10.04, 0.02, 0.02}));
}

// Every movable particle's velocity NaN, written before the frame's solve.
class BreakVelocities final : public FrameStage {
 public:
  BreakVelocities(BufferHandle velocity, std::uint32_t particles) : velocity_(velocity), particles_(particles) {}
  std::string_view name() const override { return "break velocities"; }
  Status before_frame(FrameContext& frame) override {
    if (!armed) return {};
    armed = false;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> v(4 * std::size_t{particles_}, nan);
    for (std::size_t p = 0; p < particles_; ++p) v[4 * p + 3] = 1.0f;  // w: the damping factor
    return frame.device.write_buffer(velocity_, 0, v.data(), v.size() * sizeof(float));
  }
  bool armed = false;

 private:
  BufferHandle velocity_;
  std::uint32_t particles_;
};

// A stage that fails once after the solve, when armed: a device error in
// the middle of a frame, after the positions changed.
class FailOnce final : public FrameStage {
 public:
  std::string_view name() const override { return "fail once"; }
  Status after_solve(FrameContext&) override {
    if (!armed) return {};
    armed = false;
    return Error(ErrorCode::device_lost, "the device stopped (test)");
  }
  bool armed = false;
};

// The run that never went wrong: its snapshot after each frame 1..frames
// (index 0 unused; fewer on a failure, which the caller's size check reports).
std::vector<test::Snapshot> uninterrupted(const SceneDesc& scene, const std::string& backend, int frames) {
  std::vector<test::Snapshot> out(1);
  auto plain = test::create_or_skip(scene, backend);
  if (!plain.ok()) return out;
  for (int f = 1; f <= frames; ++f) {
    drive(*plain, f);
    if (!plain->step().ok()) return out;
    out.push_back(snapshot(*plain));
  }
  return out;
}

TEST_P(DivergenceTest, HealthyRunIsNeverFlagged) {
  auto sim = test::create_or_skip(test::robustness_block(), GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  for (int f = 1; f <= 60; ++f) {
    drive(*sim, f);
    SINEW_ASSERT_OK(sim->step());
    const DivergenceReport& d = sim->last_frame().divergence;
    ASSERT_EQ(d.kind, Divergence::none) << "frame " << f << ": kinetic energy " << sim->last_frame().kinetic_energy
                                        << " J, bound " << d.energy_bound << " J";
    EXPECT_GT(d.energy_bound, sim->last_frame().kinetic_energy);
  }
  EXPECT_EQ(sim->last_frame().divergence.diverged_frames, 0u);
}

TEST_P(DivergenceTest, ThrownTargetIsReportedAsEnergyGrowthAndLogged) {
  auto sim = test::create_or_skip(test::robustness_block(), GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  capture_log();
  test::run(*sim, 1, 3);
  throw_target(*sim);
  SINEW_ASSERT_OK(sim->step());  // report: the frame stands
  const FrameStats& stats = sim->last_frame();
  EXPECT_EQ(stats.divergence.kind, Divergence::energy_growth);
  EXPECT_GT(stats.kinetic_energy, stats.divergence.energy_bound);
  EXPECT_FALSE(stats.divergence.rolled_back);
  EXPECT_EQ(stats.frame, 4u);
  EXPECT_EQ(stats.divergence.diverged_frames, 1u);
  ASSERT_EQ(warnings_.size(), 1u);
  EXPECT_NE(warnings_[0].find("frame 4 diverged (energy_growth)"), std::string::npos) << warnings_[0];
}

TEST_P(DivergenceTest, NonFiniteVelocitiesAreReported) {
  auto sim = test::create_or_skip(test::robustness_block(), GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  auto stage = std::make_unique<BreakVelocities>(SimulationInternals::velocity_buffer(*sim), sim->info().particles);
  BreakVelocities& breaker = *stage;
  SimulationInternals::add_stage(*sim, std::move(stage));
  capture_log();
  drive(*sim, 1);
  SINEW_ASSERT_OK(sim->step());
  EXPECT_EQ(sim->last_frame().divergence.kind, Divergence::none);
  breaker.armed = true;
  drive(*sim, 2);
  SINEW_ASSERT_OK(sim->step());
  EXPECT_EQ(sim->last_frame().divergence.kind, Divergence::non_finite);
  ASSERT_FALSE(warnings_.empty());
  EXPECT_NE(warnings_.back().find("non_finite"), std::string::npos) << warnings_.back();
}

TEST_P(DivergenceTest, StopReturnsANamedError) {
  auto sim = test::create_or_skip(test::robustness_block(), GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  SINEW_ASSERT_OK(sim->set_divergence_settings({.on_divergence = OnDivergence::stop}));
  capture_log();
  drive(*sim, 1);
  SINEW_ASSERT_OK(sim->step());
  throw_target(*sim);
  const Status s = sim->step();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::diverged);
  EXPECT_NE(s.error().message().find("energy_growth"), std::string::npos) << s.error().message();
  EXPECT_EQ(sim->last_frame().divergence.kind, Divergence::energy_growth);
  EXPECT_EQ(warnings_.size(), 1u);
}

TEST_P(DivergenceTest, RollBackRestoresTheLastGoodFrameBitwise) {
  const SceneDesc scene = test::robustness_block();
  const std::vector<test::Snapshot> expected = uninterrupted(scene, GetParam(), 8);
  ASSERT_EQ(expected.size(), 9u);

  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  SINEW_ASSERT_OK(sim->set_divergence_settings({.on_divergence = OnDivergence::roll_back}));
  capture_log();
  test::run(*sim, 1, 5);
  throw_target(*sim);  // frame 6 diverges
  SINEW_ASSERT_OK(sim->step());
  const FrameStats& stats = sim->last_frame();
  EXPECT_EQ(stats.divergence.kind, Divergence::energy_growth);
  EXPECT_TRUE(stats.divergence.rolled_back);
  EXPECT_EQ(stats.divergence.rolled_back_to, 5u);
  EXPECT_EQ(stats.frame, 5u);
  EXPECT_TRUE(same_bits(snapshot(*sim), expected[5])) << "rolled back to frame 5, on " << GetParam();
  ASSERT_EQ(warnings_.size(), 1u);
  EXPECT_NE(warnings_[0].find("rolled back to frame 5"), std::string::npos) << warnings_[0];
  // The scene continues from frame 5 as if frame 6 had never gone wrong.
  for (int f = 6; f <= 8; ++f) {
    drive(*sim, f);
    SINEW_ASSERT_OK(sim->step());
    EXPECT_EQ(sim->last_frame().divergence.kind, Divergence::none);
    EXPECT_TRUE(same_bits(snapshot(*sim), expected[f])) << "frame " << f << " after the roll-back, on " << GetParam();
  }
}

TEST_P(DivergenceTest, FailedFrameRollsBackAndTheSceneGoesOn) {
  const SceneDesc scene = test::robustness_block();
  const std::vector<test::Snapshot> expected = uninterrupted(scene, GetParam(), 6);
  ASSERT_EQ(expected.size(), 7u);
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  auto stage = std::make_unique<FailOnce>();
  FailOnce& failing = *stage;
  SimulationInternals::add_stage(*sim, std::move(stage));
  SINEW_ASSERT_OK(sim->set_divergence_settings({.on_divergence = OnDivergence::roll_back}));
  capture_log();
  test::run(*sim, 1, 4);
  failing.armed = true;
  drive(*sim, 5);
  const Status failed = sim->step();
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code(), ErrorCode::device_lost);
  EXPECT_NE(failed.error().message().find("rolled back to frame 4"), std::string::npos) << failed.error().message();
  EXPECT_EQ(sim->last_frame().frame, 4u);
  EXPECT_TRUE(same_bits(snapshot(*sim), expected[4])) << "on " << GetParam();
  ASSERT_EQ(warnings_.size(), 1u);
  test::run(*sim, 5, 6);  // usable: the frames the failure interrupted, as if it never happened
  EXPECT_TRUE(same_bits(snapshot(*sim), expected[6])) << "on " << GetParam();
}

TEST_P(DivergenceTest, InjectedDeviceFaultsRollBackBitwise) {
  // The device itself fails in the middle of frame 5 (tests/faulty_device.h):
  // a submission, a wait or a read-back. Each time the scene goes back to
  // frame 4 and continues as the run that never failed. A plain frame reads
  // nothing on its own (its statistics come with the wait); with mesh
  // collision the frame reads the positions back, so the read-back fails there.
  const SceneDesc plain = test::robustness_block();
  SceneDesc reading = plain;
  reading.mesh_collision.enabled = true;
  reading.mesh_collision.self_collision = true;
  using Call = test::FaultyDevice::Call;
  for (auto [call, scene] : {std::pair{Call::submit, plain}, {Call::wait, plain}, {Call::read_buffer, reading}}) {
    SCOPED_TRACE(test::FaultyDevice::name(call));
    const std::vector<test::Snapshot> expected = uninterrupted(scene, GetParam(), 6);
    ASSERT_EQ(expected.size(), 7u);
    auto real = create_device({.backend = GetParam(), .quiet = true});
    ASSERT_TRUE(real.ok()) << real.error().message();
    auto faulty = std::make_unique<test::FaultyDevice>(std::move(*real));
    test::FaultyDevice& device = *faulty;
    auto sim = SimulationInternals::create(scene, std::move(faulty));
    ASSERT_TRUE(sim.ok()) << sim.error().message();
    SINEW_ASSERT_OK(sim->set_divergence_settings({.on_divergence = OnDivergence::roll_back}));
    capture_log();
    test::run(*sim, 1, 4);
    drive(*sim, 5);
    device.arm(call, 1);
    const Status failed = sim->step();
    ASSERT_TRUE(device.fired());
    ASSERT_FALSE(failed.ok());
    EXPECT_NE(failed.error().message().find(test::FaultyDevice::tag()), std::string::npos) << failed.error().message();
    EXPECT_NE(failed.error().message().find("rolled back to frame 4"), std::string::npos) << failed.error().message();
    EXPECT_TRUE(same_bits(snapshot(*sim), expected[4])) << "on " << GetParam();
    test::run(*sim, 5, 6);
    EXPECT_TRUE(same_bits(snapshot(*sim), expected[6])) << "on " << GetParam();
  }
}

TEST_P(DivergenceTest, RollBackAfterATopologyChangeKeepsTheChange) {
  auto sim = test::create_or_skip(test::robustness_block(/*topology=*/true), GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  SINEW_ASSERT_OK(sim->set_divergence_settings({.on_divergence = OnDivergence::roll_back}));
  capture_log();
  test::run(*sim, 1, 3);
  auto body = sim->topology().tet_body(0);
  ASSERT_TRUE(body.ok());
  const std::vector<std::uint32_t> hole{40, 41, 42, 43, 44, 45};
  ASSERT_TRUE(sim->topology().remove_tets(*body, hole).ok());
  const test::Snapshot changed = snapshot(*sim);
  throw_target(*sim);
  SINEW_ASSERT_OK(sim->step());  // frame 4 diverges: back to frame 3 with the hole
  EXPECT_TRUE(sim->last_frame().divergence.rolled_back);
  EXPECT_EQ(sim->last_frame().frame, 3u);
  EXPECT_TRUE(same_bits(snapshot(*sim), changed));
  auto tets = sim->topology().current_tets(*body);
  ASSERT_TRUE(tets.ok());
  EXPECT_EQ(tets->size(), 96u - hole.size());
}

TEST_P(DivergenceTest, NeoHookeanPastItsCourantLimitIsFlagged) {
  // The test block stiffened to E = 1 MPa and stepped in one substep per
  // 60 Hz frame: Courant number ~33, far past the ~0.75 at which a body at
  // rest blows up (README, "FEM materials").
  SceneDesc scene = test::robustness_block();
  ASSERT_TRUE(scene.tet_bodies[0].set_material(TetMaterial::neo_hookean, 1e6, 0.3).ok());
  scene.solver.substeps = 1;
  scene.solver.iterations = 1;
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  capture_log();
  int flagged = 0;
  for (int f = 1; f <= 120 && !flagged; ++f) {
    SINEW_ASSERT_OK(sim->step());
    if (sim->last_frame().divergence.kind != Divergence::none) flagged = f;
  }
  ASSERT_GT(flagged, 0) << "120 frames past the Courant limit and no divergence found; kinetic energy "
                        << sim->last_frame().kinetic_energy << " J";
  EXPECT_FALSE(warnings_.empty());
}

// A block started mirrored (every tet inside out), held only by very soft
// volume constraints, so it is still inverted after a frame.
SceneDesc inside_out_block() {
  SceneDesc scene;
  TetBodyDesc body;
  body.mesh = test::box_mesh(3, 2, 2, 0.01);
  body.distance_constraints = false;
  body.volume_compliance = 1.0;
  for (Vec3d v : body.mesh.vertices) body.initial_vertices.push_back({v[0], -v[1], v[2]});
  scene.tet_bodies.push_back(body);
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.substeps = 1;
  scene.solver.iterations = 1;
  return scene;
}

TEST_P(DivergenceTest, InvertedTetsAreCountedAsTheHostCountsThem) {
  const SceneDesc scene = inside_out_block();
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  capture_log();
  // Checked alone: the volume check (the total volume is negative) would come first.
  SINEW_ASSERT_OK(sim->set_divergence_settings({.max_volume_change = 10.0, .max_inverted_fraction = 0.5}));
  SINEW_ASSERT_OK(sim->step());
  std::vector<float> x;
  SINEW_ASSERT_OK(sim->read_positions(x));
  const TetMesh& mesh = scene.tet_bodies[0].mesh;
  std::uint32_t inverted = 0;
  for (const auto& t : mesh.tets) {  // the rest winding of each tet is positive (make_tet_grid)
    double e[3][3];
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) e[k][c] = double(x[4 * t[k + 1] + c]) - double(x[4 * t[0] + c]);
    const double six_v = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                         e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    inverted += six_v < 0.0;
  }
  EXPECT_GT(inverted, mesh.tets.size() / 2);  // the scene is what the test needs
  EXPECT_EQ(sim->last_frame().inverted_tets, inverted);
  EXPECT_EQ(sim->last_frame().divergence.kind, Divergence::inverted);
}

INSTANTIATE_TEST_SUITE_P(Backends, DivergenceTest, ::testing::ValuesIn(test::backends()), test::backend_name);

TEST(DivergenceSettings, BadSettingsAreNamedErrors) {
  auto sim = Simulation::create(test::robustness_block(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const std::pair<DivergenceSettings, const char*> bad[] = {
      {{.energy_growth = 1.0}, "energy_growth"},
      {{.energy_growth = std::numeric_limits<double>::infinity()}, "energy_growth"},
      {{.floor_speed = -1.0}, "floor_speed"},
      {{.max_volume_change = 0.0}, "max_volume_change"},
      {{.max_inverted_fraction = 1.5}, "max_inverted_fraction"},
      {{.checkpoint_every = 0}, "checkpoint_every"},
  };
  for (const auto& [settings, field] : bad) {
    const Status s = sim->set_divergence_settings(settings);
    ASSERT_FALSE(s.ok()) << field;
    EXPECT_EQ(s.error().code(), ErrorCode::bad_parameter);
    EXPECT_NE(s.error().message().find(field), std::string::npos) << s.error().message();
  }
  EXPECT_EQ(sim->divergence_settings().on_divergence, OnDivergence::report);  // unchanged
}

}  // namespace
}  // namespace sinew
