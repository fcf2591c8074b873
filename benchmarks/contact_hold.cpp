// contact_hold.cpp — how well contacts hold a weight that is large against
// the particles it rests on, with and without SolverSettings::contact_sweeps:
// a rigid capsule tool of 300 g - 1 kg lying on a 1 cm-cell membrane
// (tests/contact_hold_support.h, ToolOnMembrane), 240 frames (4 s), one
// whole run per iteration, with and without MeshCollisionDesc::face_manifold.
// The kidney pressed by 5 N is bench_retraction's (--probe-force 5
// --contact-sweeps N).
//
// Counters: crossings ((frame, triangle) pairs where the tool's axis crossed
// the membrane), below_mm (how far its centre got below the membrane under
// it; > 0: through), tool_violation_mm (the deepest face contact with the
// tool inside the 1 mm thickness, FrameStats' "tool_violation_m"),
// penetration_mm (the deepest vertex inside the capsule), lowest_mm (the
// centre's lowest), force_over_weight (the mean contact force over the
// last 60 frames over the weight), frame_ms (median over the frames).
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_contact_hold --benchmark_format=csv
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "bench_support.h"
#include "contact_hold_support.h"
#include "sinew/simulation.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

void BM_ToolOnMembrane(benchmark::State& state) {
  const double mass = 1e-3 * double(state.range(0));
  const int sweeps = static_cast<int>(state.range(1));
  const SceneDesc scene = test::ToolOnMembrane::scene(mass, sweeps, state.range(2) != 0);
  constexpr int kFrames = 240, kAveraged = 60;
  test::ToolOnMembrane::Measure m;
  std::vector<double> wall;
  for (auto _ : state) {
    auto sim = Simulation::create(scene, {.backend = bench::backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    m = {};
    wall.clear();
    for (int f = 0; f < kFrames; ++f) {
      if (Status s = sim->step(); !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      wall.push_back(sim->last_frame().wall_ms);
      state.PauseTiming();
      if (Status s = test::ToolOnMembrane::measure(*sim, scene, f >= kFrames - kAveraged, kAveraged, m); !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      state.ResumeTiming();
    }
  }
  state.counters["crossings"] = m.crossings;
  state.counters["below_mm"] = 1e3 * m.below;
  state.counters["tool_violation_mm"] = 1e3 * m.tool_violation;
  state.counters["penetration_mm"] = 1e3 * m.penetration;
  state.counters["lowest_mm"] = 1e3 * m.lowest;
  state.counters["force_over_weight"] = m.force / (mass * 9.81);
  state.counters["frame_ms"] = bench::median(wall);
}

// mass [g], contact sweeps, MeshCollisionDesc::face_manifold.
BENCHMARK(BM_ToolOnMembrane)
    ->ArgsProduct({{300, 500, 700, 1000}, {0, 1, 2, 4, 8}, {0, 1}})
    ->ArgNames({"grams", "contact_sweeps", "manifold"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_contact_hold",
                     "A heavy rigid tool lying on a membrane of 1 cm cells, with and without contact-only sweeps: whether\nit passes through, how deep its contacts end, whether they carry its weight.")
