// bench_dissection — the reference scene S2 (examples/common/dissection_scene.h):
// frames of 1/60 s timed, printed as CSV: the frame times (median, p95,
// worst), the topology changes' share, the gallbladder's lift, and the
// per-stage profile (FrameStats::stages), as bench_retraction prints S1's.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "bench_support.h"
#include "command_line.h"
#include "dissection_scene.h"

namespace {

using sinew::bench::percentile;

int fail(const std::string& what) {
  std::fprintf(stderr, "bench_dissection: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli("bench_dissection",
                                   std::string(sinew::examples::kDissectionAbout) +
                                       "Prints CSV: the frame times (median, p95, worst [ms]), the gallbladder's lift and\n"
                                       "the per-stage profile. e.g. bench_dissection cpu 140 --threads 2");
  sinew::examples::DissectionSettings s{.gallbladder = std::string(SINEW_DATA_DIR) + "/meshes/tet/gallbladder_volumetric.vtk"};
  int frames = 0;
  cli.app().add_option("backend", s.backend, "Backend: cpu, opencl, vulkan or auto")
      ->required()
      ->check(CLI::IsMember({"auto", "cpu", "opencl", "vulkan"}));
  cli.app().add_option("frames", frames, "Frames of 1/60 s to time (the script lasts 138)")->required()->check(sinew::examples::at_least(1));
  cli.app().add_option("--substeps", s.substeps, "Substeps per frame")->check(sinew::examples::at_least(1));
  cli.app().add_option("--iterations", s.iterations, "Iterations per substep")->check(sinew::examples::at_least(1));
  cli.app().add_option("--threads", s.threads, "cpu backend worker threads (0: all)")->check(sinew::examples::at_least(0));
  cli.app().add_option("--topology-every", s.topology_every, "A burn and a cut every N frames")->check(sinew::examples::at_least(1));
  std::string trace;
  cli.app().add_option("--trace", trace, "Write each frame's wall time and stages [ms] as CSV to this file");
  cli.add_switch("--mesh-collision", s.mesh_collision, "Contacts between the bodies' meshes");
  if (auto exit = cli.parse(argc, argv)) return *exit;

  auto scene = sinew::examples::DissectionScene::create(s);
  if (!scene) return fail(scene.error().message());
  sinew::examples::DissectionScene& r = **scene;
  // Wall time, and the process's CPU time (every thread's): on a shared
  // machine the latter is the frame's work without the time other jobs took.
  auto cpu_now_ms = [] {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
  };
  std::vector<double> frame_ms, cpu_ms, topology_ms, dissect_ms;  // dissect_ms: the frames where the cautery and blade work
  std::map<std::string, std::vector<double>> stage_ms;
  std::vector<std::string> stage_order;
  double lift = 0.0, membrane_lift = 0.0;  // at the lift's end (before the dissection)
  const int lift_end = static_cast<int>(std::lround(sinew::examples::kLiftEnd / r.frame_time()));
  std::FILE* trace_file = trace.empty() ? nullptr : std::fopen(trace.c_str(), "w");
  if (!trace.empty() && !trace_file) return fail("cannot write " + trace);
  if (trace_file) std::fprintf(trace_file, "frame,wall_ms,dissecting,stage,stage_ms\n");
  for (int f = 1; f <= frames; ++f) {
    const double c0 = cpu_now_ms();
    const auto a = std::chrono::steady_clock::now();
    if (auto st = r.frame(); !st) return fail(st.error().message());
    frame_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
    cpu_ms.push_back(cpu_now_ms() - c0);
    if (r.dissecting()) dissect_ms.push_back(frame_ms.back());
    if (r.last_topology_ms() > 0.0) topology_ms.push_back(r.last_topology_ms());
    for (const auto& p : r.sim().last_frame().stages) {
      if (!stage_ms.count(p.name)) stage_order.push_back(p.name);
      stage_ms[p.name].push_back(p.ms);
      if (trace_file) std::fprintf(trace_file, "%d,%.3f,%d,%s,%.3f\n", f, frame_ms.back(), r.dissecting() ? 1 : 0, p.name.c_str(), p.ms);
    }
    if (f == lift_end) {
      auto c = r.check();
      if (!c) return fail(c.error().message());
      lift = c->gallbladder_lift, membrane_lift = c->membrane_lift;
    }
  }
  if (trace_file) std::fclose(trace_file);
  auto c = r.check();
  if (!c) return fail(c.error().message());
  double load[1] = {0.0};
  if (getloadavg(load, 1) != 1) load[0] = -1.0;
  std::printf("backend,particles,membrane_triangles_left,body_attachments,held,substeps,iterations,frames,median_ms,"
              "p95_ms,worst_ms,cpu_median_ms,cpu_p95_ms,dissecting_median_ms,topology_changes,topology_median_ms,load_1min,gallbladder_lift_mm,membrane_lift_mm,"
              "deepest_inside_mm,finite\n");
  std::printf("%s,%u,%zu,%zu,%zu,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%zu,%.3f,%.2f,%.3f,%.3f,%.3f,%d\n", s.backend.c_str(),
              r.sim().info().particles, c->membrane_triangles, r.scene().body_attachments.size(), r.held(),
              s.substeps, s.iterations, frames, percentile(frame_ms, 0.5), percentile(frame_ms, 0.95),
              percentile(frame_ms, 1.0), percentile(cpu_ms, 0.5), percentile(cpu_ms, 0.95), percentile(dissect_ms, 0.5), r.topology_events(), percentile(topology_ms, 0.5), load[0], 1e3 * lift,
              1e3 * membrane_lift, 1e3 * c->deepest_inside, c->finite ? 1 : 0);
  std::printf("stage,median_ms,p95_ms,worst_ms\n");
  for (const auto& name : stage_order)
    std::printf("%s,%.3f,%.3f,%.3f\n", name.c_str(), percentile(stage_ms[name], 0.5), percentile(stage_ms[name], 0.95),
                percentile(stage_ms[name], 1.0));
  return 0;
}
