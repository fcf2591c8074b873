// bleeding_organ — the bleeding reference scene (S4) timed frame by frame:
// blood from a cut vessel on kidney_57k, pooling, drained and taken by a
// suction tip, coupled both ways with the kidney (the scene:
// examples/common/bleeding_organ_scene.h). The goal: the fluid and the
// tissue keep up with the clock, <= 16.7 ms of wall time per 16.7 ms frame
// with up to 5,000 fluid particles, and a neighbour grid of <= 100 ns per
// particle.
//
//   build/benchmarks/bleeding_organ --help   (the options, their defaults and units)
//
// Prints CSV, three blocks separated by a blank line:
//   1. one summary line: frames, simulated seconds, the fluid's particles (peak,
//      and at the last frame), frame wall time (median, p95, worst) over all
//      frames and over the frames at >= 80% of the peak count, the real-time
//      ratio (median wall / 16.7 ms), the fluid and tissue medians, the
//      neighbour grid's ns per point and per fluid particle, and the mass
//      books (emitted, alive, removed, emitted - alive - removed);
//   2. the per-stage profile (FrameStats::stages): median, p95 and worst ms;
//   3. with --trace: one line per frame.
// The neighbour grid is timed after the run on what a fluid step sorts: the
// fluid particles and the boundary particles of the coupled surface at the
// tissue's last positions, on a device of the same backend (the grid's part
// of the step's program, NeighbourGrid::run_grid, median of 20 runs).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "bleeding_organ_scene.h"
#include "command_line.h"
#include "neighbours/neighbour_grid.h"
#include "sinew/fluid.h"
#include "sinew/simulation.h"

namespace {

using sinew::examples::BleedingOrganScene;

int fail(const std::string& what) {
  std::fprintf(stderr, "bleeding_organ: %s\n", what.c_str());
  return 1;
}

// The q-quantile of v (nearest rank).
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::ceil(q * double(v.size()))) - (q > 0.0 ? 1 : 0);
  return v[std::min(k, v.size() - 1)];
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "bleeding_organ",
      "The bleeding reference scene timed frame by frame: a cut vessel bleeds onto kidney_57k (corotational,\n"
      "20 kPa, pinned where it rests), the blood pools and runs off into a drain, and a suction tip takes it\n"
      "(SPH coupled both ways with the tissue, 60 Hz frames). Prints CSV: the frame time (median, p95,\n"
      "worst), the per-stage profile, the neighbour grid's ns per particle and the mass books.");
  std::string backend = "cpu";
  int frames = 180;
  bool trace = false;
  sinew::examples::BleedingOrganOptions options;
  options.mesh_path = std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node";
  cli.add_backend(backend);
  cli.app().add_option("--frames", frames, "Frames of 1/60 s")->check(sinew::examples::at_least(1));
  sinew::examples::add_bleeding_organ_options(cli, options);
  cli.app().add_flag("--trace", trace, "Print one CSV line per frame too");
  if (auto exit = cli.parse(argc, argv)) return *exit;

  auto made = sinew::examples::make_bleeding_organ_scene(options);
  if (!made) return fail(made.error().message());
  const BleedingOrganScene& s = *made;
  auto sim = sinew::Simulation::create(s.scene, {.backend = backend, .quiet = true});
  if (!sim) return fail(sim.error().message());
  sinew::SceneFluid fluid = sim->fluid();
  const auto info = fluid.info();
  if (!info) return fail(info.error().message());
  std::fprintf(stderr, "bleeding_organ: %s; kidney %zu tets, %u of %u surface triangles coupled (%u boundary particles); "
               "%u fluid steps per frame; capacity %u\n",
               sim->device_name().c_str(), s.mesh.tets.size(), s.coupled_triangles, s.surface_triangles,
               info->coupled_boundary, info->steps_per_frame, info->capacity);

  std::vector<double> wall, fluid_ms, tissue_ms;
  std::vector<std::uint32_t> counts;
  std::map<std::string, std::vector<double>> stages;
  std::vector<std::string> stage_order;
  if (trace) std::printf("frame,t_s,particles,wall_ms,fluid_ms,tissue_ms\n");
  for (int frame = 1; frame <= frames; ++frame) {
    const double t = frame * BleedingOrganScene::kFrame;
    if (auto st = s.script(fluid, t); !st) return fail(st.error().message());
    const auto a = std::chrono::steady_clock::now();
    if (auto st = sim->step(); !st) return fail("frame " + std::to_string(frame) + ": " + st.error().message());
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count();
    const sinew::FrameStats& fs = sim->last_frame();
    wall.push_back(ms);
    fluid_ms.push_back(fs.stage_ms("fluid"));
    tissue_ms.push_back(ms - fs.stage_ms("fluid"));
    counts.push_back(static_cast<std::uint32_t>(fs.counter("fluid", "particles")));
    for (const sinew::StageProfile& p : fs.stages) {
      if (!stages.count(p.name)) stage_order.push_back(p.name);
      stages[p.name].push_back(p.ms);
    }
    if (trace)
      std::printf("%d,%.4f,%u,%.3f,%.3f,%.3f\n", frame, t, counts.back(), ms, fluid_ms.back(), tissue_ms.back());
  }
  const auto stats = fluid.stats();
  if (!stats) return fail(stats.error().message());

  // The neighbour grid on what a step sorts now: fluid + coupled boundary.
  std::vector<sinew::FluidParticle> q;
  std::vector<float> x;
  if (auto st = fluid.read(q); !st) return fail(st.error().message());
  if (auto st = sim->read_positions(x); !st) return fail(st.error().message());
  const std::uint32_t first = sim->info().tet_body_first_particle[0];
  std::vector<std::array<double, 3>> vertices(s.mesh.vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v)
    for (int k = 0; k < 3; ++k) vertices[v][k] = x[4 * (first + v) + std::size_t(k)];
  const auto& tris = s.scene.fluid->surfaces[0].triangles;
  auto samples = sinew::sample_surface(vertices, tris, BleedingOrganScene::kSpacing);
  if (!samples) return fail(samples.error().message());
  std::vector<float> points;
  for (const auto& p : q) points.insert(points.end(), {p.position[0], p.position[1], p.position[2], 1.0f});
  for (const auto& p : samples->points) points.insert(points.end(), {float(p[0]), float(p[1]), float(p[2]), -1.0f});
  const auto n = static_cast<std::uint32_t>(points.size() / 4);
  double grid_ns = 0.0;
  {
    auto device = sinew::create_device({.backend = backend, .quiet = true});
    if (!device) return fail(device.error().message());
    auto grid = sinew::NeighbourGrid::create(**device, std::max(n, 1u), 2.0 * BleedingOrganScene::kSpacing, 1);
    if (!grid) return fail(grid.error().message());
    if (auto st = (*grid)->upload(points.data(), n); !st) return fail(st.error().message());
    std::vector<double> runs;
    for (int r = 0; r < 21; ++r) {
      const auto a = std::chrono::steady_clock::now();
      if (auto st = (*grid)->run_grid(); !st) return fail(st.error().message());
      if (auto st = (*device)->wait(); !st) return fail(st.error().message());
      if (r > 0) runs.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - a).count());
    }
    grid_ns = quantile(runs, 0.5);
  }

  // Frames at >= 80% of the peak count: the cost with the most blood.
  const std::uint32_t peak = counts.empty() ? 0u : *std::max_element(counts.begin(), counts.end());
  std::vector<double> at_peak;
  for (std::size_t f = 0; f < wall.size(); ++f)
    if (counts[f] >= 0.8 * peak) at_peak.push_back(wall[f]);
  const long long books = (long long)stats->emitted - (long long)stats->particles - (long long)stats->removed;
  if (trace) std::printf("\n");
  std::printf("backend,frames,sim_s,steps_per_frame,boundary,peak_particles,last_particles,median_ms,p95_ms,worst_ms,"
              "peak_median_ms,peak_p95_ms,realtime_ratio,fluid_median_ms,tissue_median_ms,grid_points,grid_ns_per_point,"
              "grid_ns_per_fluid,emitted,alive,removed,books\n");
  std::printf("%s,%d,%.4f,%u,%u,%u,%u,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%u,%.1f,%.1f,%llu,%u,%llu,%lld\n",
              backend.c_str(), frames, frames * BleedingOrganScene::kFrame, info->steps_per_frame,
              info->coupled_boundary, peak, counts.empty() ? 0u : counts.back(), quantile(wall, 0.5),
              quantile(wall, 0.95), quantile(wall, 1.0), quantile(at_peak, 0.5), quantile(at_peak, 0.95),
              quantile(wall, 0.5) / (1e3 * BleedingOrganScene::kFrame), quantile(fluid_ms, 0.5),
              quantile(tissue_ms, 0.5), n, grid_ns / std::max(n, 1u), q.empty() ? 0.0 : grid_ns / double(q.size()),
              static_cast<unsigned long long>(stats->emitted), stats->particles,
              static_cast<unsigned long long>(stats->removed), books);
  std::printf("\nstage,median_ms,p95_ms,worst_ms\n");
  for (const std::string& name : stage_order)
    std::printf("%s,%.3f,%.3f,%.3f\n", name.c_str(), quantile(stages[name], 0.5), quantile(stages[name], 0.95),
                quantile(stages[name], 1.0));
  return books == 0 ? 0 : 1;
}
