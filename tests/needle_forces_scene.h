// needle_forces_scene.h — a needle pushed at constant speed into a tissue
// pad, recording the force it feels over depth (docs/needles.md, "Needle
// forces"); shared by tests/needle_forces_test.cpp and
// benchmarks/needle_forces.cpp.
//
// The pad: 24 x 12 x 24 mm of 2 mm cells (6 tets each, set_elastic(E, 0.45),
// 1000 kg/m^3), its top at y = 0, its bottom pinned, lightly damped so the
// push is quasi-static. The needle: straight, 30 mm, tip down, over a point
// off the grid's lines, driven down at `speed`.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/needles.h"
#include "sinew/simulation.h"

namespace sinew::test {

struct NeedlePushSettings {
  double young = 2e4;             // the pad's E [Pa]
  double tip_radius = 3e-3;       // NeedleDesc::tip_radius [m]
  double puncture_force = 0.5;    // [N]
  double shaft_friction = 0.0;    // NeedleDesc's [N/m], [N/m], [N s/m^2], [m/s], [N]
  double shaft_static_friction = 0.0;
  double shaft_viscous_friction = 0.0;
  double shaft_stick_velocity = 1e-3;
  double cutting_force = 0.0;
  double speed = 0.01;            // of the push [m/s]
  int substeps = 16, iterations = 20;
};

inline constexpr double kPadCell = 0.002;
// Where the needle stands: off the grid's lines (x, z) [m].
inline constexpr double kPushX = 0.0007, kPushZ = 0.0009;
// The tip's start, just above the pad's top [m].
inline constexpr double kPushStart = 0.0002;

inline SceneDesc needle_push_scene(const NeedlePushSettings& s) {
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = s.substeps;
  scene.solver.iterations = s.iterations;
  constexpr std::uint32_t nx = 12, ny = 6, nz = 12;
  auto mesh = make_tet_grid({.nx = nx, .ny = ny, .nz = nz, .origin = {-6 * kPadCell, -6 * kPadCell, -6 * kPadCell},
                             .cell_size = {kPadCell, kPadCell, kPadCell}});
  TetBodyDesc pad;
  pad.mesh = *mesh;
  (void)pad.set_elastic(s.young, 0.45);
  pad.velocity_damping = 5.0;
  for (std::uint32_t i = 0; i < pad.mesh.vertices.size(); ++i)
    if (pad.mesh.vertices[i][1] < -6 * kPadCell + 1e-9) pad.pinned.push_back(i);
  scene.tet_bodies.push_back(pad);
  NeedleDesc needle;
  needle.curve = {{0.0, 0.03, 0.0}, {0.0, 0.0, 0.0}};  // tail up, tip at the origin
  needle.position = {kPushX, kPushStart, kPushZ};
  needle.puncture_force = s.puncture_force;
  needle.tip_radius = s.tip_radius;
  needle.shaft_friction = s.shaft_friction;
  needle.shaft_static_friction = s.shaft_static_friction;
  needle.shaft_viscous_friction = s.shaft_viscous_friction;
  needle.shaft_stick_velocity = s.shaft_stick_velocity;
  needle.cutting_force = s.cutting_force;
  scene.needles.push_back(needle);
  return scene;
}

// One frame of the push.
struct NeedlePushSample {
  double depth = 0.0;   // the tip below the pad's rest top [m]
  double force = 0.0;   // the reaction along the needle, against the push [N]
  double tip_force = 0.0;  // NeedleState::tip_force [N]
  bool punctured = false;  // the needle holds a puncture
  std::size_t punctures = 0;  // how many
  bool pushing = false;    // its tip pushes a surface
  std::uint32_t inverted_tets = 0;
  std::uint32_t refused_inverted = 0;
};

// Pushes the needle down at s.speed until its tip is `depth` below the pad's
// top, a frame at a time. [out] trace: one sample per frame. Errors: the
// Simulation's.
inline Status push_needle(Simulation& sim, const NeedlePushSettings& s, double depth,
                          std::vector<NeedlePushSample>& trace) {
  const double dt = 1.0 / 60.0;
  auto id = sim.needles().needle(0);
  if (!id) return id.error();
  for (int f = 1;; ++f) {
    const double y = kPushStart - s.speed * dt * f;
    if (-y > depth) return {};
    if (Status st = sim.needles().set_pose(*id, {kPushX, y, kPushZ}, {1.0, 0.0, 0.0, 0.0}); !st) return st;
    if (Status st = sim.step(); !st) return st;
    auto state = sim.needles().state(*id);
    if (!state) return state.error();
    NeedlePushSample sample;
    sample.depth = -y;
    sample.force = state->reaction_force[1];
    sample.tip_force = state->tip_force;
    sample.punctured = !state->punctures.empty();
    sample.punctures = state->punctures.size();
    sample.pushing = state->pushing;
    sample.inverted_tets = sim.last_frame().inverted_tets;
    sample.refused_inverted = state->refused_inverted;
    trace.push_back(sample);
  }
}

}  // namespace sinew::test
