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
// Writes three VTU series (pad.pvd, thread.pvd and needle.pvd; the thread
// and needle as line cells) and prints, per reported frame, the wall time,
// the punctures (entering or leaving, on the needle or on the thread) and
// how wide the slit is at the stitches' depth.
//
//   suturing [--backend auto|cpu|opencl|vulkan] [--out DIR] [--every N]
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace {

constexpr double kCell = 0.002, kRadius = 0.008, kAbove = 0.002;  // [m]
constexpr int kNx = 13, kNy = 5, kNz = 6, kSlit = 6;               // cells; the slit is column kSlit
constexpr int kThreadSegments = 100;
constexpr double kStitchZ[2] = {-0.003, 0.003};
constexpr int kTurn = 110, kShift = 40;  // frames of each phase
// The pull: up and away from the cut at this speed [m per frame] until the
// knot holds at the first puncture, then kTighten frames more, then held
// for kHold frames; at most kMostPull frames to reach the knot.
constexpr double kPullSpeed = 4.25e-4;
constexpr int kTighten = 10, kHold = 60, kMostPull = 400;
constexpr double kLastAngle = 2.0 * M_PI - 0.2;

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

// The needle's pose in the script: turned about the z axis by `angle`
// around its centre, which sits kAbove over the cut at depth z.
struct Pose {
  std::array<double, 3> position;
  double angle;
};
// The stitches' frames: both turns, then the pull.
constexpr int kStitched = 2 * kTurn + kShift;
// The needle's pose in frame f < kStitched, or `pulled` [m] into the pull.
Pose script(int f, double pulled) {
  const int second = kTurn + kShift;
  if (f < kTurn) return {{0.0, kAbove, kStitchZ[0]}, kLastAngle * (f + 1) / kTurn};
  if (f < second) {  // over to the second stitch, the tip above the left lip
    const double u = double(f - kTurn + 1) / kShift;
    return {{0.0, kAbove, kStitchZ[0] + u * (kStitchZ[1] - kStitchZ[0])}, kLastAngle};
  }
  if (f < kStitched) return {{0.0, kAbove, kStitchZ[1]}, kLastAngle + kLastAngle * (f - second + 1) / kTurn};
  return {{0.5 * pulled, kAbove + pulled, kStitchZ[1]}, 2.0 * kLastAngle};  // up and away from the cut
}

}  // namespace

int main(int argc, char** argv) {
  std::string backend = "auto", out = "suturing_out";
  int every = 10;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--backend") backend = argv[i + 1];
    else if (flag == "--out") out = argv[i + 1];
    else if (flag == "--every") every = std::max(1, std::atoi(argv[i + 1]));
    else return fail("unknown option " + flag + " (--backend, --out, --every)");
  }

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
  const std::uint32_t thread_first = sim->info().line_body_first_particle[0];
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

  std::vector<std::filesystem::path> pad_files, thread_files, needle_files;
  std::vector<double> times;
  std::vector<std::array<std::uint32_t, 2>> thread_cells, needle_cells;
  for (std::uint32_t i = 0; i < kThreadSegments; ++i) thread_cells.push_back({i, i + 1});
  for (std::uint32_t i = 0; i + 1 < needle.curve.size(); ++i) needle_cells.push_back({i, i + 1});
  std::vector<float> x, ms;
  double width_before = 0.0, pulled = 0.0;
  int knot_frame = -1, last = -1;  // when the knot first held; the last frame
  for (int f = 0; last < 0 || f <= last; ++f) {
    const Pose p = script(f, pulled);
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
    // The VTU series: the pad, the thread, the needle at its pose.
    const std::string stem = std::to_string(f);
    pad_files.push_back(std::filesystem::path(out) / ("pad_" + stem + ".vtu"));
    thread_files.push_back(std::filesystem::path(out) / ("thread_" + stem + ".vtu"));
    needle_files.push_back(std::filesystem::path(out) / ("needle_" + stem + ".vtu"));
    times.push_back(sim->last_frame().time);
    const std::span<const float> all(x);
    if (auto s = sinew::write_vtu(pad_files.back(), all.subspan(std::size_t{pad_first} * 4, pad_vertices * 4), 4,
                                  pad.mesh.tets);
        !s)
      return fail(s.error().message());
    if (auto s = sinew::write_vtu_lines(thread_files.back(),
                                        all.subspan(std::size_t{thread_first} * 4, (kThreadSegments + 1) * 4), 4,
                                        thread_cells);
        !s)
      return fail(s.error().message());
    std::vector<float> curve;
    for (const auto& c : needle.curve) {
      // The point rotated by the state's quaternion (w, x, y, z), then moved.
      const auto& r = state->rotation;
      const double w = r[0], u[3] = {r[1], r[2], r[3]};
      const double t[3] = {2 * (u[1] * c[2] - u[2] * c[1]), 2 * (u[2] * c[0] - u[0] * c[2]),
                           2 * (u[0] * c[1] - u[1] * c[0])};
      for (int k = 0; k < 3; ++k) {
        const double cross = u[(k + 1) % 3] * t[(k + 2) % 3] - u[(k + 2) % 3] * t[(k + 1) % 3];
        curve.push_back(static_cast<float>(state->position[k] + c[k] + w * t[k] + cross));
      }
    }
    if (auto s = sinew::write_vtu_lines(needle_files.back(), curve, 3, needle_cells); !s)
      return fail(s.error().message());
  }
  for (const auto& [name, files] : {std::pair{"pad.pvd", &pad_files}, std::pair{"thread.pvd", &thread_files},
                                    std::pair{"needle.pvd", &needle_files}})
    if (auto s = sinew::write_pvd(std::filesystem::path(out) / name, *files, times); !s)
      return fail(s.error().message());
  std::sort(ms.begin(), ms.end());
  std::printf("median %.2f ms per frame; the slit at the stitches %.2f -> %.2f mm\n", ms[ms.size() / 2],
              width_before * 1e3, slit_width(x) * 1e3);
  std::printf("open %s/pad.pvd, thread.pvd and needle.pvd in ParaView\n", out.c_str());
  return 0;
}
