// feature_handles_test.cpp — the public API by feature (sinew/tools.h,
// graspers.h, needles.h, topology.h; ids in sinew/ids.h): ids are typed
// (a tool's cannot stand for a needle's), name their Simulation (an id
// used on another one is a named error, never another body), a null or
// out-of-range id is named, a removed element stays removed (a stale
// index is a named error), and each handle does what the index-based
// call it replaces does.
#include <gtest/gtest.h>

#include <string>
#include <type_traits>
#include <vector>

#include "sinew/simulation.h"
#include "test_support.h"

namespace sinew::test {
namespace {

static_assert(!std::is_convertible_v<ToolId, NeedleId>, "ids are typed");
static_assert(!std::is_convertible_v<TetBodyId, TriBodyId>, "ids are typed");
static_assert(!std::is_convertible_v<std::size_t, GrasperId>, "an index is not an id");

// Two tet bodies side by side (one pinned at its top), a capsule tool, a
// collider, a grasper and a target, with topology changes.
SceneDesc scene() {
  SceneDesc s;
  for (int b = 0; b < 2; ++b) {
    TetBodyDesc body;
    body.mesh = *make_tet_grid({.nx = 2, .ny = 2, .nz = 2, .origin = {0.05 * b, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
    EXPECT_TRUE(body.set_elastic(1e5, 0.3).ok());
    for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
      if (body.mesh.vertices[v][1] > 0.019) body.pinned.push_back(v);
    s.tet_bodies.push_back(std::move(body));
  }
  ColliderDesc floor;  // a plane through the origin, normal +y (moved down below the bodies)
  floor.position = {0.0, -0.5, 0.0};
  s.colliders.push_back(floor);
  ToolDesc tool;
  tool.radius = 0.002;
  tool.half_height = 0.01;
  tool.position = {0.2, 0.2, 0.2};
  tool.mass = 0.05;
  s.tools.push_back(tool);
  s.graspers.push_back({});
  s.targets.push_back({0.0, 0.0, 0.0});
  s.topology_changes = true;
  return s;
}

void expect_error(const Status& s, const std::string& words) {
  ASSERT_FALSE(s.ok()) << words;
  EXPECT_NE(s.error().message().find(words), std::string::npos) << s.error().message();
}

TEST(FeatureHandles, IdsComeFromTheirHandleAndNameTheirKind) {
  auto sim = Simulation::create(scene(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  EXPECT_TRUE(sim->tools().tool(0).ok());
  EXPECT_TRUE(sim->tools().collider(0).ok());
  EXPECT_TRUE(sim->tools().target(0).ok());
  EXPECT_TRUE(sim->graspers().grasper(0).ok());
  EXPECT_TRUE(sim->topology().tet_body(1).ok());
  expect_error(sim->tools().tool(1).status(), "index 1 is not a tool (the scene has 1)");
  expect_error(sim->needles().needle(0).status(), "index 0 is not a needle (the scene has 0)");
  expect_error(sim->topology().tri_body(0).status(), "is not a tri body");
  // A null id (default-made) is refused by name.
  expect_error(sim->tools().apply_force(ToolId{}, {0, 0, 0}, {0, 0, 0}), "a null ToolId");
  // A forged index past the scene's objects too.
  ToolId forged = *sim->tools().tool(0);
  forged.index = 7;
  expect_error(sim->tools().state(forged).status(), "ToolId 7 is not one of the scene's 1");
}

TEST(FeatureHandles, AnIdOfAnotherSimulationIsANamedErrorNeverAnotherBody) {
  auto a = Simulation::create(scene(), {.backend = "cpu", .quiet = true});
  auto b = Simulation::create(scene(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(a.ok() && b.ok());
  const TetBodyId body_of_a = *a->topology().tet_body(0);
  expect_error(b->topology().remove_tets(body_of_a, std::vector<std::uint32_t>{0}).status(),
               "the TetBodyId belongs to another Simulation");
  // b's body 0 is whole: nothing was removed from the wrong scene.
  EXPECT_EQ(b->topology().current_tets(*b->topology().tet_body(0))->size(), a->topology().current_tets(body_of_a)->size());
  expect_error(b->graspers().open(*a->graspers().grasper(0)).status(), "the GrasperId belongs to another Simulation");
  expect_error(b->tools().set_pose(*a->tools().collider(0), {0, 0, 0}, {1, 0, 0, 0}),
               "the ColliderId belongs to another Simulation");
}

TEST(FeatureHandles, ARemovedElementStaysRemovedAndIsNamedAsStale) {
  auto sim = Simulation::create(scene(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  Topology topology = sim->topology();
  const TetBodyId body = *topology.tet_body(1);
  const std::vector<std::uint32_t> tets{0, 5};
  auto removed = topology.remove_tets(body, tets);
  ASSERT_TRUE(removed.ok()) << removed.error().message();
  EXPECT_EQ(removed->tets_removed, tets);
  EXPECT_EQ(removed->body, 1u);
  // The same tets again: stale, and nothing changes.
  const std::size_t live = topology.current_tets(body)->size();
  expect_error(topology.remove_tets(body, std::vector<std::uint32_t>{5}).status(), "was removed already");
  EXPECT_EQ(topology.current_tets(body)->size(), live);
  // The other body is untouched: ids are per body.
  EXPECT_EQ(topology.current_tets(*topology.tet_body(0))->size(), live + tets.size());
  SINEW_ASSERT_OK(sim->step());
}

TEST(FeatureHandles, HandlesDoWhatTheIndexCallsDid) {
  // The same script through the handles and through the deprecated index
  // calls: every position equal after 10 frames.
  const auto run = [](bool handles) {
    auto sim = Simulation::create(scene(), {.backend = "cpu", .quiet = true});
    EXPECT_TRUE(sim.ok());
    std::vector<float> x;
    if (!sim.ok()) return x;
    const Pose jaws{.position = {0.01, 0.0, 0.01}};
    for (int f = 0; f < 10; ++f) {
      const std::array<double, 3> force{0.0, 0.01 * f, 0.0};
      const std::array<double, 3> target{0.001 * f, 0.0, 0.0};
      if (handles) {
        Tools tools = sim->tools();
        EXPECT_TRUE(tools.apply_force(*tools.tool(0), force, {0, 0, 0}).ok());
        EXPECT_TRUE(tools.set_position(*tools.target(0), target).ok());
        EXPECT_TRUE(tools.set_pose(*tools.collider(0), {0, -0.5 - 0.01 * f, 0}, {1, 0, 0, 0}).ok());
        if (f == 3) EXPECT_TRUE(sim->graspers().close(*sim->graspers().grasper(0), jaws, {0.006, 0.006, 0.006}).ok());
        if (f == 7) EXPECT_TRUE(sim->graspers().open(*sim->graspers().grasper(0)).ok());
      } else {
        EXPECT_TRUE(sim->apply_tool_force(0, force, {0, 0, 0}).ok());
        EXPECT_TRUE(sim->set_target(0, target).ok());
        EXPECT_TRUE(sim->set_collider_pose(0, {0, -0.5 - 0.01 * f, 0}, {1, 0, 0, 0}).ok());
        if (f == 3) EXPECT_TRUE(sim->close_grasper(0, jaws, {0.006, 0.006, 0.006}).ok());
        if (f == 7) EXPECT_TRUE(sim->open_grasper(0).ok());
      }
      EXPECT_TRUE(sim->step().ok());
    }
    EXPECT_TRUE(sim->read_positions(x).ok());
    return x;
  };
  const std::vector<float> by_handle = run(true), by_index = run(false);
  ASSERT_FALSE(by_handle.empty());
  EXPECT_EQ(by_handle, by_index);
}

}  // namespace
}  // namespace sinew::test
