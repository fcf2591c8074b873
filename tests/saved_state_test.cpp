// saved_state_test.cpp — Simulation::save_state / restore_state: restoring
// and stepping gives bitwise the run that was never interrupted, on every
// backend, from memory, from a file, in a new Simulation, and across a
// topology change (more in saved_topology_test.cpp); damaged, foreign and
// mismatched states are named errors that leave the Simulation as it was.
#include <filesystem>
#include <fstream>

#include <unistd.h>  // getpid

#include "fluid_cup.h"
#include "mesh_contact_support.h"
#include "robustness_scenes.h"
#include "runtime/state_format.h"
#include "saved_state_support.h"
#include "thread_scenes.h"

namespace sinew {
namespace {

using test::run;
using test::same_bits;
using test::snapshot;
using test::Snapshot;

class SavedStateTest : public test::BackendTest {};

// ctest runs each test in a process of its own, two at a time: a name
// shared by two tests (bad.state) needs the process's id to stay theirs.
std::string tmp_path(const std::string& name) {
  std::filesystem::create_directories(SINEW_TEST_TMP_DIR);
  return std::string(SINEW_TEST_TMP_DIR) + "/" + std::to_string(::getpid()) + "_" + name;
}

TEST_P(SavedStateTest, RestoreThenStepIsBitwiseTheUninterruptedRun) {
  const SceneDesc scene = test::robustness_block();
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  run(*sim, 1, 6);
  SavedState at6;
  SINEW_ASSERT_OK(sim->save_state(at6));
  EXPECT_EQ(at6.frame(), 6u);
  const std::string file = tmp_path("saved_state_" + GetParam() + ".state");
  SINEW_ASSERT_OK(sim->save_state(file));
  const Snapshot frame6 = snapshot(*sim);
  run(*sim, 7, 15);
  const Snapshot frame15 = snapshot(*sim);
  ASSERT_FALSE(same_bits(frame6, frame15));  // the scene moves: the comparison below can fail

  // Back in the same Simulation, from memory.
  SINEW_ASSERT_OK(sim->restore_state(at6));
  EXPECT_EQ(sim->last_frame().frame, 6u);
  EXPECT_TRUE(same_bits(snapshot(*sim), frame6));
  run(*sim, 7, 15);
  EXPECT_EQ(sim->last_frame().frame, 15u);
  EXPECT_TRUE(same_bits(snapshot(*sim), frame15)) << "restored in memory, on " << GetParam();

  // A new Simulation of the same scene, from the file (a restart).
  auto fresh = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(fresh.ok()) << fresh.error().message();
  SINEW_ASSERT_OK(fresh->restore_state(file));
  run(*fresh, 7, 15);
  EXPECT_TRUE(same_bits(snapshot(*fresh), frame15)) << "restored from a file in a new Simulation, on " << GetParam();
}

TEST_P(SavedStateTest, RestoreAcrossATopologyChangeIsBitwise) {
  const SceneDesc scene = test::robustness_block(/*topology=*/true);
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  run(*sim, 1, 3);
  SavedState before;
  SINEW_ASSERT_OK(sim->save_state(before));
  auto body = sim->topology().tet_body(0);
  ASSERT_TRUE(body.ok());
  const std::vector<std::uint32_t> hole{40, 41, 42, 43, 44, 45};  // the cells at the middle of the block
  auto removed = sim->topology().remove_tets(*body, hole);
  ASSERT_TRUE(removed.ok()) << removed.error().message();
  run(*sim, 4, 6);
  SavedState after;
  SINEW_ASSERT_OK(sim->save_state(after));
  run(*sim, 7, 12);
  const Snapshot frame12 = snapshot(*sim);
  SINEW_ASSERT_OK(sim->restore_state(after));
  run(*sim, 7, 12);
  EXPECT_TRUE(same_bits(snapshot(*sim), frame12)) << "after remove_tets, on " << GetParam();

  // The state from before the removal: the block whole again, the removal made again.
  SINEW_ASSERT_OK(sim->restore_state(before));
  EXPECT_EQ(sim->last_frame().frame, 3u);
  ASSERT_TRUE(sim->topology().remove_tets(*sim->topology().tet_body(0), hole).ok());
  run(*sim, 4, 12);
  EXPECT_TRUE(same_bits(snapshot(*sim), frame12)) << "from before remove_tets, on " << GetParam();
  // The state from after it, in a Simulation that has not made the change: replayed.
  auto fresh = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(fresh.ok());
  SINEW_ASSERT_OK(fresh->restore_state(after));
  run(*fresh, 7, 12);
  EXPECT_TRUE(same_bits(snapshot(*fresh), frame12)) << "replayed in a new Simulation, on " << GetParam();
}

// A scene stepped without inputs: save at frame `save`, run to `end`,
// restore, run to `end` again, in the same Simulation (which has seen the
// later frames) and in a new one (which has seen none); each end must be
// the same bits as the uninterrupted run's.
void expect_restore_bitwise(const SceneDesc& scene, const std::string& backend, int save, int end) {
  auto sim = test::create_or_skip(scene, backend);
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  for (int f = 1; f <= save; ++f) SINEW_ASSERT_OK(sim->step());
  SavedState state;
  SINEW_ASSERT_OK(sim->save_state(state));
  const Snapshot saved = snapshot(*sim);
  for (int f = save + 1; f <= end; ++f) SINEW_ASSERT_OK(sim->step());
  const Snapshot uninterrupted = snapshot(*sim);
  ASSERT_FALSE(same_bits(saved, uninterrupted));  // the scene moves
  SINEW_ASSERT_OK(sim->restore_state(state));
  for (int f = save + 1; f <= end; ++f) SINEW_ASSERT_OK(sim->step());
  EXPECT_TRUE(same_bits(snapshot(*sim), uninterrupted)) << "restored in the same Simulation, on " << backend;
  auto fresh = test::create_or_skip(scene, backend);
  ASSERT_TRUE(fresh.ok()) << fresh.error().message();
  SINEW_ASSERT_OK(fresh->restore_state(state));
  for (int f = save + 1; f <= end; ++f) SINEW_ASSERT_OK(fresh->step());
  EXPECT_TRUE(same_bits(snapshot(*fresh), uninterrupted)) << "restored in a new Simulation, on " << backend;
}

// A grasper closed on the block's top and lifting it: the hold (which
// particles and surface points, where in the jaws' frame) is in the state.
// Restored into the same Simulation after the grasper was opened, and into
// a new one whose grasper never closed, the run goes on bitwise.
TEST_P(SavedStateTest, RestoreWithAClosedGrasperIsBitwise) {
  SceneDesc scene = test::robustness_block();
  scene.graspers.push_back({.capacity = 16, .point_capacity = 8});
  const auto jaws_at = [](int frame) {
    return Pose{.position = {0.03, 0.02 + 0.001 * (frame - 4), 0.01}, .rotation = {1, 0, 0, 0}};
  };
  const auto lift = [&](Simulation& sim, int from, int to) {
    for (int f = from; f <= to; ++f) {
      test::drive(sim, f);
      SINEW_ASSERT_OK(sim.graspers().move(*sim.graspers().grasper(0), jaws_at(f)));
      SINEW_ASSERT_OK(sim.step());
    }
  };
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  run(*sim, 1, 4);
  auto held = sim->graspers().close(*sim->graspers().grasper(0), jaws_at(4), {0.006, 0.006, 0.015});
  ASSERT_TRUE(held.ok()) << held.error().message();
  ASSERT_FALSE(held->empty());
  lift(*sim, 5, 10);
  SavedState at10;
  SINEW_ASSERT_OK(sim->save_state(at10));
  const std::string file = tmp_path("grasper_" + GetParam() + ".state");
  SINEW_ASSERT_OK(sim->save_state(file));
  const Snapshot frame10 = snapshot(*sim);
  lift(*sim, 11, 20);
  const Snapshot frame20 = snapshot(*sim);
  ASSERT_FALSE(same_bits(frame10, frame20));

  // The same Simulation, its grasper opened since the save.
  ASSERT_TRUE(sim->graspers().open(*sim->graspers().grasper(0)).ok());
  SINEW_ASSERT_OK(sim->restore_state(at10));
  EXPECT_TRUE(same_bits(snapshot(*sim), frame10));
  lift(*sim, 11, 20);
  EXPECT_TRUE(same_bits(snapshot(*sim), frame20)) << "restored after opening the grasper, on " << GetParam();

  // A new Simulation whose grasper never closed, from the file.
  auto fresh = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(fresh.ok()) << fresh.error().message();
  SINEW_ASSERT_OK(fresh->restore_state(file));
  lift(*fresh, 11, 20);
  EXPECT_TRUE(same_bits(snapshot(*fresh), frame20)) << "restored from a file in a new Simulation, on " << GetParam();
  // It holds what it held: opening it releases the same particles.
  auto released = fresh->graspers().open(*fresh->graspers().grasper(0));
  ASSERT_TRUE(released.ok());
  EXPECT_EQ(*released, *held);

  // And a state saved with the grasper open opens a closed one.
  SavedState open_state;
  auto other = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(other.ok());
  run(*other, 1, 4);
  SINEW_ASSERT_OK(other->save_state(open_state));
  run(*other, 5, 8);
  const Snapshot open8 = snapshot(*other);
  auto again = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(again.ok());
  run(*again, 1, 4);
  ASSERT_TRUE(again->graspers().close(*again->graspers().grasper(0), jaws_at(4), {0.006, 0.006, 0.015}).ok());
  SINEW_ASSERT_OK(again->restore_state(open_state));
  run(*again, 5, 8);
  EXPECT_TRUE(same_bits(snapshot(*again), open8)) << "an open grasper's state, on " << GetParam();
}

TEST_P(SavedStateTest, RestoreWithMeshCollisionIsBitwise) {
  // Two blocks dropped onto each other: the contacts of the frames after
  // the restore are found again from the restored positions.
  expect_restore_bitwise(test::dropped_blocks_scene(ContactSchedule::colored), GetParam(), 20, 40);
}

TEST_P(SavedStateTest, RestoreWithContinuousCollisionIsBitwise) {
  // The linked rings of the thread tests hanging from their two targets,
  // falling onto each other under gravity.
  SceneDesc scene = test::LinkedRings::scene(/*continuous=*/true);
  scene.gravity = {0.0, -9.81, 0.0};
  expect_restore_bitwise(scene, GetParam(), 10, 25);
}

TEST_P(SavedStateTest, RestoreWithAFluidIsBitwise) {
  // Fluid poured into the tissue cup of the fluid tests, coupled both ways:
  // the fluid's particles, their grid and counts are in the state.
  const SceneDesc scene = test::cup_scene(true, {0, -9.81, 0},
                                          test::fluid_block(4, 3, 4, {2 * test::kCupCell, 1.5 * test::kCupCell,
                                                                      2 * test::kCupCell}));
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  for (int f = 1; f <= 20; ++f) SINEW_ASSERT_OK(sim->step());
  SavedState state;
  SINEW_ASSERT_OK(sim->save_state(state));
  std::vector<FluidParticle> saved_fluid;
  SINEW_ASSERT_OK(sim->fluid().read(saved_fluid));
  for (int f = 21; f <= 40; ++f) SINEW_ASSERT_OK(sim->step());
  std::vector<FluidParticle> fluid40, again;
  SINEW_ASSERT_OK(sim->fluid().read(fluid40));
  const Snapshot tissue40 = snapshot(*sim);
  SINEW_ASSERT_OK(sim->restore_state(state));
  for (int f = 21; f <= 40; ++f) SINEW_ASSERT_OK(sim->step());
  SINEW_ASSERT_OK(sim->fluid().read(again));
  EXPECT_TRUE(same_bits(snapshot(*sim), tissue40)) << "the tissue, on " << GetParam();
  ASSERT_EQ(again.size(), fluid40.size());
  ASSERT_EQ(saved_fluid.size(), fluid40.size());
  EXPECT_NE(std::memcmp(saved_fluid.data(), fluid40.data(), fluid40.size() * sizeof(FluidParticle)), 0);  // it moved
  EXPECT_EQ(std::memcmp(again.data(), fluid40.data(), fluid40.size() * sizeof(FluidParticle)), 0)
      << "the fluid, on " << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Backends, SavedStateTest, ::testing::ValuesIn(test::backends()), test::backend_name);

// ---- Damaged and foreign states (the format is the same on every backend: CPU only).

class SavedStateFile : public ::testing::Test {
 protected:
  void SetUp() override {
    auto made = Simulation::create(test::robustness_block(), {.backend = "cpu", .quiet = true});
    ASSERT_TRUE(made.ok()) << made.error().message();
    sim_.emplace(std::move(*made));
    run(*sim_, 1, 2);
    SINEW_ASSERT_OK(sim_->save_state(good_));
    run(*sim_, 3, 4);
    at4_ = snapshot(*sim_);
  }
  // restore_state of `bytes` written to a file: a named error of `code` whose message holds `says`.
  void expect_refused(const std::vector<std::byte>& bytes, ErrorCode code, const std::string& says) {
    const std::string file = tmp_path("bad.state");
    {
      std::ofstream out(file, std::ios::binary | std::ios::trunc);
      out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    }
    const Status s = sim_->restore_state(file);
    ASSERT_FALSE(s.ok()) << "accepted a state that should fail with: " << says;
    EXPECT_EQ(s.error().code(), code) << s.error().message();
    EXPECT_NE(s.error().message().find(says), std::string::npos) << s.error().message();
    EXPECT_TRUE(same_bits(snapshot(*sim_), at4_));  // the Simulation is left as it was
    EXPECT_EQ(sim_->last_frame().frame, 4u);
  }
  std::optional<Simulation> sim_;
  SavedState good_;
  Snapshot at4_;
};

TEST_F(SavedStateFile, TruncatedFileIsANamedError) {
  std::vector<std::byte> bytes = good_.bytes;
  bytes.resize(bytes.size() - 100);
  expect_refused(bytes, ErrorCode::bad_input_file, "truncated");
  bytes.resize(10);
  expect_refused(bytes, ErrorCode::bad_input_file, "header");
}

TEST_F(SavedStateFile, ForeignFileIsANamedError) {
  std::vector<std::byte> bytes = good_.bytes;
  bytes[0] = std::byte{'X'};
  expect_refused(bytes, ErrorCode::bad_input_file, "magic");
  const std::string text = "solid cube\n  facet normal 0 0 1\nendsolid cube\n padding padding padding padding";
  std::vector<std::byte> stl(text.size());
  std::memcpy(stl.data(), text.data(), text.size());
  expect_refused(stl, ErrorCode::bad_input_file, "magic");
}

TEST_F(SavedStateFile, NewerVersionIsANamedError) {
  std::vector<std::byte> bytes = good_.bytes;
  const std::uint32_t version = kSavedStateVersion + 1;
  std::memcpy(bytes.data() + 8, &version, 4);
  expect_refused(bytes, ErrorCode::bad_input_file, "version");
}

// `state` as version 1 wrote it: the payload less its last `drop` bytes.
std::vector<std::byte> as_version_1(const SavedState& state, std::size_t drop) {
  return test::rewritten(state, drop, 1).bytes;
}

TEST_F(SavedStateFile, VersionOneStatesAreRead) {
  // Without mesh collision version 2 adds nothing: the same payload is the same state.
  SavedState v1{as_version_1(good_, 0)};
  SINEW_ASSERT_OK(sim_->restore_state(v1));
  run(*sim_, 3, 4);
  EXPECT_TRUE(same_bits(snapshot(*sim_), at4_));
  // With it, version 1 lacks the velocities the next frame's contacts are
  // sought with (the last array: the scene has no fluid); it is read, and
  // the frames after it measure them from the device's, as a first frame does.
  auto blocks = Simulation::create(test::dropped_blocks_scene(ContactSchedule::colored), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(blocks.ok()) << blocks.error().message();
  for (int f = 1; f <= 5; ++f) SINEW_ASSERT_OK(blocks->step());
  SavedState at5;
  SINEW_ASSERT_OK(blocks->save_state(at5));
  std::vector<float> x;
  SINEW_ASSERT_OK(blocks->read_positions(x));
  const std::size_t velocities = 8 + x.size() * sizeof(float);  // their length, then xyzw per particle
  SavedState cut{as_version_1(at5, velocities)};
  SINEW_ASSERT_OK(blocks->restore_state(cut));
  EXPECT_EQ(blocks->last_frame().frame, 5u);
  for (int f = 6; f <= 8; ++f) SINEW_ASSERT_OK(blocks->step());
  // The same payload as version 2 is short of them: a named error.
  cut.bytes[8] = std::byte{2};
  const Status short_of = blocks->restore_state(cut);
  ASSERT_FALSE(short_of.ok());
  EXPECT_NE(short_of.error().message().find("ends early"), std::string::npos) << short_of.error().message();
}

TEST_F(SavedStateFile, DamagedPayloadIsANamedError) {
  std::vector<std::byte> bytes = good_.bytes;
  bytes[bytes.size() / 2] ^= std::byte{0x40};
  expect_refused(bytes, ErrorCode::bad_input_file, "hash");
}

TEST_F(SavedStateFile, AnotherScenesStateIsANamedError) {
  SceneDesc other = test::robustness_block();
  other.tet_bodies[0].mesh = test::box_mesh(5, 2, 2, 0.01);
  other.tet_bodies[0].pinned = {0};
  other.attachments.clear();
  other.targets.clear();
  auto sim = Simulation::create(other, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  SavedState foreign;
  SINEW_ASSERT_OK(sim->save_state(foreign));
  expect_refused(foreign.bytes, ErrorCode::bad_parameter, "another scene");
}

TEST_F(SavedStateFile, MissingFileIsANamedError) {
  const Status s = sim_->restore_state(tmp_path("no_such_file.state"));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::bad_input_file);
  EXPECT_NE(s.error().message().find("no_such_file.state"), std::string::npos);
}

}  // namespace
}  // namespace sinew
