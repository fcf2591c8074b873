// suturing — two stitches across a cut, tightened (issue 13, part 4).
//
// A tissue pad (26 x 10 x 12 mm, 2 mm cells, an edge network of E = 30 kPa)
// with a cut made by the mesh: a 2 mm slit 8 mm deep across its middle,
// joined only by its bottom layer; its ends and bottom are held (it lies on
// a table). A curved needle (a half circle of radius 8 mm, kinematic) with a
// 100 mm thread tied to its tail is turned about the cut twice: in through
// the left lip, out through the slit's face, across, in through the right
// face and out through the right lip, at z = -3 mm and again at z = +3 mm
// (a running suture: the thread crosses over the cut between them). Then it
// is pulled up and away until the thread's knot (its last vertex) holds at
// the first puncture, then 4 mm more (kTighten frames), and held there: the
// stitches close the slit.
//
// Writes suturing.pvd (the pad, the thread and the needle as lines, from
// frame 0: sinew/vtk_output.h) and prints, per reported frame, the wall time,
// the punctures (entering or leaving, on the needle or on the thread) and
// how wide the slit is at the stitches' depth.
//
//   suturing --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command_line.h"
#include "suture_scene.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace {

constexpr double kCell = 0.002;  // [m]
constexpr double kRadius = sinew::examples::kSutureNeedleRadius, kAbove = sinew::examples::kSutureNeedleAbove;
constexpr int kNx = 13, kNy = 5, kNz = 6, kSlit = 6;               // cells; the slit is column kSlit
constexpr int kThreadSegments = 100;
constexpr const double (&kStitchZ)[2] = sinew::examples::kSutureStitchZ;
// The pull: up and away from the cut at this speed [m per frame] until the
// knot holds at the first puncture, then kTighten frames more, then held
// for kHold frames; at most kMostPull frames to reach the knot.
constexpr double kPullSpeed = 4.25e-4;
constexpr int kTighten = 10, kHold = 60, kMostPull = 400;

int fail(const std::string& message) {
  std::fprintf(stderr, "suturing: %s\n", message.c_str());
  return 1;
}

// The pad: a grid with the slit's cells removed above the bottom layer
// (every vertex stays used: the slit's faces are the vertex columns either
// side of it).
sinew::TetMesh slit_pad() {
  auto grid = sinew::make_tet_grid({.nx = kNx, .ny = kNy, .nz = kNz,
                                    .origin = {-kNx * kCell / 2, -kNy * kCell, -kNz * kCell / 2},
                                    .cell_size = {kCell, kCell, kCell}});
  sinew::TetMesh pad = *grid;
  const double slit_lo = -kNx * kCell / 2 + kSlit * kCell, slit_hi = slit_lo + kCell;
  std::erase_if(pad.tets, [&](const std::array<std::uint32_t, 4>& t) {
    double x = 0.0, y = 0.0;
    for (std::uint32_t v : t) x += pad.vertices[v][0] / 4, y += pad.vertices[v][1] / 4;
    return x > slit_lo && x < slit_hi && y > -(kNy - 1) * kCell;
  });
  return pad;
}

// The stitches' frames (both turns; the script is suture_scene.h's), then the pull.
constexpr int kStitched = sinew::examples::kSutureStitchFrames;

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "suturing",
      "Two stitches across a cut in a tissue pad, tightened: a curved needle with a 100 mm thread turned\n"
      "about the cut twice, then pulled until the knot holds. Prints per reported frame the wall time, the\n"
      "punctures and the slit's width; writes suturing.pvd (pad, thread, needle) into --out.");
  std::string backend = "auto", out = cli.default_out();
  int every = 10;
  cli.add_backend(backend);
  cli.app().add_option("--every", every, "Report and write the VTU files every N frames of 1/60 s (and the last)")
      ->check(sinew::examples::at_least(1));
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  sinew::SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};  // on a table
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 8;
  scene.solver.iterations = 10;
  sinew::TetBodyDesc pad;
  pad.mesh = slit_pad();
  if (auto s = pad.set_elastic(3e4, 0.45); !s) return fail(s.error().message());
  pad.velocity_damping = 5.0;
  for (std::uint32_t v = 0; v < pad.mesh.vertices.size(); ++v) {
    const auto& p = pad.mesh.vertices[v];
    if (std::abs(std::abs(p[0]) - kNx * kCell / 2) < 1e-9 || p[1] < -kNy * kCell + 1e-9) pad.pinned.push_back(v);
  }
  scene.tet_bodies.push_back(pad);
  sinew::NeedleDesc needle;
  for (int i = 0; i <= 16; ++i)
    needle.curve.push_back({kRadius * std::cos(M_PI * i / 16), kRadius * std::sin(M_PI * i / 16), 0.0});
  needle.position = {0.0, kAbove, kStitchZ[0]};
  needle.puncture_force = 0.01;
  needle.thread = 0;
  sinew::LineBodyDesc thread;
  for (int i = 0; i <= kThreadSegments; ++i) {
    thread.vertices.push_back({kRadius, kAbove + 0.001 * i, kStitchZ[0]});
    thread.masses.push_back(1e-5);
    if (i < kThreadSegments) thread.segments.push_back({std::uint32_t(i), std::uint32_t(i + 1)});
  }
  thread.bending_compliance = 10.0;
  thread.velocity_damping = 5.0;
  scene.line_bodies.push_back(thread);
  scene.needles.push_back(needle);

  auto sim = sinew::Simulation::create(scene, {.backend = backend});
  if (!sim) return fail(sim.error().message());
  sinew::Needles needles = sim->needles();
  const auto needle_id = needles.needle(0);
  if (!needle_id) return fail(needle_id.error().message());
  std::printf("suturing on %s: %zu tets, a %d-segment thread; %d frames of stitching, then the pull\n",
              sim->device_name().c_str(), pad.mesh.tets.size(), kThreadSegments, kStitched);

  const std::uint32_t pad_first = sim->info().tet_body_first_particle[0];
  const std::size_t pad_vertices = pad.mesh.vertices.size();
  // The slit's width at the stitches' depth (y = -6 mm): its two faces'
  // vertices at each stitch's z (mean of the two nearest grid planes).
  const auto slit_width = [&](const std::vector<float>& x) {
    double sum = 0.0;
    int n = 0;
    for (std::uint32_t v = 0; v < pad_vertices; ++v) {
      const auto& p = pad.mesh.vertices[v];
      if (std::abs(p[1] + 3 * kCell) > 1e-9 || std::abs(std::abs(p[2]) - kCell) > 1e-9) continue;
      const double face_x = -kNx * kCell / 2 + kSlit * kCell;
      if (std::abs(p[0] - face_x) < 1e-9) sum -= x[4 * (pad_first + v)], ++n;
      if (std::abs(p[0] - face_x - kCell) < 1e-9) sum += x[4 * (pad_first + v)];
    }
    return n > 0 ? sum / n : 0.0;
  };

  // Bodies named as in scenes/suturing.json; frame numbers counted as the
  // runner does (its frame 1 is this loop's f = 0), so its output is the same.
  auto output = sinew::SceneOutput::create(
      scene, out,
      {.bodies = {{.kind = sinew::BodyKind::tet, .name = "pad"}, {.kind = sinew::BodyKind::line, .name = "thread"}},
       .name = "suturing"});
  if (!output) return fail(output.error().message());
  if (auto s = output->write(*sim, 0); !s) return fail(s.error().message());
  std::vector<float> x, ms;
  double width_before = 0.0, pulled = 0.0;
  int knot_frame = -1, last = -1;  // when the knot first held; the last frame
  for (int f = 0; last < 0 || f <= last; ++f) {
    const sinew::examples::SutureNeedlePose p = sinew::examples::suture_script(f, pulled);
    const std::array<double, 4> q{std::cos(p.angle / 2), 0.0, 0.0, std::sin(p.angle / 2)};
    if (auto s = needles.set_pose(*needle_id, p.position, q); !s) return fail(s.error().message());
    if (auto s = sim->step(); !s) return fail("frame " + std::to_string(f) + ": " + s.error().message());
    ms.push_back(static_cast<float>(sim->last_frame().wall_ms));
    if (auto s = sim->read_positions(x); !s) return fail(s.error().message());
    if (f == 0) width_before = slit_width(x);
    auto state = needles.state(*needle_id);
    if (!state) return fail(state.error().message());
    if (f >= kStitched) {  // the pull: until the knot holds at the first puncture, then kTighten frames more
      const bool knotted = !state->punctures.empty() && state->punctures[0].on_thread &&
                           state->punctures[0].thread_segment + 1 == kThreadSegments;
      if (knot_frame < 0 && knotted) {
        knot_frame = f, last = f + kTighten + kHold;
        std::printf("frame %3d  the knot holds at the first puncture, the needle %.1f mm up\n", f, pulled * 1e3);
      }
      if (knot_frame < 0 && f - kStitched >= kMostPull)
        return fail("the knot never reached the first puncture in " + std::to_string(kMostPull) + " frames of pulling");
      if (knot_frame < 0 || f < knot_frame + kTighten) pulled += kPullSpeed;
    }
    if (f % every != 0 && f != last) continue;
    std::string holes;
    for (const auto& h : state->punctures) holes += std::string(h.exit ? "out" : "in") + (h.on_thread ? "/thread " : "/needle ");
    std::printf("frame %3d  %6.2f ms  slit %.2f mm  %zu punctures: %s\n", f, ms.back(), slit_width(x) * 1e3,
                state->punctures.size(), holes.c_str());
    if (auto s = output->write(*sim, f + 1); !s) return fail(s.error().message());
  }
  std::sort(ms.begin(), ms.end());
  std::printf("median %.2f ms per frame; the slit at the stitches %.2f -> %.2f mm\n", ms[ms.size() / 2],
              width_before * 1e3, slit_width(x) * 1e3);
  std::printf("open %s/suturing.pvd in ParaView\n", out.c_str());
  return 0;
}
