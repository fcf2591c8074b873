// topology_benchmark.cpp — what a cut costs (issue 16, part 5): a block of
// 50,400 tets (20 x 21 x 20 cells of 5 mm, 6 tets each, distance + volume
// constraints or corotational FEM, pinned at its base, 10 substeps x 2
// iterations at 60 Hz) takes 10 blade strokes into its top face, each
// removing up to about 50 tets (a blade reaching 2 cm below the top face's
// rest height, 1 cm wide, swept 5 mm).
// Goal: a cut adds <= 2 ms to its frame on 2 cores, and the frames after
// it run as fast as before.
//
// Per run (one iteration), medians [ms]:
//   frame_before_ms  a frame before any cut (20 frames);
//   cut_ms           Simulation::cut_body: reading the positions back, the
//                    blade against the tets, the removal (constraints,
//                    masses, uploads) and the program rebuilt;
//   rebuild_ms       of which rebuilding the frame program;
//   frame_after_ms   a frame after the 10 cuts (20 frames);
//   tets_per_cut     the largest cut (its tets).
// fem:1 uses corotational FEM; collision:1 turns mesh collision on, which
// each change makes again from the live tets.
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_topology --benchmark_repetitions=3
//       --benchmark_format=csv > benchmarks/results/topology_<date>.csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "bench_support.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace {

using namespace sinew;

constexpr double kCell = 5e-3;  // [m]
constexpr int kNx = 20, kNy = 21, kNz = 20;

SceneDesc block(bool fem, bool collision) {
  SceneDesc scene;
  TetBodyDesc body;
  body.mesh = *make_tet_grid({.nx = kNx, .ny = kNy, .nz = kNz, .cell_size = {kCell, kCell, kCell}});
  body.density = 1000.0;
  if (fem) {
    (void)body.set_material(TetMaterial::corotational, 3e4, 0.3);
  } else {
    (void)body.set_elastic(3e4, 0.3);
  }
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] < 1e-9) body.pinned.push_back(v);
  scene.tet_bodies.push_back(body);
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  scene.solver.measure_errors = false;
  scene.topology_changes = true;
  // collision:1 turns mesh collision on (self-collision of the block's
  // surface), which a change makes again from the live tets.
  scene.mesh_collision.enabled = collision;
  scene.mesh_collision.thickness = 5e-4;
  return scene;
}

double frames_ms(Simulation& sim, int frames, benchmark::State& state) {
  std::vector<double> ms;
  for (int f = 0; f < frames; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!sim.step()) state.SkipWithError("step");
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return bench::median(ms);
}

void BM_Cut(benchmark::State& state) {
  const bool fem = state.range(0) == 1, collision = state.range(1) == 1;
  std::vector<double> before, cut, rebuild, after;
  double most = 0;
  for (auto _ : state) {
    auto sim = Simulation::create(block(fem, collision), {.backend = bench::backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    state.SetLabel(sim->device_name());
    frames_ms(*sim, 5, state);  // warm up
    before.push_back(frames_ms(*sim, 20, state));
    const double top = kNy * kCell;
    for (int c = 0; c < 10; ++c) {
      // A blade from 1 cm above the top face (rest) to 2 cm below it (the
      // face sags under gravity), 1 cm wide along z, swept 5 mm along x;
      // each stroke 9.5 mm further along z.
      const double x = 0.0251, z = 0.0051 + 0.0095 * c;
      const Simulation::Blade from{{x, top + 1e-2, z}, {x, top - 2e-2, z + 1e-2}};
      const Simulation::Blade to{{x + 5e-3, top + 1e-2, z}, {x + 5e-3, top - 2e-2, z + 1e-2}};
      auto e = sim->cut_body(0, from, to);
      if (!e) {
        state.SkipWithError(e.error().message().c_str());
        return;
      }
      cut.push_back(e->wall_ms);
      rebuild.push_back(e->rebuild_ms);
      most = std::max(most, double(e->tets_removed.size()));
      frames_ms(*sim, 1, state);
    }
    after.push_back(frames_ms(*sim, 20, state));
  }
  state.counters["frame_before_ms"] = bench::median(before);
  state.counters["cut_ms"] = bench::median(cut);
  state.counters["cut_max_ms"] = *std::max_element(cut.begin(), cut.end());
  state.counters["rebuild_ms"] = bench::median(rebuild);
  state.counters["frame_after_ms"] = bench::median(after);
  state.counters["tets_per_cut"] = most;
}

}  // namespace

BENCHMARK(BM_Cut)
    ->ArgNames({"fem", "collision"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
