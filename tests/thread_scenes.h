// thread_scenes.h — the scenes of the continuous collision tests (issue
// 13, part 3; tests/continuous_collision_test.cpp), shared with their
// benchmark (benchmarks/continuous_collision_benchmark.cpp): threads and a
// thin probe driven at a tool's speed against each other and a membrane.
// Each scene's drive() moves its targets or collider for frame f.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "mesh_contact_support.h"
#include "sinew/simulation.h"

namespace sinew::test {

inline constexpr double kFrame = 1.0 / 60.0;

// The tests' common settings: no gravity, 60 frames per second of 8
// substeps with 10 sweeps, mesh collision at 0.5 mm with CCD on or off.
inline SceneDesc thread_scene(bool continuous) {
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
  // Each target's distance from its start after frame f (of `frame` [s]):
  // `speed` [m/s] until 3 cm (past where the rings are tight: they hook after 1 cm and
  // can stretch about 2.3 cm more), then held.
  static double pulled(int f, double speed, double frame = kFrame) { return std::min(speed * (f + 1) * frame, 0.03); }
  static Status drive(Simulation& sim, int f, double speed, double frame = kFrame) {
    const double d = pulled(f, speed, frame);
    if (Status s = sim.set_target(0, {-r - d, 0.0, 0.0}); !s) return s;
    return sim.set_target(1, {2.0 * r + d, 0.0, 0.0});
  }
};

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
  static Status drive(Simulation& sim, int f, double speed) {
    for (int side = 0; side < 2; ++side)
      if (Status s = sim.set_target(side, {end_x(side), height(f, speed), z}); !s) return s;
    return {};
  }
};

// ---- A thin probe pushed up into a membrane.

// The membrane of ThreadUnderMembrane alone, and under it a capsule
// collider (a needle-thin probe: radius 0.5 mm, 2 cm long, upright) whose
// tip rises at `speed` from 5 mm under the membrane to 15 mm above its
// plane, off the grid's lines (no vertex on its path), then stays.
struct ProbeUnderMembrane {
  static constexpr double x = 0.03013, z = 0.03017, half = 0.01;
  static SceneDesc scene(bool continuous) {
    SceneDesc scene = ThreadUnderMembrane::scene(continuous);
    scene.line_bodies.clear();
    scene.attachments.clear();
    scene.targets.clear();
    ColliderDesc probe;
    probe.shape = ColliderShape::capsule;
    probe.radius = 5e-4;
    probe.half_height = half;
    probe.position = {x, tip(-1, 1.0) - half, z};
    scene.colliders.push_back(probe);
    return scene;
  }
  // The tip's height after frame f (f = -1: the start).
  static double tip(int f, double speed) { return std::min(-0.005 + speed * (f + 1) * kFrame, 0.015); }
  static Status drive(Simulation& sim, int f, double speed) {
    return sim.set_collider_pose(0, {x, tip(f, speed) - half, z}, {1.0, 0.0, 0.0, 0.0});
  }
};

}  // namespace sinew::test
