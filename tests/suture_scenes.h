// suture_scenes.h — the scenes of the needle and suture tests (issue 13,
// part 4; tests/suture_test.cpp), shared with their benchmark
// (benchmarks/suture_benchmark.cpp): two tissue pads either side of a cut
// and a curved needle, with its thread, driven through both.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace sinew::test {

// Two soft pads (an edge network and volumes of E = 30 kPa, nu = 0.45; 12 x 10 x 12 mm of
// 2 mm cells, 1,080 tets each) either side of a cut `gap` wide along the
// z axis (pad A at x < -gap / 2, pad B at x > gap / 2; tops at y = 0),
// each pinned at its far end (x = -/+ (gap / 2 + 12 mm)). No gravity (the
// pads lie on a table), 60 frames per second of 8 substeps with 10 sweeps.
// The needle: a half circle of radius R = 8 mm (17 points), its centre
// 2 mm above the cut, in the z = 0 plane. needle_pose(a) turns it by `a`
// about its centre (the z axis): at 0 its tip, at (-R, 2 mm) and pointing
// down, sits 2 mm over pad A; turning by pi drives it down through A, out of
// A's cut face, across the cut, into B's and up out of B's top at
// (R, 2 mm); by 2 pi its tail has followed. Its thread: 60 mm of 1 mm
// segments from the needle's tail, straight up, its last vertex the knot.
struct SuturePads {
  static constexpr double radius = 0.008, centre_height = 0.002, cell = 0.002;
  static constexpr int thread_segments = 60;
  static SceneDesc scene(double gap = 0.004) {
    SceneDesc scene;
    scene.gravity = {0.0, 0.0, 0.0};  // the pads lie on a table
    scene.solver.time_step = 1.0 / 60.0;
    scene.solver.substeps = 8;
    scene.solver.iterations = 10;
    for (int side = 0; side < 2; ++side) {
      const double x0 = side == 0 ? -gap / 2 - 6 * cell : gap / 2;
      auto mesh = make_tet_grid({.nx = 6, .ny = 5, .nz = 6, .origin = {x0, -5 * cell, -3 * cell},
                                 .cell_size = {cell, cell, cell}});
      TetBodyDesc pad;
      pad.mesh = *mesh;
      // Edges and volumes (the FEM's neo-Hookean needs a far smaller step,
      // README), with the compliances set by hand to c_d = 1/E, c_v =
      // 3 (1 - 2 nu) / E at 30 kPa, 0.45: the tissue these stitches were
      // tuned on, an effective E of ~7 kPa (docs/materials.md).
      // set_elastic(3e4, 0.45) is 4x stiffer: the pulled thread closed the
      // cut less (edges 3.59 mm apart, not < 3.5) and the row slid 0.67 mm
      // along the thread (not < 0.5).
      pad.distance_compliance = 1.0 / 3e4;
      pad.volume_compliance = 3.0 * (1.0 - 2.0 * 0.45) / 3e4;
      pad.velocity_damping = 5.0;
      const int far = side == 0 ? 0 : 6;
      for (int k = 0; k <= 6; ++k)
        for (int j = 0; j <= 5; ++j) pad.pinned.push_back(static_cast<std::uint32_t>(far + 7 * (j + 6 * k)));
      scene.tet_bodies.push_back(pad);
    }
    NeedleDesc needle;
    for (int i = 0; i <= 16; ++i) {
      const double phi = M_PI * i / 16;  // tail at phi = 0, tip at pi
      needle.curve.push_back({radius * std::cos(phi), radius * std::sin(phi), 0.0});
    }
    needle.position = {0.0, centre_height, 0.0};
    needle.puncture_force = 0.01;
    LineBodyDesc thread;
    for (int i = 0; i <= thread_segments; ++i) {
      thread.vertices.push_back({radius, centre_height + 0.001 * i, 0.0});
      thread.masses.push_back(1e-5);
      if (i < thread_segments)
        thread.segments.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1)});
    }
    thread.bending_compliance = 10.0;
    thread.velocity_damping = 5.0;
    scene.line_bodies.push_back(thread);
    needle.thread = 0;
    scene.needles.push_back(needle);
    return scene;
  }
  // The needle turned by a [rad] about its centre (the z axis).
  static std::array<double, 4> needle_rotation(double a) { return {std::cos(a / 2), 0.0, 0.0, std::sin(a / 2)}; }

  // The stitch, frame by frame: the needle turns to 2 pi - 0.2 (its tail
  // just out of B's top) over `turn_frames`, then is pulled away from the
  // cut (up and towards +x, 2:1) at `pull_speed` [m per frame] up to
  // `pulled_most` [m], then tugged: 3 mm back and forth every 2 s.
  static constexpr int turn_frames = 110;
  static constexpr double last_angle = 2.0 * M_PI - 0.2, pull_speed = 5e-4, pulled_most = 0.06;
  static double pulled(int f) {
    if (f < turn_frames) return 0.0;
    const double straight = pull_speed * (f - turn_frames);
    if (straight <= pulled_most) return straight;
    const int tug = f - turn_frames - static_cast<int>(pulled_most / pull_speed);
    return pulled_most - 0.0015 * (1.0 - std::cos(2.0 * M_PI * tug / 120.0));
  }
  static Status drive(Simulation& sim, int f) {
    const double a = std::min(last_angle, last_angle * (f + 1) / turn_frames);
    const double d = pulled(f);
    return sim.set_needle_pose(0, {0.5 * d, centre_height + d, 0.0}, needle_rotation(a));
  }
};

// A puncture's tissue point (xyzw positions in the user's order).
inline std::array<double, 3> puncture_point(const SceneDesc& scene, const Simulation& sim,
                                            const Simulation::Puncture& p, const std::vector<float>& x) {
  std::array<std::uint32_t, 3> tri{};
  std::uint32_t first = 0;
  if (p.body_kind == BodyKind::tet) {
    tri = extract_boundary_surface(scene.tet_bodies[p.body].mesh).triangles[p.triangle];
    first = sim.info().tet_body_first_particle[p.body];
  } else {
    tri = scene.tri_bodies[p.body].mesh.triangles[p.triangle];
    first = sim.info().tri_body_first_particle[p.body];
  }
  std::array<double, 3> q{0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) q[a] += p.weights[k] * x[4 * std::size_t{first + tri[k]} + a];
  return q;
}

// How far [m] a puncture on line body `body` is from its own point on the
// thread (its segment and s, as the row holds it), and from the thread's
// closest point to it: the row must hold the point where the thread is.
struct OnThread {
  double from_row = 0.0, from_closest = 0.0;
};
inline OnThread on_thread(const std::array<double, 3>& q, const Simulation::Puncture& p, const Simulation& sim,
                          std::uint32_t body, std::size_t vertices, const std::vector<float>& x) {
  const std::uint32_t first = sim.info().line_body_first_particle[body];
  OnThread out{INFINITY, INFINITY};
  for (std::size_t i = 0; i + 1 < vertices; ++i) {
    std::array<double, 3> a{}, e{};
    for (int k = 0; k < 3; ++k) {
      a[k] = x[4 * (first + i) + k];
      e[k] = x[4 * (first + i + 1) + k] - a[k];
    }
    const double ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    double s = ee > 0.0 ? ((q[0] - a[0]) * e[0] + (q[1] - a[1]) * e[1] + (q[2] - a[2]) * e[2]) / ee : 0.0;
    s = std::clamp(s, 0.0, 1.0);
    if (i == p.thread_segment) s = p.thread_s;
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) d2 += (q[k] - a[k] - s * e[k]) * (q[k] - a[k] - s * e[k]);
    if (i == p.thread_segment) out.from_row = std::sqrt(d2);
    out.from_closest = std::min(out.from_closest, std::sqrt(d2));
  }
  return out;
}

}  // namespace sinew::test
