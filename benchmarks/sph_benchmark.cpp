// sph_benchmark — a weakly compressible SPH step (issue 15, part 2;
// src/fluid/sph_solver.h) in ns per particle at 10^4, 10^5 and 10^6 fluid
// particles, on the backend named by SINEW_BACKEND: a cube of fluid
// resting in a tank of one boundary layer, spacing 1 mm, h = 2 mm; one step
// is one program (the neighbour grid, density, the velocities gathered,
// forces and motion). Counted per fluid and boundary particle alike.
// Goal (issue 15): <= 200 ns per particle on 2 cores; a scratch sort-grid
// WCSPH took 268 ns here.
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_sph --benchmark_format=csv
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <vector>

#include "backends/backend.h"
#include "bench_support.h"
#include "fluid/sph_solver.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;
using P3 = std::array<double, 3>;

void BM_SphStep(benchmark::State& state) {
  const int side = static_cast<int>(std::lround(std::cbrt(double(state.range(0)))));
  const double s = 1e-3;
  std::vector<P3> fluid, boundary;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 0; k < side; ++k) fluid.push_back({(i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s});
  for (int i = -1; i <= side; ++i)
    for (int k = -1; k <= side; ++k) boundary.push_back({(i + 0.5) * s, -0.5 * s, (k + 0.5) * s});
  for (int j = 0; j < side + 2; ++j)
    for (int a = -1; a <= side; ++a) {
      boundary.push_back({-0.5 * s, (j + 0.5) * s, (a + 0.5) * s});
      boundary.push_back({(side + 0.5) * s, (j + 0.5) * s, (a + 0.5) * s});
      if (a >= 0 && a < side) {
        boundary.push_back({(a + 0.5) * s, (j + 0.5) * s, -0.5 * s});
        boundary.push_back({(a + 0.5) * s, (j + 0.5) * s, (side + 0.5) * s});
      }
    }
  auto device = create_device({.backend = bench::backend(), .quiet = true});
  if (!device) {
    state.SkipWithError(device.error().message().c_str());
    return;
  }
  auto solver = SphSolver::create(**device, {.spacing = s}, fluid, boundary);
  if (!solver) {
    state.SkipWithError(solver.error().message().c_str());
    return;
  }
  const double particles = double(fluid.size() + boundary.size());
  std::vector<double> ns;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!(*solver)->step(1)) {
      state.SkipWithError("step");
      return;
    }
    ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / particles);
  }
  state.counters["ns_per_particle"] = bench::median(ns);
  state.counters["particles"] = particles;
  state.SetLabel((*device)->device_name());
}

}  // namespace

BENCHMARK(BM_SphStep)->ArgName("fluid")->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();

SINEW_BENCHMARK_MAIN("bench_sph",
                     "A weakly compressible SPH step in ns per particle at 10^4, 10^5 and 10^6 fluid particles (a cube of\nfluid resting in a tank).")
