// suture_benchmark.cpp — what a suturing frame costs, split by stage (issue
// 13, part 5): the tests' stitch (tests/suture_scenes.h: a half-circle
// needle through two pads either side of a cut, 2,160 tets, a 60-segment
// thread), driven frame by frame for the whole stitch: 110 frames of
// turning (tip contacts, punctures in and out, the punctures passing to the
// thread) and 190 of pulling and tugging (the thread sliding through four
// punctures, then its knot holding).
// Per run (the whole stitch = one iteration), medians over its frames [ms]:
// wall time per frame; the needles' host side (suture_ms: reading the
// positions back, testing the tip's path against the surfaces' 1,200
// triangles, uploading the rows, reading them back); the rest (the frame's
// program: the sweeps with the suture rows in each, and the statistics);
// where the backend times its kernels, the device time of xpbd_sutures per
// frame (all its dispatches: one per sweep). phase:0 times the turning
// frames, phase:1 the pulling ones; needle:0 the same pads and thread
// without the needle (what the scene costs without sutures).
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_suture --benchmark_repetitions=3
//       --benchmark_format=csv > benchmarks/results/suture_<date>.csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "sinew/simulation.h"
#include "suture_scenes.h"

namespace {

using namespace sinew;

std::string backend() {
  const char* v = std::getenv("SINEW_BACKEND");
  return v ? v : "auto";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void BM_Suture(benchmark::State& state) {
  const bool pulling = state.range(0) == 1, needle = state.range(1) == 1;
  SceneDesc scene = test::SuturePads::scene();
  if (!needle) scene.needles.clear();
  constexpr int frames = 300;
  std::size_t sutures_kernel = 0;
  for (const auto name : kernel_names()) {
    if (name == "xpbd_sutures") break;
    ++sutures_kernel;
  }
  std::vector<double> wall, suture, rest, kernel;
  for (auto _ : state) {
    auto sim = Simulation::create(scene, {.backend = backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    wall.clear(), suture.clear(), rest.clear(), kernel.clear();
    for (int f = 0; f < frames; ++f) {
      if (Status s = needle ? test::SuturePads::drive(*sim, f) : Status{}; !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      if (Status s = sim->step(); !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      if ((f >= test::SuturePads::turn_frames) != pulling) continue;
      const FrameStats& st = sim->last_frame();
      wall.push_back(st.wall_ms);
      suture.push_back(st.suture_ms);
      rest.push_back(st.wall_ms - st.suture_ms - st.collision_ms);
      if (st.device.timed) kernel.push_back(st.device.kernel_ms[sutures_kernel]);
    }
    auto stitched = sim->needle_state(0);
    if (needle && (!stitched || stitched->punctures.size() != 4)) {
      state.SkipWithError("the stitch did not make its four punctures");
      return;
    }
  }
  state.counters["frame_ms"] = median(wall);
  state.counters["suture_host_ms"] = median(suture);
  state.counters["program_ms"] = median(rest);
  state.counters["sutures_kernel_ms"] = kernel.empty() ? -1.0 : median(kernel);
  state.SetLabel(backend() + (pulling ? "/pulling" : "/turning"));
}

BENCHMARK(BM_Suture)
    ->ArgNames({"phase", "needle"})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({0, 0})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
