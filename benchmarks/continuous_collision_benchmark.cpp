// continuous_collision_benchmark.cpp — what continuous collision detection
// (MeshCollisionDesc::continuous, issue 13 part 3) costs per frame, split by
// stage, on the tests' three scenes (tests/thread_scenes.h), driven at
// 1 m/s for 30 frames (half a second):
//   rings     two linked thread rings pulled apart and held tight;
//   membrane  a thread pulled up into a pinned membrane and held;
//   probe     a thin capsule collider pushed up into the membrane.
// Per run (one whole scene = one iteration), medians over its frames [ms]:
// wall time per frame, the frame's contact detection (collision_ms), the
// CCD tests (ccd_ms: read-backs, broad phase, queries, the fail-safe) and
// the rest (the sweeps, repair sweeps included, and the statistics); and
// per frame on average: touches found, repair rounds, particles stopped or
// carried. ccd:0 runs the same scene without CCD (which lets the threads and
// the probe through: the tests' controls).
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_continuous_collision --benchmark_repetitions=3
//       --benchmark_format=csv > benchmarks/results/continuous_collision_<date>.csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_support.h"
#include "sinew/simulation.h"
#include "thread_scenes.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

using bench::backend;
using bench::median;

void BM_ContinuousCollision(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const bool continuous = state.range(1) == 1;
  const SceneDesc scene = which == 0   ? test::LinkedRings::scene(continuous)
                          : which == 1 ? test::ThreadUnderMembrane::scene(continuous)
                                       : test::ProbeUnderMembrane::scene(continuous);
  constexpr int frames = 30;
  std::vector<double> wall, collision, ccd, rest;
  double hits = 0.0, repairs = 0.0, acted = 0.0;
  for (auto _ : state) {
    auto sim = Simulation::create(scene, {.backend = backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    wall.clear(), collision.clear(), ccd.clear(), rest.clear();
    hits = repairs = acted = 0.0;
    for (int f = 0; f < frames; ++f) {
      const Status driven = which == 0   ? test::LinkedRings::drive(*sim, f, 1.0)
                            : which == 1 ? test::ThreadUnderMembrane::drive(*sim, f, 1.0)
                                         : test::ProbeUnderMembrane::drive(*sim, f, 1.0);
      if (!driven) {
        state.SkipWithError(driven.error().message().c_str());
        return;
      }
      if (Status s = sim->step(); !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      const FrameStats& st = sim->last_frame();
      wall.push_back(st.wall_ms);
      collision.push_back(st.collision_ms);
      ccd.push_back(st.ccd_ms);
      rest.push_back(st.wall_ms - st.collision_ms - st.ccd_ms);
      hits += st.ccd_hits;
      repairs += st.ccd_repairs;
      acted += st.ccd_reverted + st.ccd_carried;
    }
  }
  state.counters["wall_ms"] = median(wall);
  state.counters["collision_ms"] = median(collision);
  state.counters["ccd_ms"] = median(ccd);
  state.counters["solve_ms"] = median(rest);
  state.counters["touches"] = hits / frames;
  state.counters["repairs"] = repairs / frames;
  state.counters["failsafe_particles"] = acted / frames;
}

BENCHMARK(BM_ContinuousCollision)
    ->ArgNames({"scene", "ccd"})
    ->ArgsProduct({{0, 1, 2}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_continuous_collision",
                     "What continuous collision in the solver costs per frame, by stage, on the continuous collision\ntests' three thread scenes, with CCD on and off.")
