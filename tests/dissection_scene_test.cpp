// The reference scene S2 (examples/common/dissection_scene.h), shortened: the
// lift (62 frames), then 0.4 s of the cautery and the blade (28 frames) (the lift, then the cautery and the blade).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dissection_scene.h"
#include "runtime/simulation_internals.h"

namespace {

using sinew::examples::DissectionScene;

TEST(DissectionScene, MembranePullsTheGallbladderUpThenIsCutWithTheSceneValid) {
  sinew::examples::DissectionSettings s{.gallbladder = std::string(SINEW_DATA_DIR) + "/meshes/tet/gallbladder_volumetric.vtk"};
  s.threads = 2;
  auto made = DissectionScene::create(s);
  ASSERT_TRUE(made.ok()) << made.error().message();
  DissectionScene& r = **made;
  ASSERT_GT(r.held(), 0u);
  // Valid from the start (the body attachments' repeated unused slots are
  // no conflict) and after every burn and cut.
  auto start_colors = sinew::SimulationInternals::check_colors(r.sim());
  ASSERT_TRUE(start_colors.ok());
  std::printf("colour conflicts at the start: %llu\n", static_cast<unsigned long long>(start_colors->conflicts));
  const int lift_end = static_cast<int>(std::lround(sinew::examples::kLiftEnd / r.frame_time())) + 2;
  const int frames = static_cast<int>(std::lround((sinew::examples::kDissectStart + 0.4) / r.frame_time()));
  for (int f = 1; f <= lift_end; ++f) ASSERT_TRUE(r.frame().ok()) << "frame " << f;
  auto lifted = r.check();
  ASSERT_TRUE(lifted.ok());
  std::printf("lift: gallbladder %.3f mm, liver %.3f mm, membrane (held) %.3f mm; pull on the jaws %.3f N up\n",
              1e3 * lifted->gallbladder_lift, 1e3 * lifted->liver_lift, 1e3 * lifted->membrane_lift,
              -lifted->grasp_force[1]);
  // The membrane carries the grasper's lift to the gallbladder (two-way
  // attachments): the goal is 2 mm.
  EXPECT_GT(lifted->membrane_lift, 0.005);
  EXPECT_GE(lifted->gallbladder_lift, 0.002);
  EXPECT_GT(lifted->liver_lift, 0.0);
  EXPECT_TRUE(lifted->finite);
  EXPECT_EQ(r.topology_events(), 0u);  // nothing cut yet

  for (int f = lift_end + 1; f <= frames; ++f) ASSERT_TRUE(r.frame().ok()) << "frame " << f;
  auto end = r.check();
  ASSERT_TRUE(end.ok());
  std::printf("dissection: %zu topology changes, %zu triangles removed, %zu left; deepest inside %.3f mm\n",
              r.topology_events(), r.triangles_removed(), end->membrane_triangles, 1e3 * end->deepest_inside);
  EXPECT_GE(r.topology_events(), 5u);
  EXPECT_GT(r.triangles_removed(), 0u);
  EXPECT_TRUE(end->finite);
  auto colors = sinew::SimulationInternals::check_colors(r.sim());
  ASSERT_TRUE(colors.ok()) << colors.error().message();
  std::printf("colour conflicts at the end: %llu\n", static_cast<unsigned long long>(colors->conflicts));
  EXPECT_EQ(start_colors->conflicts, 0u);
  EXPECT_EQ(colors->conflicts, 0u);
  // Nothing passes through beyond the membrane's thickness (1 mm): mesh
  // collision keeps the membrane out of the gallbladder and the liver bed.
  EXPECT_LE(end->deepest_inside, 1e-3);
}

}  // namespace
