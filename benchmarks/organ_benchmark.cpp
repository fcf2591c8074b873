// organ_benchmark — a frame on the real organ meshes against the benchmark
// cube of about the same size, in one run, so the cost per constraint of a
// mesher's mesh and of a structured grid can be compared (issue 11: "real
// organ meshes within 1.5x of the cube's per-constraint cost").
//
// Meshes (first argument): cube20 (20^3 cells, 48,000 tets, ~108k distance
// + volume constraints), kidney_57k (57,071 tets, 138k), cube40 (384,000
// tets, ~866k) and liver_382k (382,510 tets, 906k), the organs in the
// mesher's vertex order (scaled from mm to m). Each is solved with distance
// + volume constraints (E = 30 kPa, nu = 0.45) or one of the FEM materials,
// with the particles reordered on the device or not, at 10 substeps x 1
// iteration per 60 Hz frame, pinned at its lowest 5 mm in x, errors not
// measured. Counters: constraints, colors, particles, and
// projections_per_s (constraint projections per second of wall time).
//   bench_organs --benchmark_out=organs.csv --benchmark_out_format=csv
//   SINEW_BACKEND=cpu|opencl|vulkan|auto (default auto); SINEW_THREADS=N.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <string>

#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "benchmark_main.h"

namespace {

constexpr const char* kMeshes[] = {"cube20", "kidney_57k", "cube40", "liver_382k"};
constexpr const char* kMaterials[] = {"xpbd", "neo_hookean", "stvk", "corotational"};

std::string env_or(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v ? v : fallback;
}

// Meshes are read once per process.
const sinew::Result<sinew::TetMesh>& mesh(int index) {
  static std::map<int, sinew::Result<sinew::TetMesh>> cache;
  if (auto it = cache.find(index); it != cache.end()) return it->second;
  const std::string name = kMeshes[index];
  sinew::Result<sinew::TetMesh> m = sinew::Error(sinew::ErrorCode::internal, "unset");
  if (name.starts_with("cube")) {
    const int n = std::atoi(name.c_str() + 4);
    const double cell = 0.1 / n;  // 10 cm wide, like an organ
    m = sinew::make_tet_grid({.nx = n, .ny = n, .nz = n, .origin = {0, 0, 0}, .cell_size = {cell, cell, cell}});
  } else {
    m = sinew::read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/" + name + ".node");
    if (m) sinew::scale_mesh(*m, 1e-3);
  }
  return cache.emplace(index, std::move(m)).first->second;
}

void BM_Organ(benchmark::State& state) {
  const auto& m = mesh(static_cast<int>(state.range(0)));
  if (!m) {
    state.SkipWithError(m.error().message().c_str());
    return;
  }
  const int material = static_cast<int>(state.range(1));
  sinew::TetBodyDesc body;
  body.mesh = *m;
  body.density = 1060.0;
  const sinew::TetMaterial models[] = {sinew::TetMaterial::none, sinew::TetMaterial::neo_hookean,
                                       sinew::TetMaterial::stvk, sinew::TetMaterial::corotational};
  const sinew::Status made = material == 0 ? body.set_elastic(3e4, 0.45)
                                           : body.set_material(models[material], 3e4, 0.45);
  if (!made) {
    state.SkipWithError(made.error().message().c_str());
    return;
  }
  double lo = 1e30;
  for (const auto& v : body.mesh.vertices) lo = std::min(lo, v[0]);
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] < lo + 0.005) body.pinned.push_back(v);
  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 10, .iterations = 1, .measure_errors = false};
  scene.solver.reorder_particles = state.range(2) != 0;
  scene.tet_bodies.push_back(std::move(body));
  auto sim = sinew::Simulation::create(
      scene, {.backend = env_or("SINEW_BACKEND", "auto"), .threads = std::atoi(env_or("SINEW_THREADS", "0").c_str()),
              .quiet = true});
  if (!sim) {
    state.SkipWithError(sim.error().message().c_str());
    return;
  }
  for (int warm = 0; warm < 2; ++warm) (void)sim->step();
  for (auto _ : state)
    if (auto s = sim->step(); !s) {
      state.SkipWithError(s.error().message().c_str());
      return;
    }
  const auto& info = sim->info();
  state.counters["constraints"] = info.constraints();
  state.counters["colors"] = info.colors;
  state.counters["particles"] = info.particles;
  state.counters["projections_per_s"] =
      benchmark::Counter(double(info.constraints()) * scene.solver.substeps * scene.solver.iterations,
                         benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::string(kMeshes[state.range(0)]) + " " + kMaterials[material] + " " + sim->device_name());
}

void OrganArgs(benchmark::internal::Benchmark* b) {
  for (int reorder : {1, 0})
    for (int material = 0; material < 4; ++material)
      for (int m = 0; m < 4; ++m) b->Args({m, material, reorder});
}

BENCHMARK(BM_Organ)
    ->Apply(OrganArgs)
    ->ArgNames({"mesh", "material", "reorder"})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_organs",
                     "Real organ meshes (kidney_57k, liver_382k) against cubes of their size, 10 substeps x 1 iteration per\n60 Hz frame: ms per frame and constraint projections per second, reordered or in the mesher's order.")
