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

#include "mesh_contact_support.h"
#include "runtime/continuous_collision.h"
#include "test_support.h"
#include "thread_topology.h"

namespace sinew::test {
namespace {

class ContinuousCollisionTest : public BackendTest {};

constexpr double kFrame = 1.0 / 60.0;

// The tests' common settings: no gravity, 60 frames per second of 8
// substeps with 10 sweeps, mesh collision at 0.5 mm with CCD on or off.
SceneDesc thread_scene(bool continuous) {
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.time_step = kFrame;
  scene.solver.substeps = 8;
  scene.solver.iterations = 10;
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 5e-4;
  scene.mesh_collision.continuous = continuous;
  return scene;
}

// ---- Two linked rings of one thread, pulled apart.

// One line body of two closed rings of `n` segments and radius r = 1 cm,
// linked like chain links: ring A in the z = 0 plane around the origin,
// ring B in the y = 0 plane around (r, 0, 0), each passing through the
// other's centre. A's vertex 0 (at (-r, 0, 0)) is attached to target 0, B's
// vertex 0 (at (2r, 0, 0)) to target 1; moving the targets apart along x
// pulls the rings tight against each other, hooked at A's (r, 0, 0) and B's
// origin. The segments are inextensible (compliance 0).
struct LinkedRings {
  static constexpr int n = 32;
  static constexpr double r = 0.01;
  static SceneDesc scene(bool continuous) {
    SceneDesc scene = thread_scene(continuous);
    LineBodyDesc t;
    for (int ring = 0; ring < 2; ++ring)
      for (int i = 0; i < n; ++i) {
        const double a = 2.0 * M_PI * i / n;
        if (ring == 0) t.vertices.push_back({-r * std::cos(a), -r * std::sin(a), 0.0});
        else t.vertices.push_back({r + r * std::cos(a), 0.0, r * std::sin(a)});
        t.masses.push_back(1e-4);
        t.segments.push_back({static_cast<std::uint32_t>(ring * n + i), static_cast<std::uint32_t>(ring * n + (i + 1) % n)});
      }
    t.bending_compliance = 1.0;
    t.velocity_damping = 1.0;
    scene.line_bodies.push_back(t);
    scene.targets = {{-r, 0.0, 0.0}, {2.0 * r, 0.0, 0.0}};
    scene.attachments = {{{BodyKind::line, 0, 0}, 0, 0.0}, {{BodyKind::line, 0, static_cast<std::uint32_t>(n)}, 1, 0.0}};
    return scene;
  }
  // Each target's distance from its start after frame f: `speed` [m/s]
  // until 3 cm (past where the rings are tight: they hook after 1 cm and
  // can stretch about 2.3 cm more), then held.
  static double pulled(int f, double speed) { return std::min(speed * (f + 1) * kFrame, 0.03); }
  static LinkingCount linking(const Simulation& sim) {
    std::vector<float> x;
    EXPECT_TRUE(sim.read_positions(x).ok());
    std::vector<Point3> a, b;
    for (int i = 0; i < n; ++i) a.push_back(at(x, static_cast<std::uint32_t>(i)));
    for (int i = 0; i < n; ++i) b.push_back(at(x, static_cast<std::uint32_t>(n + i)));
    return linking_count(a, b);
  }
};

struct RunSummary {
  int first_change = -1;  // the first frame whose linking number differs from the start's (-1: none)
  std::uint32_t hits = 0, repairs = 0, reverted = 0;
};

RunSummary pull_rings(Simulation& sim, double speed, int frames) {
  RunSummary out;
  const LinkingCount start = LinkedRings::linking(sim);
  EXPECT_EQ(start.over, start.under);
  EXPECT_EQ(std::abs(start.over), 1) << "the rings start linked";
  for (int f = 0; f < frames; ++f) {
    const double d = LinkedRings::pulled(f, speed);
    EXPECT_TRUE(sim.set_target(0, {-LinkedRings::r - d, 0.0, 0.0}).ok());
    EXPECT_TRUE(sim.set_target(1, {2.0 * LinkedRings::r + d, 0.0, 0.0}).ok());
    const Status s = sim.step();
    EXPECT_TRUE(s.ok()) << s.error().message();
    if (!s.ok()) break;
    const FrameStats& st = sim.last_frame();
    out.hits += st.ccd_hits;
    out.repairs += st.ccd_repairs;
    out.reverted += st.ccd_reverted;
    const LinkingCount now = LinkedRings::linking(sim);
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

// ---- A thread pulled up into a membrane.

// A 6 x 6 cm membrane (12 x 12 cells, 1 mm thick) in the y = 0 plane,
// pinned all round; under it, 3 mm down, a 4 cm thread of 16 segments
// (offset from the membrane's grid lines, so no vertex sits under an edge)
// whose ends are attached to targets that rise at `speed` to 2 cm above
// the membrane's plane and stay there: the thread must tent the membrane.
struct ThreadUnderMembrane {
  static constexpr int segments = 16;
  static SceneDesc scene(bool continuous) {
    SceneDesc scene = thread_scene(continuous);
    TriBodyDesc m;
    m.mesh = membrane(12, 12, 0.005, 0.0);
    for (int i = 0; i <= 12; ++i)
      for (int k = 0; k <= 12; ++k)
        if (i == 0 || i == 12 || k == 0 || k == 12) m.pinned.push_back(static_cast<std::uint32_t>(i * 13 + k));
    m.velocity_damping = 2.0;
    scene.tri_bodies.push_back(m);
    LineBodyDesc t;
    for (int i = 0; i <= segments; ++i) {
      t.vertices.push_back({end_x(0) + (end_x(1) - end_x(0)) * i / segments, -0.003, z});
      t.masses.push_back(1e-4);
      if (i < segments) t.segments.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1)});
    }
    t.bending_compliance = 1.0;
    t.velocity_damping = 2.0;
    scene.line_bodies.push_back(t);
    scene.targets = {{end_x(0), -0.003, z}, {end_x(1), -0.003, z}};
    scene.attachments = {{{BodyKind::line, 0, 0}, 0, 0.0},
                         {{BodyKind::line, 0, static_cast<std::uint32_t>(segments)}, 1, 0.0}};
    return scene;
  }
  static constexpr double z = 0.03013;
  static double end_x(int side) { return side == 0 ? 0.01071 : 0.04971; }
  static double height(int f, double speed) { return std::min(-0.003 + speed * (f + 1) * kFrame, 0.02); }
};

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
    const double y = ThreadUnderMembrane::height(f, speed);
    for (int side = 0; side < 2; ++side)
      EXPECT_TRUE(sim.set_target(side, {ThreadUnderMembrane::end_x(side), y, ThreadUnderMembrane::z}).ok());
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
