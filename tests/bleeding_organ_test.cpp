// bleeding_organ_test.cpp — the bleeding reference scene (S4,
// examples/common/bleeding_organ_scene.h) shortened: blood from a cut
// vessel on kidney_57k, coupled both ways, with the suction tip coming
// down early. Checks the physics of the scene every frame on the CPU:
//   - the books: the fluid's own (emitted = alive + removed) and the split
//     of the removed between the suction tip and the drain, each removal
//     named by where the particle was seen last (none unexplained), so
//     emitted = alive + suctioned + drained exactly;
//   - every particle finite, none inside the kidney's tets (no tunnelling);
//   - the tissue feels the blood: the force the fluid puts on the kidney is
//     non-zero and, summed over the frames the blood lies on it, downward.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "bleeding_organ_scene.h"
#include "sinew/simulation.h"

namespace sinew {
namespace {

using examples::BleedingOrganScene;

TEST(BleedingOrgan, BooksBalanceNothingTunnelsAndTheKidneyFeelsTheBlood) {
  examples::BleedingOrganOptions options;
  options.mesh_path = std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node";
  options.flow_ml = 4.0;          // a fast bleed: the pool forms within the test's frames
  options.suction_start = 0.05;   // the tip is at the wound from 0.3 s
  auto made = examples::make_bleeding_organ_scene(options);
  ASSERT_TRUE(made) << made.error().message();
  const BleedingOrganScene& s = *made;
  EXPECT_LT(s.coupled_triangles, s.surface_triangles) << "only the surface near the fluid is sampled";
  auto sim = Simulation::create(s.scene, {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim) << sim.error().message();
  SceneFluid fluid = sim->fluid();
  const std::uint32_t first = sim->info().tet_body_first_particle[0];

  examples::RemovalBooks books;
  std::vector<FluidParticle> q;
  std::vector<float> x;
  double push_down = 0.0;  // the vertical impulse on the kidney over the frames with blood on it [N s]
  int frames_with_push = 0;
  const int frames = 24;  // 0.4 s
  for (int frame = 1; frame <= frames; ++frame) {
    const double t = frame * BleedingOrganScene::kFrame;
    ASSERT_TRUE(s.script(fluid, t));
    const Status stepped = sim->step();
    ASSERT_TRUE(stepped) << "frame " << frame << ": " << stepped.error().message();
    ASSERT_TRUE(fluid.read(q));
    const auto stats = fluid.stats();
    ASSERT_TRUE(stats);
    ASSERT_EQ(q.size(), stats->particles);
    EXPECT_EQ(stats->emitted, stats->particles + stats->removed) << "the fluid's books, frame " << frame;
    books.update(q, s.suction_at(t), s, BleedingOrganScene::kFrame * std::max(2.0 * stats->max_speed, 0.3) + 2e-3);
    EXPECT_EQ(books.unexplained, 0u) << "a particle vanished away from both sinks, frame " << frame;
    EXPECT_LE(books.vanished(), stats->removed);
    EXPECT_EQ(stats->emitted, stats->particles + books.suctioned(stats->removed) + books.drained);

    ASSERT_TRUE(sim->read_positions(x));
    const examples::TetContainment kidney(s.mesh, x, first, 4e-3);
    for (const FluidParticle& p : q) {
      ASSERT_TRUE(std::isfinite(p.position[0]) && std::isfinite(p.position[1]) && std::isfinite(p.position[2]) &&
                  std::isfinite(p.velocity[0]) && std::isfinite(p.velocity[1]) && std::isfinite(p.velocity[2]))
          << "particle " << p.id << ", frame " << frame;
      EXPECT_FALSE(kidney.inside({p.position[0], p.position[1], p.position[2]}))
          << "particle " << p.id << " inside the kidney at frame " << frame;
    }
    const auto impulses = fluid.last_impulses();
    ASSERT_TRUE(impulses);
    if (stats->particles > 0 && impulses->tissue[1] != 0.0) {
      push_down -= impulses->tissue[1];
      ++frames_with_push;
    }
  }
  const auto stats = fluid.stats();
  ASSERT_TRUE(stats);
  // The scene did what it is for: blood on the kidney, some run off, some suctioned.
  EXPECT_GT(stats->particles, 100u);
  EXPECT_GT(books.suctioned(stats->removed), 0u) << "the suction tip took nothing";
  EXPECT_GT(frames_with_push, frames / 2) << "the kidney felt the blood in too few frames";
  EXPECT_GT(push_down, 0.0) << "the blood's push on the kidney is not downward on average";
}

}  // namespace
}  // namespace sinew
