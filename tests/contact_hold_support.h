// contact_hold_support.h — a heavy free tool lying on a membrane, shared by
// tests/contact_hold_test.cpp, tests/mesh_contact_test.cpp (the backends'
// agreement) and benchmarks/contact_hold.cpp: how well contacts hold a
// weight that is large against the particles it rests on.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh_contact_support.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"

namespace sinew::test {

/// A 10 cm membrane of 1 cm cells (1 mm thick, 1 MPa: c = 1e-6 1/Pa,
/// 1000 kg/m^3, so 0.1 g a particle), pinned along its border at y = 0, and
/// a rigid capsule tool (radius 4 mm, 3 cm between its caps' centres) of
/// `mass` [kg] under gravity lying on it along x, over the middle of a row
/// of cells (a face under it, no vertex line), dropped from 0.1 mm above the
/// thickness. 60 Hz frames of 20 substeps x 2 iterations, mesh collision on
/// (1 mm, faces against the tool, MeshCollisionDesc::face_manifold as `manifold`).
struct ToolOnMembrane {
  static constexpr int cells = 10;
  static constexpr double cell = 0.01, thickness = 1e-3;
  static constexpr double radius = 0.004, half_height = 0.015;
  static SceneDesc scene(double mass, int contact_sweeps, bool manifold = true) {
    SceneDesc scene;
    scene.gravity = {0.0, -9.81, 0.0};
    scene.solver.time_step = 1.0 / 60.0;
    scene.solver.substeps = 20;
    scene.solver.iterations = 2;
    scene.solver.contact_sweeps = contact_sweeps;
    scene.tri_bodies.push_back(pinned_membrane(cells, cell, 1e-6));
    ToolDesc tool;
    tool.radius = radius;
    tool.half_height = half_height;
    tool.mass = mass;
    const double r2 = radius * radius, l2 = 4.0 * half_height * half_height;
    tool.inertia = {mass * (3 * r2 + l2) / 12, mass * r2 / 2, mass * (3 * r2 + l2) / 12};  // a solid cylinder
    tool.rotation = {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};  // its axis (y) along x
    tool.position = {0.05, radius + thickness + 1e-4, 0.055};
    tool.gravity = true;
    scene.tools.push_back(tool);
    scene.mesh_collision.enabled = true;
    scene.mesh_collision.thickness = thickness;
    scene.mesh_collision.face_manifold = manifold;
    return scene;
  }

  /// What a run measured, worst over its frames.
  struct Measure {
    int crossings = 0;           ///< (frame, triangle) pairs where the tool's axis crossed the membrane
    double below = 0.0;          ///< how far the tool's centre got below the membrane under it [m] (0: never)
    double tool_violation = 0.0; ///< the deepest face contact with the tool inside the thickness [m]
    double penetration = 0.0;    ///< the deepest membrane vertex inside the capsule [m]
    double lowest = 1e9;         ///< the tool's centre, lowest [m]
    double force = 0.0;          ///< mean contact force on the tool along +y over the last `averaged` frames [N]
  };

  /// One frame's measures, folded into m. [in] averaged: frames the force is averaged over.
  static Status measure(Simulation& sim, const SceneDesc& scene, bool average, int averaged, Measure& m) {
    std::vector<float> x;
    if (Status s = sim.read_positions(x); !s) return s;
    const auto id = sim.tools().tool(0);
    if (!id) return id.error();
    auto state = sim.tools().state(*id);
    if (!state) return state.error();
    const std::uint32_t first = sim.info().tri_body_first_particle[0];
    const ToolDesc& tool = scene.tools[0];
    const P3 c{state->position[0], state->position[1], state->position[2]};
    const auto axis = [&](double s) {  // a point of the axis, s in [-1, 1]
      const double w = state->rotation[0], qx = state->rotation[1], qy = state->rotation[2], qz = state->rotation[3];
      // The tool frame's y axis in the world: the rotation's second column.
      const P3 y{2 * (qx * qy - w * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz + w * qx)};
      return P3{c[0] + s * tool.half_height * y[0], c[1] + s * tool.half_height * y[1], c[2] + s * tool.half_height * y[2]};
    };
    const P3 a0 = axis(-1.0), a1 = axis(1.0);
    double height = -1e9;  // the membrane under the tool's centre
    for (const auto& t : scene.tri_bodies[0].mesh.triangles) {
      const P3 a = at(x, first + t[0]), b = at(x, first + t[1]), d = at(x, first + t[2]);
      m.crossings += segment_crosses_triangle(a0, a1, a, b, d);
      if (!segment_crosses_triangle({c[0], 1.0, c[2]}, {c[0], -1.0, c[2]}, a, b, d)) continue;
      const P3 n = cross(sub(b, a), sub(d, a));
      height = a[1] - (n[0] * (c[0] - a[0]) + n[2] * (c[2] - a[2])) / n[1];
    }
    if (height > -1e9) m.below = std::max(m.below, height - c[1]);
    const P3 ab = sub(a1, a0);
    for (std::uint32_t v = 0; v < scene.tri_bodies[0].mesh.vertices.size(); ++v) {
      const P3 d = sub(at(x, first + v), a0);
      const double u = std::clamp(dot(d, ab) / dot(ab, ab), 0.0, 1.0);
      const P3 r{d[0] - u * ab[0], d[1] - u * ab[1], d[2] - u * ab[2]};
      m.penetration = std::max(m.penetration, tool.radius - std::sqrt(dot(r, r)));
    }
    m.tool_violation = std::max(m.tool_violation, sim.last_frame().counter("mesh collision", "tool_violation_m"));
    m.lowest = std::min(m.lowest, c[1]);
    if (average) m.force += state->contact_force[1] / averaged;
    return {};
  }
};

}  // namespace sinew::test
