// tissue_sag — a block of soft tissue, pinned on one face, sagging under
// gravity. Writes a VTU series (open tissue_sag.pvd in ParaView) and prints
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
//   tissue_sag [--backend auto|cpu|opencl|vulkan] [--frames N] [--cells N]
//              [--out DIR] [--substeps N] [--iterations N]
//              [--stiffness-damping TAU_S] [--velocity-damping K_PER_S]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/simulation.h"

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
  std::string out = "tissue_sag_out";
};

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    if (!v) { std::fprintf(stderr, "missing value after %s\n", a.c_str()); return false; }
    if (a == "--backend") o.backend = v;
    else if (a == "--frames") o.frames = std::atoi(v);
    else if (a == "--cells") o.cells = std::atoi(v);
    else if (a == "--substeps") o.substeps = std::atoi(v);
    else if (a == "--iterations") o.iterations = std::atoi(v);
    else if (a == "--out") o.out = v;
    else if (a == "--stiffness-damping") o.stiffness_damping = std::atof(v);
    else if (a == "--velocity-damping") o.velocity_damping = std::atof(v);
    else { std::fprintf(stderr, "unknown option %s\n", a.c_str()); return false; }
    ++i;
  }
  if (o.frames < 1 || o.cells < 1) { std::fprintf(stderr, "--frames and --cells must be >= 1\n"); return false; }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!parse(argc, argv, opt)) return 2;

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
  const auto tets = body.mesh.tets;  // kept for the VTU output
  scene.tet_bodies.push_back(std::move(body));

  auto sim = sinew::Simulation::create(scene, {.backend = opt.backend});
  if (!sim) { std::fprintf(stderr, "%s\n", sim.error().message().c_str()); return 1; }
  const auto& info = sim->info();
  std::printf("tissue_sag on %s: %u particles, %u constraints (%u distance, %u volume), %u colours, "
              "%d substeps x %d iterations\n",
              sim->device_name().c_str(), info.particles, info.constraints(), info.distance_constraints,
              info.volume_constraints, info.colors, opt.substeps, opt.iterations);

  std::filesystem::create_directories(opt.out);
  std::vector<std::filesystem::path> files;
  std::vector<double> times;
  std::vector<float> x, v, speed;
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
    if (auto s = sim->read_velocities(v); !s) { std::fprintf(stderr, "%s\n", s.error().message().c_str()); return 1; }
    speed.resize(info.particles);
    float tip = 0.0f;  // lowest point [m]
    for (std::uint32_t p = 0; p < info.particles; ++p) {
      speed[p] = std::sqrt(v[4 * p] * v[4 * p] + v[4 * p + 1] * v[4 * p + 1] + v[4 * p + 2] * v[4 * p + 2]);
      tip = std::min(tip, x[4 * p + 1]);
    }
    const sinew::VertexField fields[] = {{"speed", 1, speed}};
    files.push_back(opt.out + "/frame_" + std::to_string(f) + ".vtu");
    times.push_back(sim->last_frame().time);
    if (auto s = sinew::write_vtu(files.back(), x, 4, tets, fields); !s) {
      std::fprintf(stderr, "%s\n", s.error().message().c_str());
      return 1;
    }
    const sinew::FrameStats& st = sim->last_frame();
    std::printf("frame %4d  t = %.3f s  %.3f ms/frame (mean %.3f)  residual rms %.2e  volume change %+.3f%%  "
                "kinetic energy %.2e J  lowest point %.1f mm\n",
                f, st.time, st.wall_ms, total_ms / f, st.residual_rms, 100.0 * st.volume_change, st.kinetic_energy,
                1e3 * tip);
  }
  if (auto s = sinew::write_pvd(opt.out + "/tissue_sag.pvd", files, times); !s) {
    std::fprintf(stderr, "%s\n", s.error().message().c_str());
    return 1;
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
