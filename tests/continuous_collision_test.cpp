// continuous_collision_test.cpp — continuous collision detection in the
// solver (issue 13, part 3; MeshCollisionDesc::continuous): threads pulled
// fast against each other and into a membrane never pass through, checked
// by topology (a linking number, which side of the membrane each thread
// vertex is on) computed from the positions alone, on every backend; the
// search on its own; the fail-safe; and the settings' errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "math/vec3.h"
#include "mesh_contact_support.h"
#include "runtime/continuous_collision.h"
#include "test_support.h"
#include "thread_scenes.h"
#include "thread_topology.h"

namespace sinew::test {
namespace {

class ContinuousCollisionTest : public BackendTest {};

// The rings' linking count from the positions.
LinkingCount linking(const Simulation& sim) {
  std::vector<float> x;
  EXPECT_TRUE(sim.read_positions(x).ok());
  std::vector<Point3> a, b;
  for (int i = 0; i < LinkedRings::n; ++i) a.push_back(at(x, static_cast<std::uint32_t>(i)));
  for (int i = 0; i < LinkedRings::n; ++i) b.push_back(at(x, static_cast<std::uint32_t>(LinkedRings::n + i)));
  return linking_count(a, b);
}

struct RunSummary {
  int first_change = -1;  // the first frame whose linking number differs from the start's (-1: none)
  std::uint32_t hits = 0, repairs = 0, reverted = 0;
};

RunSummary pull_rings(Simulation& sim, double speed, int frames, double frame = kFrame) {
  RunSummary out;
  const LinkingCount start = linking(sim);
  EXPECT_EQ(start.over, start.under);
  EXPECT_EQ(std::abs(start.over), 1) << "the rings start linked";
  for (int f = 0; f < frames; ++f) {
    EXPECT_TRUE(LinkedRings::drive(sim, f, speed, frame).ok());
    const Status s = sim.step();
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) break;
    const FrameStats& st = sim.last_frame();
    out.hits += st.ccd_hits;
    out.repairs += st.ccd_repairs;
    out.reverted += st.ccd_reverted;
    const LinkingCount now = linking(sim);
    EXPECT_EQ(now.over, now.under) << "frame " << f << ": a degenerate projection";
    if (out.first_change < 0 && now.over != start.over) out.first_change = f;
  }
  return out;
}

// The rings pulled apart at 1 m/s (a tool's speed; 2 m/s between them) and
// held tight for half a second: they stay linked, every frame. The pull
// asks for more than the rings can stretch, so the solver cannot meet every
// constraint and the touches keep coming: CCD finds them (hits), its
// contacts resolve them (repairs), and the rest are stopped by the
// fail-safe. (Without it they come apart: the next test.)
TEST_P(ContinuousCollisionTest, LinkedRingsPulledApartAtAToolsSpeedStayLinked) {
  auto sim = create_or_skip(LinkedRings::scene(true), GetParam());
  SINEW_ASSERT_OK(sim);
  const RunSummary run = pull_rings(*sim, 1.0, 30);
  std::printf("[%s] linking changed at frame %d; %u touches, %u repair rounds, %u particles stopped\n",
              GetParam().c_str(), run.first_change, run.hits, run.repairs, run.reverted);
  EXPECT_EQ(run.first_change, -1);
  EXPECT_GT(run.hits, 0u) << "the pull must make the rings touch, or the test shows nothing";
  std::vector<float> x;
  SINEW_ASSERT_OK(sim->read_positions(x));
  for (float v : x) ASSERT_TRUE(std::isfinite(v));
}

// A crossing and its undoing within one frame would leave the frame's
// linking number as it was: here a frame is one substep (1/480 s, the
// substep of the test above), so the linking number is checked after every
// substep of the same pull.
TEST_P(ContinuousCollisionTest, LinkedRingsStayLinkedAfterEverySubstep) {
  SceneDesc scene = LinkedRings::scene(true);
  scene.solver.substeps = 1;
  scene.solver.time_step = kFrame / 8.0;
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const RunSummary run = pull_rings(*sim, 1.0, 8 * 20, kFrame / 8.0);
  std::printf("[%s] per substep: linking changed at substep %d; %u touches, %u repair rounds, %u particles stopped\n",
              GetParam().c_str(), run.first_change, run.hits, run.repairs, run.reverted);
  EXPECT_EQ(run.first_change, -1);
  EXPECT_GT(run.hits, 0u);
}

// The same pull with the frame's contacts only (continuous off): the rings
// pass through each other within the second frame. What the test above
// guards against is real.
TEST(ContinuousCollision, WithoutItTheLinkedRingsComeApart) {
  auto sim = Simulation::create(LinkedRings::scene(false), {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const RunSummary run = pull_rings(*sim, 1.0, 30);
  EXPECT_GE(run.first_change, 0);
}

// The residual-driven mode runs the same search after each substep has
// converged (or stopped): the rings stay linked there too.
TEST(ContinuousCollision, LinkedRingsStayLinkedInTheResidualMode) {
  SceneDesc scene = LinkedRings::scene(true);
  scene.solver.residual_tolerance = 1e-3;
  scene.solver.max_iterations = 40;
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const RunSummary run = pull_rings(*sim, 1.0, 20);
  EXPECT_EQ(run.first_change, -1);
  EXPECT_GT(run.hits, 0u);
}

// No repair rounds (continuous_repairs = 0): every touch stops its
// particles at their substep's start at once. The rings still stay linked;
// the particles stopped are counted.
TEST(ContinuousCollision, TheFailSafeAloneKeepsTheRingsLinked) {
  SceneDesc scene = LinkedRings::scene(true);
  scene.mesh_collision.continuous_repairs = 0;
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const RunSummary run = pull_rings(*sim, 1.0, 20);
  EXPECT_EQ(run.first_change, -1);
  EXPECT_EQ(run.repairs, 0u);
  EXPECT_GT(run.reverted, 0u);
}

// The thread's vertices that are not under the membrane (an even number of
// its triangles above them), and the first frame with one (-1: none).
struct MembraneRun {
  int first_through = -1;
  int most_through = 0;
  std::uint32_t hits = 0;
};

MembraneRun pull_into_membrane(Simulation& sim, const SceneDesc& scene, double speed, int frames) {
  MembraneRun out;
  const TriMesh& mesh = scene.tri_bodies[0].mesh;
  const std::uint32_t membrane_first = sim.info().tri_body_first_particle[0];
  const std::uint32_t thread_first = sim.info().line_body_first_particle[0];
  std::vector<float> x;
  for (int f = 0; f < frames; ++f) {
    EXPECT_TRUE(ThreadUnderMembrane::drive(sim, f, speed).ok());
    const Status s = sim.step();
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) break;
    out.hits += sim.last_frame().ccd_hits;
    EXPECT_TRUE(sim.read_positions(x).ok());
    std::vector<Point3> vertices;
    for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v) vertices.push_back(at(x, membrane_first + v));
    int through = 0;
    for (int i = 0; i <= ThreadUnderMembrane::segments; ++i)
      through += crossings_above(at(x, thread_first + static_cast<std::uint32_t>(i)), vertices, mesh.triangles) % 2 == 0;
    if (through > 0 && out.first_through < 0) out.first_through = f;
    out.most_through = std::max(out.most_through, through);
  }
  return out;
}

// The thread's ends rise at 1 m/s to 2 cm above the membrane's plane and
// are held there for half a second: every vertex of the thread stays under
// the membrane, every frame.
TEST_P(ContinuousCollisionTest, ThreadPulledIntoAMembraneAtAToolsSpeedNeverPassesThrough) {
  const SceneDesc scene = ThreadUnderMembrane::scene(true);
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const MembraneRun run = pull_into_membrane(*sim, scene, 1.0, 30);
  std::printf("[%s] thread vertices through the membrane: first at frame %d, at most %d; %u touches\n",
              GetParam().c_str(), run.first_through, run.most_through, run.hits);
  EXPECT_EQ(run.first_through, -1);
  EXPECT_GT(run.hits, 0u) << "the pull must make the thread touch the membrane, or the test shows nothing";
}

// Without continuous collision the thread passes through the membrane.
TEST(ContinuousCollision, WithoutItTheThreadPassesThroughTheMembrane) {
  const SceneDesc scene = ThreadUnderMembrane::scene(false);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const MembraneRun run = pull_into_membrane(*sim, scene, 1.0, 30);
  EXPECT_GE(run.first_through, 0);
}

struct ProbeRun {
  int first_through = -1;  // the first frame whose tip is not under the membrane (-1: none)
  std::uint32_t hits = 0, repairs = 0, carried = 0, forced = 0;
};

ProbeRun push_probe(Simulation& sim, const SceneDesc& scene, int frames) {
  ProbeRun out;
  const TriMesh& mesh = scene.tri_bodies[0].mesh;
  const std::uint32_t first = sim.info().tri_body_first_particle[0];
  std::vector<float> x;
  for (int f = 0; f < frames; ++f) {
    const double tip = ProbeUnderMembrane::tip(f, 1.0);
    EXPECT_TRUE(ProbeUnderMembrane::drive(sim, f, 1.0).ok());
    const Status s = sim.step();
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) break;
    const FrameStats& st = sim.last_frame();
    out.hits += st.ccd_hits, out.repairs += st.ccd_repairs, out.carried += st.ccd_carried, out.forced += st.ccd_forced;
    EXPECT_TRUE(sim.read_positions(x).ok());
    std::vector<Point3> vertices;
    for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v) vertices.push_back(at(x, first + v));
    const Point3 tip_point{ProbeUnderMembrane::x, tip, ProbeUnderMembrane::z};
    if (out.first_through < 0 && crossings_above(tip_point, vertices, mesh.triangles) % 2 == 0) out.first_through = f;
  }
  return out;
}

// The probe's tip rises at 1 m/s and stays 15 mm above the membrane's rest
// plane for half a second: the membrane, tented over it, stays above the
// tip every frame (its axis never passes through).
TEST_P(ContinuousCollisionTest, AThinProbePushedIntoAMembraneAtAToolsSpeedNeverPassesThrough) {
  const SceneDesc scene = ProbeUnderMembrane::scene(true);
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const ProbeRun run = push_probe(*sim, scene, 30);
  std::printf("[%s] probe through the membrane at frame %d; %u touches, %u repairs, %u particles carried, %u forced\n",
              GetParam().c_str(), run.first_through, run.hits, run.repairs, run.carried, run.forced);
  EXPECT_EQ(run.first_through, -1);
  EXPECT_GT(run.hits, 0u) << "the probe must touch the membrane, or the test shows nothing";
  EXPECT_EQ(run.forced, 0u);
}

// Without continuous collision the probe passes through the membrane.
TEST(ContinuousCollision, WithoutItTheProbePassesThroughTheMembrane) {
  const SceneDesc scene = ProbeUnderMembrane::scene(false);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  EXPECT_GE(push_probe(*sim, scene, 30).first_through, 0);
}

// The fail-safe alone (no repair rounds): the membrane's particles the
// probe's axis would cross move with the probe over their substep.
TEST(ContinuousCollision, TheFailSafeCarriesTheMembraneWithTheProbe) {
  SceneDesc scene = ProbeUnderMembrane::scene(true);
  scene.mesh_collision.continuous_repairs = 0;
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const ProbeRun run = push_probe(*sim, scene, 30);
  EXPECT_EQ(run.first_through, -1);
  EXPECT_EQ(run.repairs, 0u);
  EXPECT_GT(run.carried, 0u);
  EXPECT_EQ(run.forced, 0u);
}

// Two probes squeeze the membrane, one rising from under it, the other
// (1 mm beside it) coming down from above, with the fail-safe alone: the
// first carries the membrane up with it, so the second must cross it and
// nothing can stop that. Such a crossing is never silent: the frames in
// which the second probe's tip passes through count forced pairs.
TEST(ContinuousCollision, AMembraneSqueezedBetweenTwoProbesCountsTheForcedCrossing) {
  SceneDesc scene = ProbeUnderMembrane::scene(true);
  scene.mesh_collision.continuous_repairs = 0;
  ColliderDesc down = scene.colliders[0];
  const double x = ProbeUnderMembrane::x + 0.001, half = ProbeUnderMembrane::half;
  const auto bottom = [](int f) { return std::max(0.005 - 1.0 * (f + 1) * kFrame, -0.015); };  // of the second
  down.position = {x, bottom(-1) + half, ProbeUnderMembrane::z};
  scene.colliders.push_back(down);
  auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
  SINEW_ASSERT_OK(sim);
  const TriMesh& mesh = scene.tri_bodies[0].mesh;
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  std::vector<float> positions;
  int through = -1;
  std::uint32_t carried = 0, forced = 0;
  for (int f = 0; f < 30; ++f) {
    SINEW_ASSERT_OK(ProbeUnderMembrane::drive(*sim, f, 1.0));
    SINEW_ASSERT_OK(sim->set_collider_pose(1, {x, bottom(f) + half, ProbeUnderMembrane::z}, {1.0, 0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    carried += sim->last_frame().ccd_carried;
    forced += sim->last_frame().ccd_forced;
    SINEW_ASSERT_OK(sim->read_positions(positions));
    std::vector<Point3> vertices;
    for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v) vertices.push_back(at(positions, first + v));
    if (through < 0 && crossings_above({x, bottom(f), ProbeUnderMembrane::z}, vertices, mesh.triangles) % 2 == 1) {
      through = f;
      EXPECT_GT(forced, 0u) << "the second probe crossed the membrane at frame " << f << " and nothing said so";
    }
  }
  std::printf("second probe through at frame %d; %u particles carried, %u pairs forced\n", through, carried, forced);
  EXPECT_GE(through, 0) << "squeezed between the probes, the membrane cannot stay between them";
  EXPECT_GT(carried, 0u);
}

// The probe scene's collider replaced by a rigid tool of its shape (10 g,
// no gravity), its tip 5 mm under the membrane.
void with_probe_tool(SceneDesc& scene) {
  scene.colliders.clear();
  ToolDesc tool;
  tool.radius = 5e-4;
  tool.half_height = ProbeUnderMembrane::half;
  tool.mass = 0.01;
  tool.gravity = false;
  tool.position = {ProbeUnderMembrane::x, -0.005 - ProbeUnderMembrane::half, ProbeUnderMembrane::z};
  scene.tools.push_back(tool);
}

// A rigid tool of the probe's shape (10 g, no gravity) pushed up by 1 N
// from under the membrane: it passes 1 m/s as its tip meets the membrane
// and keeps pushing for a sixth of a second. Its tip stays under the
// membrane every frame,
// and the membrane pushes it back: the continuous contacts' reaction
// reaches the tool.
TEST_P(ContinuousCollisionTest, AToolPushedIntoAMembraneNeverPassesThroughAndFeelsIt) {
  SceneDesc scene = ProbeUnderMembrane::scene(true);
  with_probe_tool(scene);
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const TriMesh& mesh = scene.tri_bodies[0].mesh;
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  std::vector<float> x;
  int first_through = -1;
  double fastest = 0.0, strongest_push = 0.0;
  std::uint32_t hits = 0, forced = 0;
  for (int f = 0; f < 10; ++f) {
    SINEW_ASSERT_OK(sim->apply_tool_force(0, {0.0, 1.0, 0.0}, {0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    hits += sim->last_frame().ccd_hits;
    forced += sim->last_frame().ccd_forced;
    auto state = sim->tool_state(0);
    SINEW_ASSERT_OK(state);
    fastest = std::max(fastest, state->velocity[1]);
    strongest_push = std::min(strongest_push, state->contact_force[1]);
    const math::Vec3 tip = math::add(math::Vec3{state->position[0], state->position[1], state->position[2]},
                                     math::rotate(state->rotation, math::Vec3{0.0, ProbeUnderMembrane::half, 0.0}));
    SINEW_ASSERT_OK(sim->read_positions(x));
    std::vector<Point3> vertices;
    for (std::uint32_t v = 0; v < mesh.vertices.size(); ++v) vertices.push_back(at(x, first + v));
    if (first_through < 0 && crossings_above({tip[0], tip[1], tip[2]}, vertices, mesh.triangles) % 2 == 0)
      first_through = f;
  }
  std::printf("[%s] tool through the membrane at frame %d; fastest %.2f m/s, pushed back by up to %.3f N; %u touches\n",
              GetParam().c_str(), first_through, fastest, -strongest_push, hits);
  EXPECT_EQ(first_through, -1);
  EXPECT_GT(fastest, 0.8);
  EXPECT_GT(hits, 0u);
  EXPECT_EQ(forced, 0u);
  EXPECT_LT(strongest_push, -0.1) << "the membrane must push the tool back";
}

// The reaction is the whole frame's: a free membrane (no pins, no damping,
// no gravity) gains exactly the momentum the tool loses to it. The tool's
// contact force over each frame, times the frame, must match the change of
// the membrane's momentum, which only the contacts change (its edges,
// areas and bending conserve it). Contacts the continuous collision
// appends in later rounds move the earlier ones to new slots; their
// earlier substeps' multipliers must move with them, or the tool feels
// only part of the push.
TEST_P(ContinuousCollisionTest, AToolFeelsTheMomentumItGivesAFreeMembrane) {
  SceneDesc scene = ProbeUnderMembrane::scene(true);
  with_probe_tool(scene);
  scene.tri_bodies[0].pinned.clear();
  scene.tri_bodies[0].velocity_damping = 0.0;
  // Rounds enough that the fail-safe never runs (it carries tissue without
  // a reaction): with the default 4 it carries a few particles here.
  scene.mesh_collision.continuous_repairs = 12;
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  const std::size_t count = scene.tri_bodies[0].mesh.vertices.size();
  std::vector<float> x, v;
  const auto momentum = [&] {  // the membrane's, along y [kg m/s]
    EXPECT_TRUE(sim->read_positions(x).ok());
    EXPECT_TRUE(sim->read_velocities(v).ok());
    double p = 0.0;
    for (std::size_t k = first; k < first + count; ++k) p += double(v[4 * k + 1]) / x[4 * k + 3];
    return p;
  };
  double given = 0.0, felt = 0.0;
  std::uint32_t hits = 0, carried = 0, forced = 0;
  for (int f = 0; f < 10; ++f) {
    const double before = momentum();
    SINEW_ASSERT_OK(sim->apply_tool_force(0, {0.0, 1.0, 0.0}, {0.0, 0.0, 0.0}));
    SINEW_ASSERT_OK(sim->step());
    hits += sim->last_frame().ccd_hits;
    carried += sim->last_frame().ccd_carried;
    forced += sim->last_frame().ccd_forced;
    auto state = sim->tool_state(0);
    SINEW_ASSERT_OK(state);
    given += momentum() - before;
    felt -= state->contact_force[1] * kFrame;
  }
  std::printf("[%s] membrane gained %.4g kg m/s, the tool felt %.4g (%u touches)\n", GetParam().c_str(), given, felt,
              hits);
  ASSERT_GT(hits, 0u) << "the tool must touch the membrane, or the test shows nothing";
  ASSERT_EQ(carried + forced, 0u) << "the fail-safe moves tissue without a reaction";
  EXPECT_GT(given, 1e-3);
  EXPECT_NEAR(felt, given, 0.02 * given);
}

// ---- Nothing to find: no change.

// A thread falling freely, far from the membrane beside it: the search
// finds no touch, no repair runs and the frame is bitwise the one the
// single frame program computes (the stepper's per-substep programs are
// cut from it, and the search only reads).
TEST(ContinuousCollision, WithNoTouchesTheFrameIsBitwiseTheSame) {
  std::vector<float> with, without;
  for (const bool continuous : {true, false}) {
    SceneDesc scene = ThreadUnderMembrane::scene(continuous);
    scene.gravity = {0.0, -9.81, 0.0};
    scene.attachments.clear();
    for (Vec3d& v : scene.line_bodies[0].vertices) v[1] -= 0.05;
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    SINEW_ASSERT_OK(sim);
    for (int f = 0; f < 10; ++f) {
      SINEW_ASSERT_OK(sim->step());
      EXPECT_EQ(sim->last_frame().ccd_hits, 0u);
    }
    SINEW_ASSERT_OK(sim->read_positions(continuous ? with : without));
  }
  ASSERT_EQ(with.size(), without.size());
  for (std::size_t k = 0; k < with.size(); ++k) ASSERT_EQ(with[k], without[k]) << "float " << k;
}

// ---- The search on its own.

// xyzw positions of `points`.
std::vector<float> positions(std::initializer_list<Point3> points) {
  std::vector<float> x;
  for (const Point3& p : points) x.insert(x.end(), {float(p[0]), float(p[1]), float(p[2]), 1.0f});
  return x;
}

// Segment 0-1 along x at y = 0; segment 2-3 along z, 1 mm above it,
// moving down through it (or stopping short). The touch's contact has the
// first segment first and its normal from the second towards the first:
// the second came from above, so -y.
TEST(ContinuousSearch, SegmentsCrossingWithinTheStepTouchWithTheNormalTheyCameFrom) {
  ContinuousSearch search({0, 1, 2, 3}, {});
  const auto start = positions({{-1e-2, 0, 0}, {1e-2, 0, 0}, {0, 1e-3, -1e-2}, {0, 1e-3, 1e-2}});
  std::vector<collision::Contact> hits;
  for (const double end_y : {-1e-3, 5e-4}) {
    const auto end = positions({{-1e-2, 0, 0}, {1e-2, 0, 0}, {0, end_y, -1e-2}, {0, end_y, 1e-2}});
    SINEW_ASSERT_OK(search.find(start, end, hits));
    if (end_y > 0.0) {
      EXPECT_TRUE(hits.empty()) << "stopping 0.5 mm short is no touch";
      continue;
    }
    ASSERT_EQ(hits.size(), 1u);
    const collision::Contact& c = hits[0];
    EXPECT_EQ(c.kind, collision::Contact::Kind::edge_edge);
    EXPECT_EQ(c.v, (std::array<std::uint32_t, 4>{0, 1, 2, 3}));
    EXPECT_NEAR(c.w[1], 0.5, 1e-5);  // the middle of each
    EXPECT_NEAR(c.w[3], 0.5, 1e-5);
    EXPECT_NEAR(c.normal[1], -1.0f, 1e-6f);
  }
}

// Touching already at the step's start (the second segment lying on the
// first, then moving down through it, or a thread end on a face moving
// through it): the start tells no side, the motion does. The normal still
// points the way the second came from (-y), not along the segments.
TEST(ContinuousSearch, PrimitivesTouchingAtTheStartTakeTheSideFromTheirMotion) {
  ContinuousSearch segments({0, 1, 2, 3}, {});
  std::vector<collision::Contact> hits;
  for (const double dx : {0.0, 3e-3}) {  // crossing in the middle, or off it (the points apart along x)
    const auto start = positions({{-1e-2, 0, 0}, {1e-2, 0, 0}, {dx, 0, -1e-2}, {dx, 0, 1e-2}});
    const auto end = positions({{-1e-2, 0, 0}, {1e-2, 0, 0}, {dx, -1e-3, -1e-2}, {dx, -1e-3, 1e-2}});
    SINEW_ASSERT_OK(segments.find(start, end, hits));
    ASSERT_EQ(hits.size(), 1u) << "dx " << dx;
    EXPECT_NEAR(hits[0].normal[1], -1.0f, 1e-6f) << "dx " << dx;
  }
  // A thread end (particle 0) on the face 2-3-4 at the start, then 1 mm up through it.
  ContinuousSearch face({0, 1}, {2, 3, 4});
  const auto start = positions({{2e-3, 0, 2e-3}, {2e-3, -1e-2, 2e-3}, {0, 0, 0}, {1e-2, 0, 0}, {0, 0, 1e-2}});
  const auto end = positions({{2e-3, 1e-3, 2e-3}, {2e-3, -1e-2, 2e-3}, {0, 0, 0}, {1e-2, 0, 0}, {0, 0, 1e-2}});
  SINEW_ASSERT_OK(face.find(start, end, hits));
  ASSERT_FALSE(hits.empty());
  for (const collision::Contact& c : hits) EXPECT_NEAR(c.normal[1], -1.0f, 1e-6f) << "kind " << int(c.kind);
}

// Neighbours (segments sharing a vertex) are never tested, however they
// move, and pairs whose particles all stay put are skipped: a thread folded
// flat onto itself at rest is no touch.
TEST(ContinuousSearch, NeighboursAndPairsAtRestAreNotTested) {
  ContinuousSearch search({0, 1, 1, 2, 3, 4}, {});
  // 0-1-2 folded back onto itself through 1; 3-4 lying exactly on 0-1.
  const auto still = positions({{0, 0, 0}, {1e-2, 0, 0}, {0, 0, 0}, {2e-3, 0, 0}, {8e-3, 0, 0}});
  std::vector<collision::Contact> hits;
  SINEW_ASSERT_OK(search.find(still, still, hits));
  EXPECT_TRUE(hits.empty());
  EXPECT_EQ(search.queries(), 0u);
}

// A thread's end moving down through a triangle: a vertex-triangle touch
// whose normal points back up, where the vertex came from.
TEST(ContinuousSearch, AThreadEndThroughATriangleTouchesIt) {
  ContinuousSearch search({3, 4}, {0, 1, 2});
  const auto start = positions({{0, 0, 0}, {1e-2, 0, 0}, {0, 0, 1e-2}, {2e-3, 1e-3, 2e-3}, {2e-3, 1e-2, 2e-3}});
  const auto end = positions({{0, 0, 0}, {1e-2, 0, 0}, {0, 0, 1e-2}, {2e-3, -1e-3, 2e-3}, {2e-3, 8e-3, 2e-3}});
  std::vector<collision::Contact> hits;
  SINEW_ASSERT_OK(search.find(start, end, hits));
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].kind, collision::Contact::Kind::vertex_triangle);
  EXPECT_EQ(hits[0].v[0], 3u);
  EXPECT_NEAR(hits[0].normal[1], 1.0f, 1e-6f);
}

TEST(ContinuousSearch, ANonFinitePositionIsNamed) {
  ContinuousSearch search({0, 1, 2, 3}, {});
  auto start = positions({{-1e-2, 0, 0}, {1e-2, 0, 0}, {0, 1e-3, -1e-2}, {0, 1e-3, 1e-2}});
  auto end = start;
  end[4 * 2 + 1] = std::nanf("");
  std::vector<collision::Contact> hits;
  const Status s = search.find(start, end, hits);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message().find("particle 2"), std::string::npos) << s.error().message();
}

// ---- Settings.

TEST(ContinuousCollision, BadSettingsAreNamed) {
  const auto error_of = [](const SceneDesc& scene) {
    auto sim = Simulation::create(scene, {.backend = "cpu", .quiet = true});
    return sim ? std::string() : sim.error().message();
  };
  SceneDesc scene = LinkedRings::scene(true);
  scene.mesh_collision.continuous_repairs = -1;
  EXPECT_NE(error_of(scene).find("continuous_repairs"), std::string::npos) << error_of(scene);
  scene = LinkedRings::scene(true);
  scene.mesh_collision.schedule = ContactSchedule::jacobi;
  EXPECT_NE(error_of(scene).find("schedule"), std::string::npos) << error_of(scene);
  scene = ThreadUnderMembrane::scene(true);
  scene.line_bodies.clear();
  scene.attachments.clear();
  scene.targets.clear();
  EXPECT_NE(error_of(scene).find("line bodies"), std::string::npos) << error_of(scene);
}

INSTANTIATE_TEST_SUITE_P(Backends, ContinuousCollisionTest, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
