// mesh_contact_test.cpp — contacts between meshes in the solver (issue 12,
// part 3), on every backend: tissue against tissue and a membrane against
// itself.
#include <gtest/gtest.h>

#include <cstdio>

#include "mesh_contact_support.h"
#include "test_support.h"

namespace sinew::test {
namespace {

class MeshContact : public BackendTest {};

TetBodyDesc soft_block(int cells, double cell, const std::array<double, 3>& origin) {
  TetBodyDesc body;
  body.mesh = box_mesh(cells, cells, cells, cell);
  for (auto& v : body.mesh.vertices)
    for (int k = 0; k < 3; ++k) v[k] += origin[k];
  EXPECT_TRUE(body.set_elastic(2e6, 0.3).ok());
  body.density = 1000.0;
  body.velocity_damping = 2.0;
  return body;
}

// A 3 cm block dropped from 1 cm onto a 4 cm block resting on the floor,
// offset so that its edges and corners meet the lower block's faces and its
// vertices fall between the lower one's (finer and coarser meshes).
TEST_P(MeshContact, DroppedBlocksRestOnEachOtherWithinTheThickness) {
  SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  scene.tet_bodies.push_back(soft_block(4, 0.01, {0.0, 0.0, 0.0}));
  scene.tet_bodies.push_back(soft_block(4, 0.0075, {0.005, 0.05, 0.0065}));
  ColliderDesc floor;
  scene.colliders.push_back(floor);
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 1e-3;
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  for (int f = 0; f < 120; ++f) SINEW_ASSERT_OK(sim->step());
  std::vector<float> x;
  SINEW_ASSERT_OK(sim->read_positions(x));
  const PlacedBody lower{&scene.tet_bodies[0].mesh, sim->info().tet_body_first_particle[0]};
  const PlacedBody upper{&scene.tet_bodies[1].mesh, sim->info().tet_body_first_particle[1]};
  const double depth = std::max(penetration(x, upper, lower), penetration(x, lower, upper));
  double lowest_upper = 1e9;
  for (std::uint32_t v = 0; v < scene.tet_bodies[1].mesh.vertices.size(); ++v)
    lowest_upper = std::min(lowest_upper, at(x, upper.first + v)[1]);
  const FrameStats& s = sim->last_frame();
  std::printf("[%s] depth %.3g mm, upper block's lowest %.4f m, KE %.3g J, %u contacts in %u colours, margin %.3g mm, %.2f ms\n",
              GetParam().c_str(), depth * 1e3, lowest_upper, s.kinetic_energy, s.mesh_contacts, s.mesh_contact_colors,
              s.collision_margin * 1e3, s.collision_ms);
  EXPECT_LT(depth, scene.mesh_collision.thickness);
  EXPECT_GT(lowest_upper, 0.0395);  // on the lower block (top at 4 cm), not beside or inside it
  EXPECT_LT(s.kinetic_energy, 1e-5);
  EXPECT_GT(s.mesh_contacts, 0u);
}

INSTANTIATE_TEST_SUITE_P(Backends, MeshContact, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
