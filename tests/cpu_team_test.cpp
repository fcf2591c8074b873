// cpu_team_test.cpp — the CPU backend's thread team in a simulation: a frame
// gives bitwise the same positions on any number of threads, with or
// without the adaptive choice between the team and one thread.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "test_support.h"

namespace sinew {
namespace {

// A block hanging from one face with a plane under it: every kind of step
// of a frame program (solves of every colour size, contacts, statistics
// reductions, indirect-free and cooperative dispatches).
TEST(CpuTeam, PositionsAreBitwiseTheSameOnAnyThreadCount) {
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 4, .iterations = 3};
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 9, .ny = 4, .nz = 6, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
  ASSERT_TRUE(body.set_material(TetMaterial::neo_hookean, 2e4, 0.4).ok());
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] < 1e-9) body.pinned.push_back(v);
  scene.tet_bodies.push_back(body);
  ColliderDesc floor;
  floor.position = {0.0, -0.01, 0.0};
  scene.colliders.push_back(floor);
  std::vector<std::vector<float>> result;
  for (int threads : {1, 2, 3}) {
    for (bool adaptive : {true, false}) {  // the team for every program, or where it measured faster
      if (threads == 1 && !adaptive) continue;
      auto sim = Simulation::create(
          scene, {.backend = "cpu", .threads = threads, .cpu_adaptive_team = adaptive, .quiet = true});
      ASSERT_TRUE(sim.ok()) << sim.error().message();
      for (int f = 0; f < 40; ++f) ASSERT_TRUE(sim->step().ok());
      ASSERT_TRUE(sim->read_positions(result.emplace_back()).ok());
    }
  }
  ASSERT_EQ(result.size(), 5u);
  for (std::size_t r = 1; r < result.size(); ++r)
    EXPECT_EQ(0, std::memcmp(result[0].data(), result[r].data(), result[0].size() * 4))
        << "1 thread vs run " << r << " (2 or 3 threads, adaptive or always the team)";
  // It sagged: the comparison is of a moving body, not of the rest state.
  EXPECT_LT(result[0][4 * (body.mesh.vertices.size() - 1) + 1], 0.035f);
}

// More threads than the team can hold is a named error, not std::terminate
// (it was: a thread per member, created without a cap).
TEST(CpuTeam, TooManyThreadsIsANamedError) {
  SceneDesc scene;
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = 1, .ny = 1, .nz = 1, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
  scene.tet_bodies.push_back(body);
  auto sim = Simulation::create(scene, {.backend = "cpu", .threads = 100000, .quiet = true});
  ASSERT_FALSE(sim.ok());
  EXPECT_EQ(sim.error().code(), ErrorCode::bad_parameter);
  EXPECT_NE(sim.error().message().find("DeviceOptions.threads must be <= 256"), std::string::npos)
      << sim.error().message();
}

}  // namespace
}  // namespace sinew
