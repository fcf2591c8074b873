// saved_topology_test.cpp — saved states across topology changes, level-set
// cuts and needles: a state saved before or after removals, cuts, cautery,
// tears or a level-set cut, restored into the same Simulation (which has
// made more changes since, or other ones) or into a new one, and stepped
// with the same inputs, gives bitwise the run that was never interrupted,
// with the same constraint slots; so does a needle and its thread saved
// mid-insertion. On every backend (a missing device skips). Damaged logs
// are named errors.
#include <algorithm>
#include <cstring>
#include <limits>
#include <map>

#include "robustness_scenes.h"
#include "runtime/simulation_internals.h"
#include "runtime/state_format.h"
#include "saved_state_support.h"
#include "mesh_contact_support.h"
#include "sinew/level_set.h"

namespace sinew {
namespace {

using test::same_bits;
using test::snapshot;
using test::Snapshot;

class SavedTopologyTest : public test::BackendTest {};

std::vector<std::uint32_t> slots(const Simulation& sim) {
  auto words = SimulationInternals::constraint_words(sim);
  EXPECT_TRUE(words.ok()) << words.error().message();
  return words.ok() ? *words : std::vector<std::uint32_t>{};
}

// A run of `scene` on `backend` whose frames [from, to] run(sim, from, to)
// steps with their inputs and changes: saved after frame `early` and after
// `late`, run to `end`; then `early` restored into the same Simulation (which
// has made every later change) and `late` into a new one (which has made
// none), each run on to `end`, must end bitwise where the uninterrupted run
// did, the new one with the slots the state was saved with.
template <class Run>
void expect_restores_either_way(const SceneDesc& scene, const std::string& backend, Run run, int early, int late,
                                int end) {
  auto sim = test::create_or_skip(scene, backend);
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  SavedState first, second;
  run(*sim, 1, early);
  SINEW_ASSERT_OK(sim->save_state(first));
  run(*sim, early + 1, late);
  SINEW_ASSERT_OK(sim->save_state(second));
  const std::vector<std::uint32_t> slots_then = slots(*sim);
  const Snapshot at_late = snapshot(*sim);
  run(*sim, late + 1, end);
  const Snapshot uninterrupted = snapshot(*sim);
  ASSERT_FALSE(same_bits(at_late, uninterrupted));  // the scene moves: the comparisons below can fail
  SINEW_ASSERT_OK(sim->restore_state(first));
  run(*sim, early + 1, end);
  EXPECT_TRUE(same_bits(snapshot(*sim), uninterrupted)) << "restored after frame " << early << ", on " << backend;
  auto fresh = test::create_or_skip(scene, backend);
  ASSERT_TRUE(fresh.ok()) << fresh.error().message();
  SINEW_ASSERT_OK(fresh->restore_state(second));
  EXPECT_EQ(slots(*fresh), slots_then);
  run(*fresh, late + 1, end);
  EXPECT_TRUE(same_bits(snapshot(*fresh), uninterrupted))
      << "restored after frame " << late << " in a new Simulation, on " << backend;
}

// The block of the robustness tests with topology changes, driven as there
// (test::drive), and changed between frames as a function of the frame
// alone: after frame 3 a hole removed from its middle, after frame 6 a cut
// down through its free end, from frame 8 to 10 a cautery tip on its top
// (its dwell time reached on the second touch: the heat carries between
// frames).
void change(Simulation& sim, int frame) {
  auto body = sim.topology().tet_body(0);
  ASSERT_TRUE(body.ok());
  if (frame == 3) {
    const std::vector<std::uint32_t> hole{40, 41, 42, 43, 44, 45};
    auto removed = sim.topology().remove_tets(*body, hole);
    ASSERT_TRUE(removed.ok()) << removed.error().message();
  }
  if (frame == 6) {
    auto cut = sim.topology().cut(*body, {{0.033, 0.03, -0.01}, {0.033, 0.03, 0.03}},
                                  {{0.033, 0.005, -0.01}, {0.033, 0.005, 0.03}});
    ASSERT_TRUE(cut.ok()) << cut.error().message();
    EXPECT_FALSE(cut->tets_removed.empty());
  }
  if (frame >= 8 && frame <= 10) {
    auto burned = sim.topology().cauterize(*body, {0.015, 0.018, 0.01}, 0.009, 1.0 / 60.0, 1.5 / 60.0);
    ASSERT_TRUE(burned.ok()) << burned.error().message();
    if (frame < 10) {  // at 10 the tip may reach tets the burn at 9 uncovered, or none
      EXPECT_EQ(burned->tets_removed.empty(), frame == 8) << "frame " << frame;
    }
  }
}

// Frames [from, to], each with its inputs and its changes after it.
void run(Simulation& sim, int from, int to) {
  for (int f = from; f <= to; ++f) {
    test::drive(sim, f);
    SINEW_ASSERT_OK(sim.step());
    change(sim, f);
  }
}

TEST_P(SavedTopologyTest, RemovalsCutsAndCauteryRestoreBitwiseEitherWay) {
  const SceneDesc scene = test::robustness_block(/*topology=*/true);
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  // States after frames 2 (no change yet), 7 (hole and cut) and 9 (cautery heat
  // and a first burn), each with the constraint slots then.
  std::map<int, SavedState> state;
  std::map<int, std::vector<std::uint32_t>> slots_at;
  for (int f = 1; f <= 14; ++f) {
    run(*sim, f, f);
    if (f == 2 || f == 7 || f == 9) {
      SINEW_ASSERT_OK(sim->save_state(state[f]));
      slots_at[f] = slots(*sim);
    }
  }
  const Snapshot uninterrupted = snapshot(*sim);
  const std::vector<std::uint32_t> slots14 = slots(*sim);
  ASSERT_NE(slots_at[2], slots14);  // the changes changed the slots

  // The same Simulation, which has made every change since: back before
  // all of them (it is made again), then forward across some (replayed).
  SINEW_ASSERT_OK(sim->restore_state(state[2]));
  EXPECT_EQ(slots(*sim), slots_at[2]);
  SINEW_ASSERT_OK(sim->restore_state(state[9]));
  EXPECT_EQ(slots(*sim), slots_at[9]);
  SINEW_ASSERT_OK(sim->restore_state(state[7]));  // fewer changes than it has made
  EXPECT_EQ(slots(*sim), slots_at[7]);
  run(*sim, 8, 14);
  EXPECT_TRUE(same_bits(snapshot(*sim), uninterrupted)) << "restored back across the changes, on " << GetParam();
  EXPECT_EQ(slots(*sim), slots14);
  // Its ids still name it.
  EXPECT_TRUE(sim->tools().state(*sim->tools().tool(0)).ok());

  // A new Simulation, from the state after the hole and the cut (replayed).
  auto fresh = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(fresh.ok()) << fresh.error().message();
  SINEW_ASSERT_OK(fresh->restore_state(state[9]));
  EXPECT_EQ(slots(*fresh), slots_at[9]);
  run(*fresh, 10, 14);
  EXPECT_TRUE(same_bits(snapshot(*fresh), uninterrupted)) << "restored in a new Simulation, on " << GetParam();
  EXPECT_EQ(slots(*fresh), slots14);
}

// A membrane hanging from its edge z = 0 and a thread hanging beside it,
// changed between frames: after frame 2 four triangles removed, after frame 3
// two of the thread's segments broken, after frames 4 to 6 a cautery tip on
// the membrane's pinned edge (its dwell time reached on the second touch).
SceneDesc sheet_and_thread() {
  SceneDesc scene;
  scene.solver.substeps = 8;
  scene.solver.iterations = 4;
  TriBodyDesc sheet;
  sheet.mesh = test::membrane(8, 8, 0.005, 0.0);
  for (std::uint32_t v = 0; v <= 8; ++v) sheet.pinned.push_back(v * 9);  // k = 0
  scene.tri_bodies.push_back(sheet);
  LineBodyDesc thread;
  for (std::uint32_t i = 0; i <= 10; ++i) {
    thread.vertices.push_back({0.05, 0.0, 0.004 * i});
    thread.masses.push_back(1e-4);
    if (i < 10) thread.segments.push_back({i, i + 1});
  }
  thread.pinned = {0};
  scene.line_bodies.push_back(thread);
  scene.topology_changes = true;
  return scene;
}

void run_sheet(Simulation& sim, int from, int to) {
  Topology t = sim.topology();
  for (int f = from; f <= to; ++f) {
    SINEW_ASSERT_OK(sim.step());
    if (f == 2) {
      const std::vector<std::uint32_t> triangles{60, 61, 62, 63};
      ASSERT_TRUE(t.remove_triangles(*t.tri_body(0), triangles).ok());
    }
    if (f == 3) {
      const std::vector<std::uint32_t> segments{7, 3};
      ASSERT_TRUE(t.remove_segments(*t.line_body(0), segments).ok());
    }
    if (f >= 4 && f <= 6) {
      // At the pinned edge, where the sheet swinging down moves least.
      auto burned = t.cauterize(*t.tri_body(0), {0.02, 0.0, 0.003}, 0.008, 1.0 / 60.0, 1.5 / 60.0);
      ASSERT_TRUE(burned.ok()) << burned.error().message();
      if (f < 6) {
        EXPECT_EQ(burned->triangles_removed.empty(), f == 4) << "frame " << f;
      }
    }
  }
}

TEST_P(SavedTopologyTest, TrianglesSegmentsAndTheirCauteryRestoreBitwiseEitherWay) {
  expect_restores_either_way(sheet_and_thread(), GetParam(), run_sheet, 1, 4, 12);
}

// A strip of 10 x 1 x 1 cells pinned at both ends and held 30% beyond its
// length: it tears within the first frames (topology_test.cpp's).
SceneDesc torn_strip() {
  SceneDesc scene;
  TetBodyDesc strip;
  strip.mesh = test::box_mesh(10, 1, 1, 0.002);
  (void)strip.set_elastic(3e5, 0.3);
  strip.density = 1000.0;
  for (std::uint32_t v = 0; v < strip.mesh.vertices.size(); ++v) {
    const Vec3d& p = strip.mesh.vertices[v];
    if (p[0] < 1e-9 || p[0] > 0.02 - 1e-9) strip.pinned.push_back(v);
    strip.initial_vertices.push_back({p[0] * 1.3, p[1], p[2]});
  }
  strip.tear_strain = 0.2;
  scene.tet_bodies.push_back(strip);
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 40;
  scene.topology_changes = true;
  return scene;
}

TEST_P(SavedTopologyTest, TearsRestoreBitwiseEitherWay) {
  std::size_t tears = 0;
  const auto run_strip = [&](Simulation& sim, int from, int to) {
    for (int f = from; f <= to; ++f) {
      SINEW_ASSERT_OK(sim.step());
      tears += sim.topology().last_tears().size();
    }
  };
  // Saved before the first frame (which tears) and after the tenth.
  expect_restores_either_way(torn_strip(), GetParam(), run_strip, 0, 10, 20);
  EXPECT_GT(tears, 0u);
}

// A stage that reports the frame's kinetic energy as NaN, after the tears
// (it runs after the scene's stages): the frame that tore diverges.
class DivergeAfterTears final : public FrameStage {
 public:
  std::string_view name() const override { return "diverge after tears"; }
  Status after_frame(FrameContext& frame) override {
    frame.stats.kinetic_energy = std::numeric_limits<double>::quiet_NaN();
    return {};
  }
};

TEST_P(SavedTopologyTest, AFrameThatToreAndDivergedRollsBackBeforeTheTears) {
  const SceneDesc scene = torn_strip();
  auto plain = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(plain.ok()) << plain.error().message();
  SINEW_ASSERT_OK(plain->step());
  ASSERT_FALSE(plain->topology().last_tears().empty());  // the first frame tears
  const Snapshot frame1 = snapshot(*plain);
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok());
  SINEW_ASSERT_OK(sim->set_divergence_settings({.on_divergence = OnDivergence::roll_back}));
  const Snapshot frame0 = snapshot(*sim);
  SimulationInternals::add_stage(*sim, std::make_unique<DivergeAfterTears>());
  SINEW_ASSERT_OK(sim->step());  // tears, diverges, rolls back (the Simulation made again, without the stage)
  EXPECT_TRUE(sim->last_frame().divergence.rolled_back);
  EXPECT_EQ(sim->last_frame().frame, 0u);
  EXPECT_TRUE(same_bits(snapshot(*sim), frame0));
  auto tets = sim->topology().current_tets(*sim->topology().tet_body(0));
  ASSERT_TRUE(tets.ok());
  EXPECT_EQ(tets->size(), scene.tet_bodies[0].mesh.tets.size());  // whole again
  SINEW_ASSERT_OK(sim->step());
  EXPECT_FALSE(sim->last_frame().divergence.rolled_back);
  EXPECT_TRUE(same_bits(snapshot(*sim), frame1)) << "the frame again, on " << GetParam();
}

#if SINEW_HAS_OPENVDB
// A cloth resting on a solid level-set block (its inside stored, so it can be
// cut) with a burr drilling through it under the cloth after frame 8.
SceneDesc cloth_on_block() {
  SceneDesc scene;
  scene.solver.substeps = 8;
  scene.solver.iterations = 10;
  TriBodyDesc cloth;
  cloth.mesh = test::membrane(10, 10, 0.002, 0.0);
  for (auto& v : cloth.mesh.vertices) v = {v[0] - 0.01, 0.003, v[2] - 0.01};
  cloth.velocity_damping = 2.0;
  scene.tri_bodies.push_back(cloth);
  auto block = LevelSet::box({-0.015, -0.01, -0.015}, {0.015, 0.0, 0.015},
                             {.voxel_size = 5e-4, .exterior_band = 2e-3, .interior_band = INFINITY});
  EXPECT_TRUE(block.ok()) << block.error().message();
  ColliderDesc collider;
  collider.shape = ColliderShape::level_set;
  if (block.ok()) collider.level_set = *block;
  scene.colliders.push_back(collider);
  return scene;
}

void run_cloth(Simulation& sim, int from, int to) {
  for (int f = from; f <= to; ++f) {
    SINEW_ASSERT_OK(sim.step());
    if (f != 8) continue;
    auto cut = sim.tools().cut(*sim.tools().collider(0), {.radius = 0.006}, {.position = {0.0, 0.002, 0.0}},
                               {.position = {0.0, -0.02, 0.0}});
    ASSERT_TRUE(cut.ok()) << cut.error().message();
    EXPECT_GT(cut->removed_volume, 0.0);
  }
}

TEST_P(SavedTopologyTest, ALevelSetCutRestoresBitwiseEitherWay) {
  // Saved before the cut (the block whole again, then cut again) and after it.
  expect_restores_either_way(cloth_on_block(), GetParam(), run_cloth, 5, 12, 30);
}
#endif

// A pinned pad (12 x 10 x 12 mm of 2 mm cells) and a straight needle with a
// thread tied to its tail, driven down into the pad 0.5 mm a frame.
SceneDesc needle_and_thread() {
  SceneDesc scene;
  scene.gravity = {0.0, -9.81, 0.0};
  scene.solver.substeps = 8;
  scene.solver.iterations = 10;
  auto mesh = make_tet_grid({.nx = 6, .ny = 5, .nz = 6, .origin = {-0.006, -0.01, -0.006},
                             .cell_size = {0.002, 0.002, 0.002}});
  EXPECT_TRUE(mesh.ok());
  TetBodyDesc pad;
  if (mesh.ok()) pad.mesh = *mesh;
  (void)pad.set_elastic(3e4, 0.45);
  pad.velocity_damping = 5.0;
  for (std::uint32_t v = 0; v < pad.mesh.vertices.size(); ++v)
    if (pad.mesh.vertices[v][1] < -0.01 + 1e-9) pad.pinned.push_back(v);
  scene.tet_bodies.push_back(pad);
  LineBodyDesc thread;
  for (std::uint32_t i = 0; i <= 20; ++i) {
    thread.vertices.push_back({0.0007 + 0.001 * i, 0.0102, 0.0009});  // from the needle's tail, sideways
    thread.masses.push_back(1e-5);
    if (i < 20) thread.segments.push_back({i, i + 1});
  }
  thread.velocity_damping = 5.0;
  scene.line_bodies.push_back(thread);
  NeedleDesc needle;
  needle.curve = {{0.0, 0.01, 0.0}, {0.0, 0.0, 0.0}};  // tail up, tip at its origin
  needle.position = {0.0007, 0.0002, 0.0009};
  needle.puncture_force = 0.01;
  needle.thread = 0;
  scene.needles.push_back(needle);
  return scene;
}

void push(Simulation& sim, int from, int to) {
  auto id = sim.needles().needle(0);
  ASSERT_TRUE(id.ok());
  for (int f = from; f <= to; ++f) {
    SINEW_ASSERT_OK(sim.needles().set_pose(*id, {0.0007, 0.0002 - 0.0005 * f, 0.0009}, {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim.step());
  }
}

TEST_P(SavedTopologyTest, ANeedleAndThreadSavedMidInsertionRestoreBitwise) {
  const SceneDesc scene = needle_and_thread();
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  auto id = sim->needles().needle(0);
  ASSERT_TRUE(id.ok());
  push(*sim, 1, 10);
  auto at10 = sim->needles().state(*id);
  ASSERT_TRUE(at10.ok());
  ASSERT_FALSE(at10->punctures.empty()) << "the needle should be in the pad by now";
  SavedState state;
  SINEW_ASSERT_OK(sim->save_state(state));
  push(*sim, 11, 20);
  const Snapshot uninterrupted = snapshot(*sim);
  const auto end = sim->needles().state(*id);
  ASSERT_TRUE(end.ok());
  const auto expect_same_needle = [&](Simulation& s, const char* how) {
    EXPECT_TRUE(same_bits(snapshot(s), uninterrupted)) << how << ", on " << GetParam();
    auto got = s.needles().state(*s.needles().needle(0));
    ASSERT_TRUE(got.ok());
    EXPECT_EQ(got->punctures.size(), end->punctures.size()) << how;
    EXPECT_EQ(std::memcmp(got->reaction_force.data(), end->reaction_force.data(), sizeof end->reaction_force), 0)
        << how;
  };
  SINEW_ASSERT_OK(sim->restore_state(state));
  push(*sim, 11, 20);
  expect_same_needle(*sim, "restored in the same Simulation");
  auto fresh = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(fresh.ok());
  SINEW_ASSERT_OK(fresh->restore_state(state));
  push(*fresh, 11, 20);
  expect_same_needle(*fresh, "restored in a new Simulation");
}

INSTANTIATE_TEST_SUITE_P(Backends, SavedTopologyTest, ::testing::ValuesIn(test::backends()), test::backend_name);

// A log that removes an element twice, or one that does not exist, is a
// named error that leaves the Simulation as it was (CPU: the format is the
// same on every backend).
TEST(SavedTopologyLog, ADamagedLogIsANamedError) {
  const SceneDesc scene = test::robustness_block(/*topology=*/true);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  run(*sim, 1, 4);  // the hole after frame 3
  SavedState good;
  SINEW_ASSERT_OK(sim->save_state(good));
  const Snapshot at4 = snapshot(*sim);
  // The hole's elements as the log holds them, then made 40, 40 or 40, 999999.
  const std::uint32_t hole[6] = {40, 41, 42, 43, 44, 45};
  const auto at = std::search(good.bytes.begin(), good.bytes.end(), reinterpret_cast<const std::byte*>(hole),
                              reinterpret_cast<const std::byte*>(hole) + sizeof hole);
  ASSERT_NE(at, good.bytes.end());
  const std::size_t offset = static_cast<std::size_t>(at - good.bytes.begin());
  for (const auto& [element, says] : {std::pair<std::uint32_t, const char*>{40, "a second time"}, {999999, "does not exist"}}) {
    const SavedState bad = test::rewritten(good, 0, kSavedStateVersion, [&](std::vector<std::byte>& payload) {
      std::memcpy(payload.data() + offset - state_format::kHeaderBytes + 4, &element, 4);
    });
    const Status s = sim->restore_state(bad);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code(), ErrorCode::bad_parameter);
    EXPECT_NE(s.error().message().find(says), std::string::npos) << s.error().message();
    EXPECT_TRUE(same_bits(snapshot(*sim), at4));
  }
}

TEST(SavedTopologyLog, VersionThreeStatesRestoreOnlyWithoutChanges) {
  const SceneDesc scene = test::robustness_block(/*topology=*/true);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  const std::size_t tets = scene.tet_bodies[0].mesh.tets.size();
  const std::size_t heat = 8 + 8 * tets;  // its length, then a double per tet
  run(*sim, 1, 2);
  SavedState at2;
  SINEW_ASSERT_OK(sim->save_state(at2));
  run(*sim, 3, 5);  // the hole after frame 3
  const Snapshot at5 = snapshot(*sim);
  SavedState at5_state;
  SINEW_ASSERT_OK(sim->save_state(at5_state));
  // Saved before any change: read, with no log (the Simulation made again: it has made one since).
  SINEW_ASSERT_OK(sim->restore_state(test::rewritten(at2, 8 + heat, 3)));
  run(*sim, 3, 5);
  EXPECT_TRUE(same_bits(snapshot(*sim), at5));
  // Saved after one: that version did not hold it.
  const std::size_t log = 8 + 2 + 8 + 8 + 4 * 6;  // one record: kind and burn, body, the hole's 6 tets
  const Status s = sim->restore_state(test::rewritten(at5_state, log + heat, 3));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("format version 3"), std::string::npos) << s.error().message();
}

// A needle's row that is not of the scene (its kind, here) is a named error.
TEST(SavedTopologyLog, ADamagedNeedleRowIsANamedError) {
  auto sim = Simulation::create(needle_and_thread(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  push(*sim, 1, 10);
  SavedState good;
  SINEW_ASSERT_OK(sim->save_state(good));
  // The needles end the payload (no topology changes, no level set): the
  // last row is its 8 words, 4 weights, surface, triangle, exit and slip.
  const std::size_t row = 8 * 4 + 4 * 4 + 4 + 4 + 1 + 4;
  const std::uint32_t kind = 99;
  const SavedState bad = test::rewritten(good, 0, kSavedStateVersion, [&](std::vector<std::byte>& payload) {
    std::memcpy(payload.data() + payload.size() - row, &kind, 4);
  });
  const Status s = sim->restore_state(bad);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code(), ErrorCode::bad_parameter);
  EXPECT_NE(s.error().message().find("its kind"), std::string::npos) << s.error().message();
  SINEW_ASSERT_OK(sim->restore_state(good));
}

// A Simulation made on a device given to it cannot be made again: a state
// whose changes do not continue its own is a named error, nothing changed.
TEST(SavedTopologyLog, AGivenDeviceCannotBeMadeAgain) {
  const SceneDesc scene = test::robustness_block(/*topology=*/true);
  auto device = create_device({.backend = "cpu", .quiet = true});
  ASSERT_TRUE(device.ok());
  auto sim = SimulationInternals::create(scene, std::move(*device));
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  run(*sim, 1, 2);
  SavedState before;
  SINEW_ASSERT_OK(sim->save_state(before));
  run(*sim, 3, 4);  // the hole after frame 3
  const Snapshot at4 = snapshot(*sim);
  const Status s = sim->restore_state(before);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("device given"), std::string::npos) << s.error().message();
  EXPECT_TRUE(same_bits(snapshot(*sim), at4));
}

}  // namespace
}  // namespace sinew
