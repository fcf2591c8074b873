// mesh_contact_benchmark.cpp — the three schedules of the contacts between
// meshes (MeshCollisionDesc::schedule, issue 12 part 3) on the tests' two
// contact scenes, measured on convergence and cost:
//   blocks  a 3 cm block dropped onto a 4 cm block (120 frames, 2 s);
//   fold    a membrane strip folded onto itself (180 frames, 3 s).
// Per run (one whole scene = one iteration): wall time per frame (median
// over frames) and its collision part; penetration: blocks, the deepest a
// surface vertex of either block lies inside the other at any 10th frame
// [mm]; fold, the most intersecting triangle pairs at any 6th frame; the
// worst contact violation (thickness - gap at a frame's end) over the run
// [mm]; mean contacts and colours per frame.
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_mesh_contacts --benchmark_repetitions=3
//       --benchmark_format=csv > benchmarks/results/mesh_contacts_<date>.csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_support.h"
#include "mesh_contact_support.h"
#include "sinew/simulation.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

using bench::backend;

void BM_MeshContacts(benchmark::State& state) {
  const bool fold = state.range(0) == 1;
  constexpr ContactSchedule schedules[] = {ContactSchedule::colored, ContactSchedule::jacobi,
                                           ContactSchedule::device_colored};
  constexpr const char* schedule_names[] = {"colored", "jacobi", "device_colored"};
  const ContactSchedule schedule = schedules[state.range(1)];
  const SceneDesc scene = fold ? test::FoldedStrip::scene(schedule) : test::dropped_blocks_scene(schedule);
  const int frames = fold ? 2 * test::FoldedStrip::fold_frames : 120;
  std::vector<double> wall, collision;
  double penetration = 0.0, violation = 0.0, contacts = 0.0, colors = 0.0, overflow = 0.0;
  for (auto _ : state) {
    auto sim = Simulation::create(scene, {.backend = backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    std::vector<float> x;
    wall.clear();
    collision.clear();
    penetration = violation = contacts = colors = overflow = 0.0;
    for (int f = 0; f < frames; ++f) {
      if (fold)
        for (int k = 0; k <= test::FoldedStrip::nz; ++k)
          if (auto id = sim->tools().target(k)) (void)sim->tools().set_position(*id, test::FoldedStrip::target(f, k));
      if (Status s = sim->step(); !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      const FrameStats& st = sim->last_frame();
      wall.push_back(st.wall_ms);
      collision.push_back(st.collision_ms);
      violation = std::max(violation, st.contact_violation);
      contacts += st.mesh_contacts;
      colors += st.mesh_contact_colors;
      overflow += st.mesh_contact_overflow;
      state.PauseTiming();
      if (fold && f % 6 == 5) {
        (void)sim->read_positions(x);
        penetration = std::max<double>(
            penetration, test::self_intersections(x, scene.tri_bodies[0].mesh, sim->info().tri_body_first_particle[0]));
      } else if (!fold && f % 10 == 9) {
        (void)sim->read_positions(x);
        const test::PlacedBody a{&scene.tet_bodies[0].mesh, sim->info().tet_body_first_particle[0]};
        const test::PlacedBody b{&scene.tet_bodies[1].mesh, sim->info().tet_body_first_particle[1]};
        penetration = std::max({penetration, 1e3 * test::penetration(x, a, b), 1e3 * test::penetration(x, b, a)});
      }
      state.ResumeTiming();
    }
  }
  using bench::median;
  state.counters["frame_ms"] = median(wall);
  state.counters["collision_ms"] = median(collision);
  state.counters["penetration"] = penetration;  // blocks: [mm]; fold: intersecting triangle pairs
  state.counters["violation_mm"] = 1e3 * violation;
  state.counters["contacts"] = contacts / frames;
  state.counters["colors"] = colors / frames;
  state.counters["overflow"] = overflow / frames;  // device_colored only
  state.SetLabel(std::string(fold ? "fold/" : "blocks/") + schedule_names[state.range(1)]);
}

// schedule: 0 colored (host), 1 jacobi, 2 device_colored.
BENCHMARK(BM_MeshContacts)
    ->ArgsProduct({{0, 1}, {0, 1, 2}})
    ->ArgNames({"scene", "schedule"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_mesh_contacts",
                     "The three schedules of the contacts between meshes on the tests' contact scenes (a block dropped on a\nblock, a membrane folded onto itself): wall time per frame, its collision part, penetration.")
