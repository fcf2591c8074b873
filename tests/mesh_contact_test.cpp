// mesh_contact_test.cpp — contacts between meshes in the solver (issue 12,
// part 3), on every backend: tissue against tissue and a membrane against
// itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

// A membrane strip lying on the floor has one end lifted by its edge's
// vertices (attached to targets) over the rest and laid down on it: the
// fold's upper layer settles onto the lower one by gravity and must never
// pass through it (no two triangles sharing no vertex ever intersect), and
// ends resting on it.
TEST_P(MeshContact, MembraneFoldedOntoItselfNeverPassesThroughItself) {
  constexpr int nx = 24, nz = 6;
  constexpr double cell = 0.005;
  SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  TriBodyDesc strip;
  strip.mesh = membrane(nx, nz, cell, 0.002);
  strip.thickness = 1e-3;
  strip.distance_compliance = 1e-6;
  strip.area_compliance = 1e-6;
  // No bending constraints: like cloth, the fold lies flat under its weight.
  strip.velocity_damping = 3.0;
  scene.tri_bodies.push_back(strip);
  ColliderDesc floor;
  scene.colliders.push_back(floor);
  // The far edge (x = nx * cell = 12 cm) held by targets that follow a half
  // circle about x = 5.75 cm over 1.5 s, ending just past the strip's other
  // end (x = -0.5 cm), 3 mm up: the upper layer is pulled taut over the lower.
  const double centre = 0.0575, radius = nx * cell - centre;
  for (int k = 0; k <= nz; ++k) {
    scene.targets.push_back({nx * cell, 0.002, k * cell});
    AttachmentDesc a;
    a.vertex = {BodyKind::tri, 0, static_cast<std::uint32_t>(nx * (nz + 1) + k)};
    a.target = static_cast<std::uint32_t>(k);
    a.compliance = 1e-6;
    scene.attachments.push_back(a);
  }
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 1.5e-3;
  auto sim = create_or_skip(scene, GetParam());
  SINEW_ASSERT_OK(sim);
  const std::uint32_t first = sim->info().tri_body_first_particle[0];
  std::vector<float> x;
  int worst = 0;
  std::uint32_t most_contacts = 0;
  constexpr int fold_frames = 90, total = 180;
  for (int f = 0; f < total; ++f) {
    const double angle = 3.14159265358979 * std::min(1.0, double(f + 1) / fold_frames);
    for (int k = 0; k <= nz; ++k)
      SINEW_ASSERT_OK(sim->set_target(k, {centre + radius * std::cos(angle), 0.002 + 0.001 * std::min(1.0, double(f + 1) / fold_frames) + radius * std::sin(angle), k * cell}));
    SINEW_ASSERT_OK(sim->step());
    most_contacts = std::max(most_contacts, sim->last_frame().mesh_contacts);
    if (f % 6 == 5 || f + 1 == total) {
      SINEW_ASSERT_OK(sim->read_positions(x));
      worst = std::max(worst, self_intersections(x, scene.tri_bodies[0].mesh, first));
    }
  }
  // The upper layer (x from 6 to 9 cm when unfolded, folded back over 1 to
  // 4.5 cm) lies on the lower one: above it (on the floor) by about the
  // thickness. (Without mesh collision it lies in it: 158 intersecting
  // triangle pairs.)
  double lowest = 1e9;
  for (int i = 12; i <= 18; ++i)
    for (int k = 0; k <= nz; ++k) lowest = std::min(lowest, at(x, first + static_cast<std::uint32_t>(i * (nz + 1) + k))[1]);
  std::printf("[%s] intersecting triangle pairs %d, most contacts %u, upper layer's lowest vertex %.2f mm\n",
              GetParam().c_str(), worst, most_contacts, lowest * 1e3);
  EXPECT_EQ(worst, 0);
  EXPECT_GT(most_contacts, 0u);
  EXPECT_GT(lowest, 0.5 * scene.mesh_collision.thickness);
  EXPECT_LT(lowest, 3.0 * scene.mesh_collision.thickness);
}

INSTANTIATE_TEST_SUITE_P(Backends, MeshContact, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
