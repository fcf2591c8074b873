// reorder_test.cpp — particles stored in bandwidth-reducing order on the device
// (src/compiler/particle_order.h) change no result and no numbering: the
// user sees the scene's vertex order, and the positions after a run with
// every kind of body, collider, tool and attachment are bitwise those of a
// run in the scene's order, on every backend.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>

#include "compiler/particle_order.h"
#include "test_support.h"

namespace sinew {
namespace {

// A tet grid whose vertices are renumbered at random, as a mesher's order
// is far from spatial: the case the reordering is for.
TetMesh shuffled_grid(int nx, int ny, int nz, double cell, Vec3d origin, std::uint32_t seed) {
  TetMesh grid = *make_tet_grid({.nx = nx, .ny = ny, .nz = nz, .origin = origin, .cell_size = {cell, cell, cell}});
  std::vector<std::uint32_t> to(grid.vertices.size());
  std::iota(to.begin(), to.end(), 0u);
  std::mt19937 rng(seed);
  std::shuffle(to.begin(), to.end(), rng);
  TetMesh out;
  out.vertices.resize(grid.vertices.size());
  for (std::size_t v = 0; v < to.size(); ++v) out.vertices[to[v]] = grid.vertices[v];
  for (const auto& t : grid.tets) out.tets.push_back({to[t[0]], to[t[1]], to[t[2]], to[t[3]]});
  return out;
}

// Every feature that refers to particles: a shuffled tet body pinned at its
// top, a closed membrane, a thread, a floor, a tool pressing on the block,
// and an attachment pulling one of the block's vertices towards a target.
SceneDesc everything_scene(bool reorder) {
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 2};
  scene.solver.reorder_particles = reorder;
  TetBodyDesc block;
  block.mesh = shuffled_grid(6, 3, 4, 0.01, {0.0, 0.0, 0.0}, 7);
  EXPECT_TRUE(block.set_elastic(5e4, 0.3).ok());
  for (std::uint32_t v = 0; v < block.mesh.vertices.size(); ++v)
    if (block.mesh.vertices[v][1] > 0.0299 && block.mesh.vertices[v][0] < 1e-9) block.pinned.push_back(v);
  scene.tet_bodies.push_back(block);

  TriBodyDesc membrane;
  membrane.mesh = extract_boundary_surface(shuffled_grid(2, 2, 2, 0.01, {0.08, 0.0, 0.0}, 11));
  membrane.bending_compliance = 1e-2;
  scene.tri_bodies.push_back(membrane);

  LineBodyDesc thread;
  for (int i = 0; i < 12; ++i) thread.vertices.push_back({0.0 + 0.005 * i, 0.06, 0.02});
  // Segments listed out of order, as a user's file may hold them.
  for (int i = 10; i >= 0; i -= 2) thread.segments.push_back({std::uint32_t(i), std::uint32_t(i + 1)});
  for (int i = 9; i >= 1; i -= 2) thread.segments.push_back({std::uint32_t(i), std::uint32_t(i + 1)});
  thread.masses.assign(thread.vertices.size(), 1e-4);
  thread.bending_compliance = 1e-3;
  thread.pinned = {0};
  scene.line_bodies.push_back(thread);

  ColliderDesc floor;
  floor.position = {0.0, -0.01, 0.0};
  scene.colliders.push_back(floor);
  ToolDesc tool;
  tool.radius = 0.004;
  tool.half_height = 0.01;
  tool.position = {0.03, 0.035, 0.02};
  tool.mass = 0.05;
  scene.tools.push_back(tool);
  // The block's vertex nearest (0.06, 0, 0.04) held by a grasper that lifts it.
  std::uint32_t corner = 0;
  for (std::uint32_t v = 0; v < block.mesh.vertices.size(); ++v) {
    const Vec3d& p = block.mesh.vertices[v];
    if (std::hypot(p[0] - 0.06, p[1], p[2] - 0.04) < 1e-9) corner = v;
  }
  scene.targets.push_back({0.06, 0.0, 0.04});
  scene.attachments.push_back({.vertex = {BodyKind::tet, 0, corner}, .target = 0, .compliance = 1e-6});
  return scene;
}

class Reorder : public test::BackendTest {};

TEST_P(Reorder, PositionsAndVelocitiesAreBitwiseThoseOfTheScenesOrder) {
  auto in_order = test::create_or_skip(everything_scene(false), GetParam());
  ASSERT_TRUE(in_order.ok()) << in_order.error().message();
  auto reordered = test::create_or_skip(everything_scene(true), GetParam());
  ASSERT_TRUE(reordered.ok()) << reordered.error().message();
  for (int f = 0; f < 30; ++f) {
    const double lift = 0.0005 * f;
    for (Simulation* sim : {&*in_order, &*reordered}) {
      ASSERT_TRUE(sim->set_target(0, {0.06, lift, 0.04}).ok());
      ASSERT_TRUE(sim->step().ok());
    }
  }
  std::vector<float> a, b;
  ASSERT_TRUE(in_order->read_positions(a).ok());
  ASSERT_TRUE(reordered->read_positions(b).ok());
  ASSERT_EQ(a.size(), b.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += std::memcmp(&a[i], &b[i], 4) != 0;
  EXPECT_EQ(differ, 0u) << "position words that differ";
  ASSERT_TRUE(in_order->read_velocities(a).ok());
  ASSERT_TRUE(reordered->read_velocities(b).ok());
  differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += std::memcmp(&a[i], &b[i], 4) != 0;
  EXPECT_EQ(differ, 0u) << "velocity words that differ";
  // The run did something: the tool fell onto the block, the grasped vertex rose.
  const auto tool_in_order = in_order->tool_state(0), tool_reordered = reordered->tool_state(0);
  ASSERT_TRUE(tool_in_order.ok() && tool_reordered.ok());
  EXPECT_EQ(tool_in_order->position, tool_reordered->position);
  EXPECT_LT(tool_in_order->position[1], 0.035);
  EXPECT_EQ(in_order->info().colors, reordered->info().colors);
}

TEST_P(Reorder, ReadPositionsIsInTheScenesVertexOrder) {
  const SceneDesc scene = everything_scene(true);
  auto sim = test::create_or_skip(scene, GetParam());
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  std::vector<float> x;
  ASSERT_TRUE(sim->read_positions(x).ok());
  const SceneInfo& info = sim->info();
  auto check = [&](const std::vector<Vec3d>& vertices, std::uint32_t first, const char* what) {
    for (std::size_t v = 0; v < vertices.size(); ++v)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(x[4 * (first + v) + k], static_cast<float>(vertices[v][k])) << what << " vertex " << v;
  };
  check(scene.tet_bodies[0].mesh.vertices, info.tet_body_first_particle[0], "tet body");
  check(scene.tri_bodies[0].mesh.vertices, info.tri_body_first_particle[0], "tri body");
  check(scene.line_bodies[0].vertices, info.line_body_first_particle[0], "line body");
  // Pinned vertices read back with inverse mass 0, at their own numbers.
  for (std::uint32_t v : scene.tet_bodies[0].pinned) EXPECT_EQ(x[4 * v + 3], 0.0f) << "pinned vertex " << v;
}

INSTANTIATE_TEST_SUITE_P(Backends, Reorder, ::testing::ValuesIn(test::backends()), test::backend_name);

// The order itself: a permutation that keeps every body's range and puts
// mesh neighbours close in memory.
TEST(ParticleOrder, IsAPermutationWithinEachBodyThatBringsNeighboursTogether) {
  const TetMesh a = shuffled_grid(12, 10, 8, 0.01, {0, 0, 0}, 3);
  const TetMesh b = shuffled_grid(5, 5, 5, 0.01, {1, 0, 0}, 4);
  const auto second = static_cast<std::uint32_t>(a.vertices.size());
  const auto total = static_cast<std::uint32_t>(second + b.vertices.size());
  std::vector<std::uint32_t> tets;
  for (const auto& t : a.tets) tets.insert(tets.end(), t.begin(), t.end());
  for (const auto& t : b.tets)
    for (std::uint32_t v : t) tets.push_back(second + v);
  // A lone particle (a body of one vertex) and a tet list as two lists.
  const std::vector<ConstraintList> lists = {{std::span(tets).first(4 * a.tets.size()), 4},
                                             {std::span(tets).subspan(4 * a.tets.size()), 4}};
  const ParticleOrder order = bandwidth_order(total + 1, lists, {second, 0, total});
  ASSERT_EQ(order.device_of.size(), total + 1);
  for (std::uint32_t p = 0; p <= total; ++p) {
    ASSERT_EQ(order.user_of[order.device_of[p]], p);
    EXPECT_EQ(p < second, order.device_of[p] < second) << "particle " << p << " left its body";
  }
  EXPECT_EQ(order.device_of[total], total);
  EXPECT_FALSE(order.identity());
  // Largest distance in memory between the two ends of an edge (the
  // bandwidth): the shuffled numbering spreads them over the whole body,
  // RCM keeps every one within about a layer of the grid (13 x 11 = 143
  // vertices per layer of the 12 x 10 x 8 grid; a BFS level is a little
  // wider).
  double before = 0, after = 0;
  for (const auto& t : a.tets)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        before = std::max(before, std::abs(double(t[i]) - double(t[j])));
        after = std::max(after, std::abs(double(order.device_of[t[i]]) - double(order.device_of[t[j]])));
      }
  EXPECT_GT(before, 1000.0);
  EXPECT_LT(after, 400.0) << "bandwidth " << before << " -> " << after;
}

TEST(ParticleOrder, ConstraintOrderIsByColourThenFirstParticle) {
  // Four distance constraints in two colours.
  const std::vector<std::uint32_t> particles = {9, 3, 1, 2, 7, 5, 0, 8};
  const std::vector<std::uint32_t> color_of = {1, 0, 1, 0};
  EXPECT_EQ(constraint_order(particles, 2, color_of, true), (std::vector<std::uint32_t>{3, 1, 0, 2}));
  EXPECT_EQ(constraint_order(particles, 2, color_of, false), (std::vector<std::uint32_t>{1, 3, 0, 2}));
}

}  // namespace
}  // namespace sinew
