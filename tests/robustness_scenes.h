// robustness_scenes.h — the scenes of the divergence, saved-state and log
// tests: a Neo-Hookean block pinned at one end, sagging onto a plane, pushed
// by a rigid tool and pulled by a moving target, with particle forces and
// (optionally) topology changes; and what a test compares bitwise.
#pragma once

#include <cmath>
#include <cstring>
#include <vector>

#include "test_support.h"

namespace sinew::test {

/// Neo-Hookean of E = 3 kPa with 8 substeps at 60 Hz: Courant number
/// h sqrt(mu / rho) / edge = 0.22, within its stable range (README, "FEM
/// materials"). [in] topology: SceneDesc::topology_changes.
inline SceneDesc robustness_block(bool topology = false) {
  SceneDesc scene;
  TetBodyDesc body;
  body.mesh = box_mesh(4, 2, 2, 0.01);
  EXPECT_TRUE(body.set_material(TetMaterial::neo_hookean, 3e3, 0.4).ok());
  body.density = 1000.0;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] < 1e-9) body.pinned.push_back(v);
  scene.tet_bodies.push_back(body);
  ColliderDesc floor;
  floor.shape = ColliderShape::plane;
  floor.position = {0.0, -0.004, 0.0};
  scene.colliders.push_back(floor);
  // The far top corner on a target the test moves.
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v) {
    const Vec3d& p = body.mesh.vertices[v];
    if (p[0] > 0.0399 && p[1] > 0.0199 && p[2] > 0.0199) {
      scene.attachments.push_back({.vertex = {.body_kind = BodyKind::tet, .body = 0, .vertex = v},
                                   .target = 0, .compliance = 1e-4});
      scene.targets.push_back({p[0], p[1], p[2]});
    }
  }
  ToolDesc tool;
  tool.radius = 0.004;
  tool.half_height = 0.01;
  tool.mass = 0.02;
  tool.gravity = false;
  const double m = tool.mass, r2 = tool.radius * tool.radius, l2 = 4 * tool.half_height * tool.half_height;
  tool.inertia = {m * (3 * r2 + l2) / 12, m * r2 / 2, m * (3 * r2 + l2) / 12};
  tool.position = {0.025, 0.0205 + tool.radius, 0.01};
  tool.rotation = {std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0};  // its axis along z
  scene.tools.push_back(tool);
  scene.external_forces = true;
  scene.topology_changes = topology;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 8;
  scene.solver.iterations = 2;
  return scene;
}

/// The inputs of frame `f` (1-based): the tool pushed down, the target
/// swinging, a small force on particle 5 every third frame. A function of
/// the frame alone, so a run restored to frame k and one never stopped
/// get the same inputs from frame k + 1 on.
inline void drive(Simulation& sim, int f) {
  auto tool = sim.tools().tool(0);
  auto target = sim.tools().target(0);
  ASSERT_TRUE(tool.ok() && target.ok());
  SINEW_ASSERT_OK(sim.tools().apply_force(*tool, {0.0, -0.05, 0.0}, {0.0, 0.0, 0.0}));
  SINEW_ASSERT_OK(sim.tools().set_position(*target, {0.04, 0.02 + 0.005 * std::sin(0.2 * f), 0.02}));
  if (f % 3 == 0) {
    std::vector<float> forces(3 * sim.info().particles, 0.0f);
    forces[3 * 5 + 1] = 0.01f;
    SINEW_ASSERT_OK(sim.set_particle_forces(forces));
  }
}

/// Steps frames [from, to] with drive's inputs.
inline void run(Simulation& sim, int from, int to) {
  for (int f = from; f <= to; ++f) {
    drive(sim, f);
    SINEW_ASSERT_OK(sim.step());
  }
}

/// Positions and velocities, read back (for a bitwise comparison).
struct Snapshot {
  std::vector<float> x, v;
  std::array<double, 3> tool{};
};
inline Snapshot snapshot(Simulation& sim) {
  Snapshot s;
  EXPECT_TRUE(sim.read_positions(s.x).ok());
  EXPECT_TRUE(sim.read_velocities(s.v).ok());
  auto tool = sim.tools().tool(0);
  if (tool.ok()) {
    auto state = sim.tools().state(*tool);
    if (state.ok()) s.tool = state->position;
  }
  return s;
}
/// Bitwise equal (memcmp: a NaN equals itself, -0 differs from +0).
inline bool same_bits(const Snapshot& a, const Snapshot& b) {
  return a.x.size() == b.x.size() && a.v.size() == b.v.size() &&
         std::memcmp(a.x.data(), b.x.data(), a.x.size() * sizeof(float)) == 0 &&
         std::memcmp(a.v.data(), b.v.data(), a.v.size() * sizeof(float)) == 0 &&
         std::memcmp(a.tool.data(), b.tool.data(), sizeof a.tool) == 0;
}

}  // namespace sinew::test
