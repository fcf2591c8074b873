// neighbour_benchmark — the fixed-radius neighbour search (issue 15, part
// 1) in ns per point at 10^4, 10^5 and 10^6 points, on the backend named
// by SINEW_BACKEND, with the points already on the device (as a fluid's
// particles are):
//   BM_NeighbourGrid   the grid alone: cells, the sort, bucket ranges, the
//                      points copied into sorted order (what an SPH step
//                      builds before it visits the cells itself);
//   BM_NeighbourLists  the grid and every point's neighbour list (count,
//                      scan, fill), as sinew/neighbours.h returns them.
// The points: a fluid at rest, a cubic lattice of spacing s jittered by up
// to s/4, in the mesher's order (row by row); radius 2 s (about 33
// neighbours each, a cubic-spline SPH kernel's support); order:1 shuffles
// them first (a fluid that has mixed). Goal (issue 15): <= 100 ns per
// point on 2 cores; CompactNSearch took 480-760 ns here.
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_neighbours --benchmark_format=csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "bench_support.h"
#include "neighbours/neighbour_grid.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

constexpr double kSpacing = 1e-3;  // [m]

std::vector<float> fluid(std::uint32_t n, bool shuffled) {
  const int side = static_cast<int>(std::ceil(std::cbrt(double(n))));
  std::mt19937 rng(15);
  std::uniform_real_distribution<float> jitter(-0.25f * float(kSpacing), 0.25f * float(kSpacing));
  std::vector<float> xyzw;
  xyzw.reserve(4 * std::size_t{n});
  for (int i = 0; i < side && xyzw.size() < 4 * std::size_t{n}; ++i)
    for (int j = 0; j < side && xyzw.size() < 4 * std::size_t{n}; ++j)
      for (int k = 0; k < side && xyzw.size() < 4 * std::size_t{n}; ++k)
        xyzw.insert(xyzw.end(), {float(k * kSpacing) + jitter(rng), float(j * kSpacing) + jitter(rng),
                                 float(i * kSpacing) + jitter(rng), 0.0f});
  if (shuffled) {
    std::vector<std::uint32_t> perm(n);
    for (std::uint32_t i = 0; i < n; ++i) perm[i] = i;
    std::shuffle(perm.begin(), perm.end(), rng);
    std::vector<float> out(xyzw.size());
    for (std::uint32_t i = 0; i < n; ++i) std::copy_n(&xyzw[4 * std::size_t{perm[i]}], 4, &out[4 * std::size_t{i}]);
    xyzw.swap(out);
  }
  return xyzw;
}

void run(benchmark::State& state, bool lists) {
  const auto n = static_cast<std::uint32_t>(state.range(0));
  auto device = create_device({.backend = bench::backend(), .quiet = true});
  if (!device) {
    state.SkipWithError(device.error().message().c_str());
    return;
  }
  auto grid = NeighbourGrid::create(**device, n, 2.0 * kSpacing, 48 * n);
  if (!grid) {
    state.SkipWithError(grid.error().message().c_str());
    return;
  }
  const std::vector<float> points = fluid(n, state.range(1) != 0);
  if (!(*grid)->upload(points.data(), n)) {
    state.SkipWithError("upload");
    return;
  }
  std::vector<double> ns;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const Status s = lists ? (*grid)->run() : (*grid)->run_grid();
    const auto t1 = std::chrono::steady_clock::now();
    if (!s) {
      state.SkipWithError(s.error().message().c_str());
      return;
    }
    ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / double(n));
  }
  // The lists' size for both rows (the grid's from one untimed search).
  if (!lists && !(*grid)->run()) {
    state.SkipWithError("lists");
    return;
  }
  state.counters["ns_per_point"] = bench::median(ns);
  state.counters["neighbours_per_point"] = double((*grid)->pairs()) / double(n);
  state.SetLabel((*device)->device_name());
}

void BM_NeighbourGrid(benchmark::State& state) { run(state, false); }
void BM_NeighbourLists(benchmark::State& state) { run(state, true); }

void sizes(benchmark::internal::Benchmark* b) {
  b->ArgNames({"points", "shuffled"});
  for (int shuffled : {0, 1})
    for (int n : {10000, 100000, 1000000}) b->Args({n, shuffled});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

}  // namespace

BENCHMARK(BM_NeighbourGrid)->Apply(sizes);
BENCHMARK(BM_NeighbourLists)->Apply(sizes);
SINEW_BENCHMARK_MAIN("bench_neighbours",
                     "The fixed-radius neighbour search in ns per point at 10^4, 10^5 and 10^6 points already on the device:\nthe grid alone, and the grid with every point's neighbour list.")
