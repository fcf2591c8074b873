// ccd_benchmark — continuous collision detection on the CCD benchmark's
// hand-crafted queries (Wang et al., "A Large Scale Benchmark and an
// Inclusion-Based Algorithm for Continuous Collision Detection", TOG 2021;
// data/ccd/handcrafted, 7,279 queries with exact answers): every query of
// one kind (range(0): 0 vertex-face, 1 edge-edge) per iteration, on one
// thread, with the tolerance range(1) (a power of ten: -6 is 1e-6 m, the
// default). Reports the time per query, the queries per second, the false
// negatives (must be 0; tests/ccd_test.cpp asserts it) and false positives
// (as a count and a fraction of the negatives), and the queries that gave up.
// BM_DeviceHandcraftedQueries: the same through the single-precision kernel
// on each backend (src/ccd/device_ccd.h).
//   bench_ccd --benchmark_out=ccd.csv --benchmark_out_format=csv
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "ccd/benchmark_queries.h"
#include "ccd/device_ccd.h"
#include "benchmark_main.h"

namespace {

using namespace sinew::ccd;

const std::vector<BenchmarkQuery>& queries() {
  static const std::vector<BenchmarkQuery> all = [] {
    auto read = read_benchmark_queries(std::string(SINEW_DATA_DIR) + "/ccd/handcrafted");
    return read ? *read : std::vector<BenchmarkQuery>{};
  }();
  return all;
}

// The counters every row reports (the CSV reporter wants the same columns).
void report(benchmark::State& state, std::size_t queries, std::size_t false_negatives, std::size_t false_positives,
            std::size_t negatives, std::size_t gave_up, std::size_t boxes) {
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(queries));
  state.counters["queries"] = double(queries);
  state.counters["false_negatives"] = double(false_negatives);
  state.counters["false_positives"] = double(false_positives);
  state.counters["fp_fraction"] = double(false_positives) / double(negatives);
  state.counters["gave_up"] = double(gave_up);
  state.counters["boxes_per_query"] = double(boxes) / double(queries);
}

void BM_HandcraftedQueries(benchmark::State& state) {
  const bool vertex_face = state.range(0) == 0;
  std::vector<BenchmarkQuery> mine;
  for (const BenchmarkQuery& q : queries())
    if (q.vertex_face == vertex_face) mine.push_back(q);
  if (mine.empty()) {
    state.SkipWithError("no queries: data/ccd/handcrafted not found");
    return;
  }
  Settings settings;
  settings.tolerance = std::pow(10.0, double(state.range(1)));
  std::size_t false_negatives = 0, false_positives = 0, negatives = 0, gave_up = 0, boxes = 0;
  for (auto _ : state) {
    false_negatives = false_positives = negatives = gave_up = boxes = 0;
    for (const BenchmarkQuery& q : mine) {
      const auto hit = run_query(q, settings);
      if (!hit) {
        state.SkipWithError(hit.error().message().c_str());
        return;
      }
      false_negatives += q.truth && !hit->touch;
      negatives += !q.truth;
      false_positives += !q.truth && hit->touch;
      gave_up += hit->gave_up;
      boxes += hit->boxes;
    }
  }
  report(state, mine.size(), false_negatives, false_positives, negatives, gave_up, boxes);
  state.SetLabel(std::string(vertex_face ? "vertex-face" : "edge-edge") + ", tolerance 1e" +
                 std::to_string(state.range(1)) + " m");
}

// The same queries through the single-precision kernel on a device
// (src/ccd/device_ccd.h): range(0) the kind as above, range(1) the backend
// (0 cpu, 1 opencl, 2 vulkan), all queries of
// the kind in one dispatch per iteration, uploads and read-back included.
void BM_DeviceHandcraftedQueries(benchmark::State& state) {
  const bool vertex_face = state.range(0) == 0;
  static const char* backends[] = {"cpu", "opencl", "vulkan"};
  auto made = sinew::create_device({.backend = backends[state.range(1)], .quiet = true});
  if (!made) {
    state.SkipWithError(made.error().message().c_str());
    return;
  }
  std::vector<DeviceQuery> mine;
  std::vector<bool> truth;
  for (const BenchmarkQuery& q : queries())
    if (q.vertex_face == vertex_face) mine.push_back({q.vertex_face, q.points}), truth.push_back(q.truth);
  if (mine.empty()) {
    state.SkipWithError("no queries: data/ccd/handcrafted not found");
    return;
  }
  std::size_t false_negatives = 0, false_positives = 0, negatives = 0, gave_up = 0, boxes = 0;
  for (auto _ : state) {
    const auto hits = device_queries(**made, mine);
    if (!hits) {
      state.SkipWithError(hits.error().message().c_str());
      return;
    }
    false_negatives = false_positives = negatives = gave_up = boxes = 0;
    for (std::size_t k = 0; k < mine.size(); ++k) {
      const Hit& hit = (*hits)[k];
      false_negatives += truth[k] && !hit.touch;
      negatives += !truth[k];
      false_positives += !truth[k] && hit.touch;
      gave_up += hit.gave_up;
      boxes += hit.boxes;
    }
  }
  report(state, mine.size(), false_negatives, false_positives, negatives, gave_up, boxes);
  state.SetLabel(std::string(vertex_face ? "vertex-face" : "edge-edge") + ", float kernel on " + backends[state.range(1)]);
}

BENCHMARK(BM_DeviceHandcraftedQueries)
    ->ArgsProduct({{0, 1}, {0, 1, 2}})
    ->ArgNames({"edge_edge", "backend"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

BENCHMARK(BM_HandcraftedQueries)
    ->ArgsProduct({{0, 1}, {-6, -4, -8}})
    ->ArgNames({"edge_edge", "tolerance_log10"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
SINEW_BENCHMARK_MAIN("bench_ccd",
                     "Continuous collision queries against ground truth: every query of the CCD benchmark's hand-crafted set\n(data/ccd/handcrafted) per kind and tolerance; false negatives (must be 0) and false positives.")
