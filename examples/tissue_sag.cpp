// tissue_sag — a block of soft tissue, pinned on one face, sagging under
// gravity. Writes its binary VTK output (open tissue_sag.pvd in ParaView:
// displacement, velocity and Green strain, sinew/vtk_output.h) and prints
// the wall time per frame, its errors, and when the block has settled (its
// lowest point within 1 mm of where it ends). The tissue is damped by a
// velocity damping of 4 1/s (TetBodyDesc::velocity_damping: velocities decay
// as exp(-4 t) in free motion), which lets it swing down past its sagged
// shape once or twice and settle in ~1.6 s (a linear cantilever estimate of
// the tip's static sag, q L^4 / (8 E I), is about 80 mm; the block ends at
// ~75 mm). --velocity-damping 0 shows the undamped swing (35-85 mm for
// seconds). Stiffness damping (--stiffness-damping TAU) is the physical,
// Rayleigh-like one, but at this example's 20 substeps x 1 iteration each
// sweep moves only 1 / (1 + tau / h) of the way to equilibrium, so a tau
// large enough to damp the swing (~40 ms) needs ~10x the iterations, or the
// block sags as if softer (README, "Damping").
//
//   tissue_sag --help   (the options, their defaults and units)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace {

struct Options {
  std::string backend = "auto";
  int frames = 180;
  int cells = 6;  // along the block's short side
  // Many substeps of one iteration ("Small Steps", Macklin et al. 2019):
  // stiffer and more accurate than few substeps of many iterations.
  int substeps = 20;
  int iterations = 1;
  double stiffness_damping = 0.0;  // tau [s]
  double velocity_damping = 4.0;   // k [1/s]
  std::string out;
};

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  sinew::examples::CommandLine cli(
      "tissue_sag",
      "A 10 x 2.5 x 5 cm block of soft tissue (E = 30 kPa, nu = 0.45), pinned on one face, sagging under gravity.\n"
      "Prints the wall time per frame, its errors and when the block has settled; writes tissue_sag.pvd\n"
      "(frame 0, then every 10 frames: block_N.vtu with displacement, velocity and strain) into --out.");
  using sinew::examples::at_least;
  opt.out = cli.default_out();
  cli.add_backend(opt.backend);
  cli.app().add_option("--frames", opt.frames, "Frames of 1/60 s to run")->check(at_least(1));
  cli.app().add_option("--cells", opt.cells, "Cells along the block's short side (4x, 1x, 2x along x, y, z)")
      ->check(at_least(1));
  cli.app().add_option("--substeps", opt.substeps, "Substeps per frame")->check(at_least(1));
  cli.app().add_option("--iterations", opt.iterations, "Solver iterations per substep")->check(at_least(1));
  cli.app().add_option("--stiffness-damping", opt.stiffness_damping, "Stiffness damping tau [s]")->check(at_least(0));
  cli.app().add_option("--velocity-damping", opt.velocity_damping, "Velocity damping k [1/s]")->check(at_least(0));
  cli.add_out(opt.out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  // A 10 cm x 2.5 cm x 5 cm block of soft tissue (E = 30 kPa, nu = 0.45,
  // liver-like), its x = 0 face pinned to a wall.
  const double size[3] = {0.10, 0.025, 0.05};
  const int n[3] = {4 * opt.cells, opt.cells, 2 * opt.cells};
  auto mesh = sinew::make_tet_grid({.nx = n[0], .ny = n[1], .nz = n[2],
                                    .origin = {0.0, 0.0, 0.0},
                                    .cell_size = {size[0] / n[0], size[1] / n[1], size[2] / n[2]},
                                    .split = sinew::TetsPerCell::six});
  if (!mesh) { std::fprintf(stderr, "%s\n", mesh.error().message().c_str()); return 1; }

  sinew::TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1060.0;
  if (auto s = body.set_elastic(30e3, 0.45); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
  body.stiffness_damping = opt.stiffness_damping;
  body.velocity_damping = opt.velocity_damping;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] == 0.0) body.pinned.push_back(v);

  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = opt.substeps, .iterations = opt.iterations};
  scene.tet_bodies.push_back(std::move(body));

  auto sim = sinew::Simulation::create(scene, {.backend = opt.backend});
  if (!sim) { std::fprintf(stderr, "%s\n", sim.error().message().c_str()); return 1; }
  const auto& info = sim->info();
  std::printf("tissue_sag on %s: %u particles, %u constraints (%u distance, %u volume), %u colours, "
              "%d substeps x %d iterations\n",
              sim->device_name().c_str(), info.particles, info.constraints(), info.distance_constraints,
              info.volume_constraints, info.colors, opt.substeps, opt.iterations);

  // The block is named as in scenes/tissue_sag.json: the runner's output of it is the same.
  auto output = sinew::SceneOutput::create(scene, opt.out, {.bodies = {{.name = "block"}}, .name = "tissue_sag"});
  if (!output) { std::fprintf(stderr, "%s\n", output.error().message().c_str()); return 1; }
  if (auto s = output->write(*sim, 0); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
  std::vector<float> x;
  std::vector<double> lowest;  // the block's lowest point per frame [m]
  double total_ms = 0.0;
  for (int f = 1; f <= opt.frames; ++f) {
    if (auto s = sim->step(); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
    total_ms += sim->last_frame().wall_ms;
    if (auto s = sim->read_positions(x); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
    float low = 0.0f;
    for (std::uint32_t p = 0; p < info.particles; ++p) low = std::min(low, x[4 * p + 1]);
    lowest.push_back(low);
    if (f % 10 != 0 && f != opt.frames) continue;
    if (auto s = output->write(*sim, f); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
    const float tip = lowest.back();  // lowest point [m]
    const sinew::FrameStats& st = sim->last_frame();
    std::printf("frame %4d  t = %.3f s  %.3f ms/frame (mean %.3f)  residual rms %.2e  volume change %+.3f%%  "
                "kinetic energy %.2e J  lowest point %.1f mm\n",
                f, st.time, st.wall_ms, total_ms / f, st.residual_rms, 100.0 * st.volume_change, st.kinetic_energy,
                1e3 * tip);
  }
  // Settled: the lowest point stays within 1 mm of where it ends from then on.
  int settled = static_cast<int>(lowest.size());
  while (settled > 0 && std::abs(lowest[settled - 1] - lowest.back()) < 1e-3) --settled;
  if (settled < static_cast<int>(lowest.size()) - 1)
    std::printf("settled (lowest point within 1 mm of its final %.1f mm) after %.2f s\n", 1e3 * lowest.back(),
                settled / 60.0);
  else
    std::printf("not settled within %.2f s (stiffness damping %g s, velocity damping %g 1/s)\n",
                lowest.size() / 60.0, opt.stiffness_damping, opt.velocity_damping);
  std::printf("mean %.3f ms per frame over %d frames (errors reduced on the device, %llu bytes read back per "
              "frame); open %s/tissue_sag.pvd in ParaView\n",
              total_ms / opt.frames, opt.frames,
              static_cast<unsigned long long>(sim->last_frame().read_back_bytes), opt.out.c_str());
  return 0;
}
