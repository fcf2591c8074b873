// suture_benchmark.cpp — what a suturing frame costs, split by stage (issue
// 13, part 5): the tests' stitch (tests/suture_scenes.h: a half-circle
// needle through two pads either side of a cut, 2,160 tets, a 60-segment
// thread), driven frame by frame for the whole stitch: 110 frames of
// turning (tip contacts, punctures in and out, the punctures passing to the
// thread) and 190 of pulling and tugging (the thread sliding through four
// punctures, then its knot holding).
// Per run (the whole stitch = one iteration), medians over its frames [ms],
// by stage:
//   frame_ms        wall time per frame;
//   broad_phase_ms  mesh collision (collision:1; FrameStats::collision_ms:
//                   reading the positions back, the BVH broad phase and the
//                   narrow phase, colouring and uploading the contacts);
//   ccd_ms          continuous collision (collision:1; FrameStats::ccd_ms:
//                   per substep, reading back, the swept-box broad phase and
//                   the CCD queries, and the repairs' bookkeeping);
//   suture_host_ms  the needles' host side (suture_ms: reading the
//                   positions back, testing the tip's path against the
//                   surfaces' 1,200 triangles, uploading the rows, reading
//                   them back);
//   solve_ms        the rest: the frame's program (the sweeps with the
//                   suture rows and the mesh contacts in each, and the
//                   statistics), and the repair sweeps CCD asks for;
//   sutures_kernel_ms  where the backend times its kernels, the device time
//                   of xpbd_sutures per frame (one dispatch per sweep).
// phase:0 times the turning frames, phase:1 the pulling ones; needle:0 the
// same pads and thread without the needle (what the scene costs without
// sutures); collision:1 with mesh collision (0.5 mm thick, no
// self-collision) and CCD on, as TheStitchHoldsWithMeshCollisionAndContinuousCollisionOn.
//
//   SINEW_BACKEND=cpu build/benchmarks/bench_suture --benchmark_repetitions=3
//       --benchmark_format=csv > benchmarks/results/suture_<date>.csv
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_support.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "suture_scenes.h"
#include "benchmark_main.h"

namespace {

using namespace sinew;

using bench::backend;
using bench::median;

void BM_Suture(benchmark::State& state) {
  const bool pulling = state.range(0) == 1, needle = state.range(1) == 1, collision = state.range(2) == 1;
  SceneDesc scene = test::SuturePads::scene();
  if (!needle) scene.needles.clear();
  if (collision) {
    scene.mesh_collision.enabled = true;
    scene.mesh_collision.thickness = 5e-4;
    scene.mesh_collision.self_collision = false;
    scene.mesh_collision.continuous = true;
  }
  constexpr int frames = 300;
  std::size_t sutures_kernel = 0;
  for (const auto name : kernel_names()) {
    if (name == "xpbd_sutures") break;
    ++sutures_kernel;
  }
  std::vector<double> wall, broad, ccd, suture, rest, kernel;
  for (auto _ : state) {
    auto sim = Simulation::create(scene, {.backend = backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    wall.clear(), broad.clear(), ccd.clear(), suture.clear(), rest.clear(), kernel.clear();
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
      broad.push_back(st.collision_ms);
      ccd.push_back(st.ccd_ms);
      suture.push_back(st.suture_ms);
      rest.push_back(st.wall_ms - st.suture_ms - st.collision_ms - st.ccd_ms);
      if (st.device.timed) kernel.push_back(st.device.kernel_ms[sutures_kernel]);
    }
    const auto needle_id = sim->needles().needle(0);
    const auto stitched = needle_id ? sim->needles().state(*needle_id) : Result<NeedleState>(needle_id.error());
    if (needle && (!stitched || stitched->punctures.size() != 4)) {
      state.SkipWithError("the stitch did not make its four punctures");
      return;
    }
  }
  state.counters["frame_ms"] = median(wall);
  state.counters["broad_phase_ms"] = median(broad);
  state.counters["ccd_ms"] = median(ccd);
  state.counters["suture_host_ms"] = median(suture);
  state.counters["solve_ms"] = median(rest);
  state.counters["sutures_kernel_ms"] = kernel.empty() ? -1.0 : median(kernel);
  state.SetLabel(backend() + (pulling ? "/pulling" : "/turning") + (collision ? "/collision" : ""));
}

// On the real liver (382,510 tets, the mesher's order, millimetres scaled to
// metres, an edge network of E = 30 kPa, its lowest fifth pinned): a
// straight 20 mm needle pushed down into its highest point at 0.4 mm per
// frame for 40 frames (it punctures). What the needles' host side costs on
// an organ's surface: the read-back of every particle and the tip's path
// tested against every surface triangle, each frame.
void BM_SutureLiver(benchmark::State& state) {
  auto mesh = read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/liver_382k.node");
  if (!mesh) {
    state.SkipWithError(mesh.error().message().c_str());
    return;
  }
  scale_mesh(*mesh, 1e-3);
  SceneDesc scene;
  scene.gravity = {0.0, 0.0, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 8;
  scene.solver.iterations = 10;
  TetBodyDesc liver;
  liver.mesh = *mesh;
  (void)liver.set_elastic(3e4, 0.45);
  double lowest = INFINITY, highest = -INFINITY;
  std::size_t top = 0;
  for (std::size_t v = 0; v < mesh->vertices.size(); ++v) {
    lowest = std::min(lowest, mesh->vertices[v][1]);
    if (mesh->vertices[v][1] > highest) highest = mesh->vertices[v][1], top = v;
  }
  for (std::uint32_t v = 0; v < mesh->vertices.size(); ++v)
    if (mesh->vertices[v][1] < lowest + 0.2 * (highest - lowest)) liver.pinned.push_back(v);
  scene.tet_bodies.push_back(liver);
  NeedleDesc needle;
  needle.curve = {{0.0, 0.02, 0.0}, {0.0, 0.0, 0.0}};
  const auto& at = mesh->vertices[top];
  needle.position = {at[0] + 4e-4, at[1] + 0.002, at[2] + 3e-4};  // off the vertex, 2 mm above
  needle.puncture_force = 0.01;
  scene.needles = {needle};
  std::vector<double> wall, suture;
  std::size_t punctures = 0;
  for (auto _ : state) {
    auto sim = Simulation::create(scene, {.backend = backend(), .quiet = true});
    if (!sim) {
      state.SkipWithError(sim.error().message().c_str());
      return;
    }
    wall.clear(), suture.clear();
    for (int f = 0; f < 40; ++f) {
      const auto& p = needle.position;
      if (Status s = sim->needles().set_pose(*sim->needles().needle(0), {p[0], p[1] - 4e-4 * (f + 1), p[2]}, {1.0, 0.0, 0.0, 0.0}); !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      if (Status s = sim->step(); !s) {
        state.SkipWithError(s.error().message().c_str());
        return;
      }
      wall.push_back(sim->last_frame().wall_ms);
      suture.push_back(sim->last_frame().suture_ms);
    }
    punctures = sim->needles().state(*sim->needles().needle(0))->punctures.size();
  }
  state.counters["frame_ms"] = median(wall);
  state.counters["suture_host_ms"] = median(suture);
  state.counters["punctures"] = static_cast<double>(punctures);
  state.SetLabel(backend() + "/liver");
}

BENCHMARK(BM_SutureLiver)->Iterations(1)->Unit(benchmark::kMillisecond);

BENCHMARK(BM_Suture)
    ->ArgNames({"phase", "needle", "collision"})
    ->Args({0, 1, 0})
    ->Args({1, 1, 0})
    ->Args({0, 0, 0})
    ->Args({0, 1, 1})
    ->Args({1, 1, 1})
    ->Args({0, 0, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

SINEW_BENCHMARK_MAIN("bench_suture",
                     "A suturing frame by stage: the suture tests' stitch (a needle through two pads, a 60-segment thread),\nturning and pulling phases, with and without mesh collision.")
