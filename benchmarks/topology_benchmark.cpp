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
//   frame_next_ms    the frame right after a cut (what the change left to
//                    it: with mesh collision, the changed body's trees);
//   frame_after_ms   a frame after the 10 cuts (20 frames);
//   tets_per_cut     the largest cut (its tets).
// fem:1 uses corotational FEM; collision:1 turns mesh collision on, which
// each change updates from the tets removed; organ:1 cuts the kidney
// (data/meshes/tet/kidney_57k, 57,071 tets in the mesher's order) instead
// of the block.
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_topology --benchmark_repetitions=3
//       --benchmark_format=csv > benchmarks/results/topology_<date>.csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <string>
#include <vector>

#include "bench_support.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

constexpr double kCell = 5e-3;  // [m]
constexpr int kNx = 20, kNy = 21, kNz = 20;
constexpr double kOrganDepth = 5e-3, kOrganWidth = 4e-3;  // the kidney's strokes [m]

// The body: the block, or (organ) the kidney as users load it, the
// mesher's order, mm scaled to m. [out] top: the highest rest vertex, where
// the strokes go.
Result<SceneDesc> scene_of(bool fem, bool collision, bool organ, std::array<double, 3>& top) {
  SceneDesc scene;
  TetBodyDesc body;
  if (organ) {
    auto kidney = read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node");
    if (!kidney) return kidney.error();
    scale_mesh(*kidney, 1e-3);
    // Laid on its back as in blood_on_organ (standing, it bends over): the
    // file's thinnest axis up, (x, y, z) -> (x, z, -y), every tet's
    // orientation kept.
    for (auto& v : kidney->vertices) v = {v[0], v[2], -v[1]};
    body.mesh = *kidney;
  } else {
    body.mesh = *make_tet_grid({.nx = kNx, .ny = kNy, .nz = kNz, .cell_size = {kCell, kCell, kCell}});
  }
  double lo = 1e30;
  top = {0.0, -1e30, 0.0};
  for (const auto& v : body.mesh.vertices) {
    lo = std::min(lo, v[1]);
    if (v[1] > top[1]) top = v;
  }
  body.density = 1000.0;
  if (organ) body.velocity_damping = 2.0;  // the pinned kidney settles instead of swinging
  if (fem) {
    (void)body.set_material(TetMaterial::corotational, 3e4, 0.3);
  } else {
    (void)body.set_elastic(3e4, 0.3);
  }
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)  // its lowest 15% (the block: its base)
    if (body.mesh.vertices[v][1] < lo + (organ ? 0.15 * (top[1] - lo) : 1e-9)) body.pinned.push_back(v);
  scene.tet_bodies.push_back(body);
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 2;
  scene.solver.measure_errors = false;
  scene.topology_changes = true;
  // collision:1 turns mesh collision on (self-collision of the block's
  // surface), which a change updates (MeshCollision::update_topology).
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
  const bool fem = state.range(0) == 1, collision = state.range(1) == 1, organ = state.range(2) == 1;
  std::vector<double> before, cut, rebuild, next, after;
  double most = 0;
  for (auto _ : state) {
    std::array<double, 3> top{};
    auto scene = scene_of(fem, collision, organ, top);
    if (!scene) {
      state.SkipWithError(scene.error().message().c_str());
      return;
    }
    auto sim = Simulation::create(*scene, {.backend = bench::backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    state.SetLabel(sim->device_name());
    frames_ms(*sim, 5, state);  // warm up
    before.push_back(frames_ms(*sim, 20, state));
    for (int c = 0; c < 10; ++c) {
      // The block: a blade from 1 cm above the top face (rest) to 2 cm
      // below it (the face sags under gravity), 1 cm wide along z, swept
      // 5 mm along x; each stroke 9.5 mm further along z. The kidney: from
      // 1 cm above its highest point to kOrganDepth below, kOrganWidth wide, strokes
      // from 2 cm before it along z.
      const double x = organ ? top[0] - 2.5e-3 : 0.0251;
      const double z = organ ? top[2] - 0.02 + 0.004 * c : 0.0051 + 0.0095 * c;
      const double bottom = organ ? top[1] - kOrganDepth : kNy * kCell - 2e-2, width = organ ? kOrganWidth : 1e-2;
      const double above = (organ ? top[1] : kNy * kCell) + 1e-2;
      const Blade from{{x, above, z}, {x, bottom, z + width}};
      const Blade to{{x + 5e-3, above, z}, {x + 5e-3, bottom, z + width}};
      auto e = sim->topology().cut(*sim->topology().tet_body(0), from, to);
      if (!e) {
        state.SkipWithError(e.error().message().c_str());
        return;
      }
      cut.push_back(e->wall_ms);
      rebuild.push_back(e->rebuild_ms);
      most = std::max(most, double(e->tets_removed.size()));
      next.push_back(frames_ms(*sim, 1, state));
    }
    after.push_back(frames_ms(*sim, 20, state));
  }
  state.counters["frame_before_ms"] = bench::median(before);
  state.counters["cut_ms"] = bench::median(cut);
  state.counters["cut_max_ms"] = *std::max_element(cut.begin(), cut.end());
  state.counters["rebuild_ms"] = bench::median(rebuild);
  state.counters["frame_next_ms"] = bench::median(next);
  state.counters["frame_after_ms"] = bench::median(after);
  state.counters["tets_per_cut"] = most;
}

}  // namespace

BENCHMARK(BM_Cut)
    ->ArgNames({"fem", "collision", "organ"})
    ->Args({0, 0, 0})
    ->Args({1, 0, 0})
    ->Args({0, 1, 0})
    ->Args({1, 0, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
SINEW_BENCHMARK_MAIN("bench_topology",
                     "Topology changes: what a cut, a cautery and the rebuild after them cost in a 50,400-tet block (and\non the kidney).")
