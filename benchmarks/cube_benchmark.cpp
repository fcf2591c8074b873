// cube_benchmark — the setup of the iMSTK paper's Figure 4 (Jeremy et al.,
// "iMSTK: Interactive Medical Simulation Toolkit"): a meshed cube under
// gravity, refined step by step, solved by PBD with distance + volume
// constraints at 2, 5 and 8 iterations; the time per frame is recorded
// against the constraint count. iMSTK reports ~7,000 constraints before it
// crosses 5 ms per frame.
//
// Each run reports the real time per frame and the user counters
// `constraints`, `colors` (dependent sweeps per iteration) and `particles`;
// on Vulkan with timestamps also `device_ms` (GPU time per frame) and
// `solve_device_ms` (of it, in the constraint solves).
//   bench_cube --benchmark_out=cube.csv --benchmark_out_format=csv
//   SINEW_BACKEND=cpu|opencl|vulkan|auto (default auto) picks the backend;
//   SINEW_THREADS=N sets the CPU backend's threads (default: all);
//   SINEW_CPU_SIMD=0 runs the scalar reference solves instead of AVX2;
//   SINEW_MATERIAL=neo_hookean|stvk|corotational solves FEM tets instead of
//   distance + volume constraints (default xpbd).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "benchmark_main.h"

namespace {

std::string backend_from_env() {
  const char* b = std::getenv("SINEW_BACKEND");
  return b ? b : "auto";
}

int threads_from_env() {
  const char* t = std::getenv("SINEW_THREADS");
  return t ? std::atoi(t) : 0;
}

// SINEW_MATERIAL: xpbd (distance + volume, the iMSTK setup), neo_hookean,
// stvk or corotational (one FEM tet constraint pair per tet instead).
sinew::Result<sinew::TetMaterial> material_from_env() {
  const char* m = std::getenv("SINEW_MATERIAL");
  const std::string name = m ? m : "xpbd";
  if (name == "xpbd") return sinew::TetMaterial::none;
  if (name == "neo_hookean") return sinew::TetMaterial::neo_hookean;
  if (name == "stvk") return sinew::TetMaterial::stvk;
  if (name == "corotational") return sinew::TetMaterial::corotational;
  return sinew::Error(sinew::ErrorCode::bad_parameter, "SINEW_MATERIAL must be xpbd, neo_hookean, stvk or corotational (got " + name + ")");
}

bool simd_from_env() {
  const char* s = std::getenv("SINEW_CPU_SIMD");
  return !(s && std::string(s) == "0");
}

// A 1 m cube of n^3 cells (6 tets each), hanging from its top face.
sinew::SceneDesc cube_scene(int n, int iterations, sinew::TetMaterial material) {
  sinew::TetBodyDesc body;
  const double h = 1.0 / n;
  body.mesh = *sinew::make_tet_grid({.nx = n, .ny = n, .nz = n, .origin = {0, 0, 0}, .cell_size = {h, h, h}});
  body.density = 1000.0;
  if (material == sinew::TetMaterial::none)
    (void)body.set_elastic(1e5, 0.4);
  else
    (void)body.set_material(material, 1e5, 0.4);
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] >= 1.0 - 1e-9) body.pinned.push_back(v);
  sinew::SceneDesc scene;
  // The solver alone: error measurement (a read-back per frame) is off.
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = iterations, .measure_errors = false};
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

void BM_Cube(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int iterations = static_cast<int>(state.range(1));
  const auto material = material_from_env();
  if (!material) {
    state.SkipWithError(material.error().message().c_str());
    return;
  }
  auto sim = sinew::Simulation::create(cube_scene(n, iterations, *material), {.backend = backend_from_env(), .threads = threads_from_env(), .cpu_simd = simd_from_env(), .quiet = true});
  if (!sim) {
    state.SkipWithError(sim.error().message().c_str());
    return;
  }
  for (int warm = 0; warm < 3; ++warm) (void)sim->step();
  double device_ms = 0.0, solve_ms = 0.0;
  for (auto _ : state) {
    if (auto s = sim->step(); !s) {
      state.SkipWithError(s.error().message().c_str());
      return;
    }
    const sinew::DeviceTimes& t = sim->last_frame().device;
    device_ms += t.span_ms;
    for (std::size_t k = 0; k < sinew::kernel_names().size(); ++k)
      if (sinew::kernel_names()[k].starts_with("xpbd_solve")) solve_ms += t.kernel_ms[k];
  }
  if (sim->last_frame().device.timed) {  // Vulkan with timestamps: GPU time per frame, all and in solves
    state.counters["device_ms"] = benchmark::Counter(device_ms, benchmark::Counter::kAvgIterations);
    state.counters["solve_device_ms"] = benchmark::Counter(solve_ms, benchmark::Counter::kAvgIterations);
  }
  const auto& info = sim->info();
  state.counters["constraints"] = info.constraints();
  state.counters["colors"] = info.colors;
  state.counters["particles"] = info.particles;
  state.counters["iterations"] = iterations;
  state.SetLabel(sim->device_name());
}

void CubeArgs(benchmark::internal::Benchmark* b) {
  for (int iterations : {2, 5, 8})
    for (int n : {4, 8, 12, 16, 20, 24, 26, 28, 32}) b->Args({n, iterations});
}

BENCHMARK(BM_Cube)->Apply(CubeArgs)->ArgNames({"cells", "iterations"})->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_cube",
                     "The iMSTK Figure 4 cube: a 1 m cube of n^3 cells hanging from its top face, 2, 5 or 8 iterations per\n1/60 s frame; real time per frame and the constraints, colours and particles.")
