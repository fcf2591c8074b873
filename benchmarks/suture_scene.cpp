// bench_suture_scene — the reference scene S3 (examples/common/suture_scene.h):
// a 20,328-tet pad with a slit, a needle and its 200-segment thread stitched
// through both lips and pulled to the knot, mesh collision and the thread's
// continuous collision on; 60 Hz frames. Times whole frames (the needle's
// pose and step()) over the whole script, or its first FRAMES frames.
//
//   bench_suture_scene BACKEND [FRAMES] [--threads N] [--substeps N] [--iterations N] [--continuous on|off]
//   e.g. bench_suture_scene cpu --threads 2
//
// Prints CSV: a header and one line of the frame times (median, p95, worst
// [ms]; the median process CPU time; the 1-minute load average at the end)
// and the scene's figures at the last frame; then the per-stage profile
// (FrameStats::stages), one line per stage with its median, p95 and worst
// [ms] over the frames.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "command_line.h"
#include "suture_scene.h"

namespace {

// Nearest-rank percentile q in [0, 1] of v (0 when empty).
double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t k = static_cast<std::size_t>(std::ceil(q * double(v.size())));
  return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "bench_suture_scene",
      std::string(sinew::examples::kSutureAbout) +
          "Prints CSV: the frame times (median, p95, worst [ms]) and the per-stage profile.\n"
          "e.g. bench_suture_scene cpu --threads 2");
  sinew::examples::SutureSettings s;
  int frames = 0;
  cli.app().add_option("backend", s.backend, "Backend: cpu, opencl, vulkan or auto")
      ->required()
      ->check(CLI::IsMember({"auto", "cpu", "opencl", "vulkan"}));
  cli.app().add_option("frames", frames, "Frames of 1/60 s to time (0: the whole script)")
      ->check(sinew::examples::at_least(0));
  cli.app().add_option("--substeps", s.substeps, "Substeps per frame")->check(sinew::examples::at_least(1));
  cli.app().add_option("--iterations", s.iterations, "Iterations per substep")->check(sinew::examples::at_least(1));
  cli.app().add_option("--threads", s.threads, "cpu backend worker threads (0: all)")->check(sinew::examples::at_least(0));
  cli.add_switch("--continuous", s.continuous, "The thread's continuous collision");
  if (auto exit = cli.parse(argc, argv)) return *exit;
  auto fail = [](const std::string& what) {
    std::fprintf(stderr, "bench_suture_scene: %s\n", what.c_str());
    return 1;
  };

  auto scene = sinew::examples::SutureScene::create(s);
  if (!scene) return fail(scene.error().message());
  sinew::examples::SutureScene& r = *scene;
  auto gap_before = r.gap();
  if (!gap_before) return fail(gap_before.error().message());
  // Wall time, and the process's CPU time (every thread's): on a shared
  // machine the latter is the frame's work without the time other jobs took.
  auto cpu_now_ms = [] {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
  };
  std::vector<double> frame_ms, cpu_ms;
  std::map<std::string, std::vector<double>> stage_ms;
  std::vector<std::string> stage_order;
  std::uint64_t forced = 0;
  while (!r.done() && (frames == 0 || r.frames() < frames)) {
    const double c0 = cpu_now_ms();
    const auto a = std::chrono::steady_clock::now();
    if (auto st = r.frame(); !st) return fail(st.error().message());
    frame_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
    cpu_ms.push_back(cpu_now_ms() - c0);
    forced += r.sim().last_frame().ccd_forced;
    for (const auto& p : r.sim().last_frame().stages) {
      if (!stage_ms.count(p.name)) stage_order.push_back(p.name);
      stage_ms[p.name].push_back(p.ms);
    }
  }
  auto c = r.check();
  if (!c) return fail(c.error().message());
  double load[1] = {0.0};
  if (getloadavg(load, 1) != 1) load[0] = -1.0;
  std::printf("backend,tets,thread_segments,substeps,iterations,continuous,frames,median_ms,p95_ms,worst_ms,"
              "cpu_median_ms,load_1min,punctures,knot_frame,gap_before_mm,gap_after_mm,ccd_forced,"
              "thread_min_distance_mm,finite\n");
  std::printf("%s,%zu,%d,%d,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.2f,%zu,%d,%.3f,%.3f,%llu,%.4f,%d\n", s.backend.c_str(),
              r.scene().tet_bodies[0].mesh.tets.size(), s.thread_segments, s.substeps, s.iterations,
              s.continuous ? 1 : 0, r.frames(), percentile(frame_ms, 0.5), percentile(frame_ms, 0.95),
              percentile(frame_ms, 1.0), percentile(cpu_ms, 0.5), load[0], c->punctures, r.knot_frame(),
              1e3 * *gap_before, 1e3 * c->gap, static_cast<unsigned long long>(forced), 1e3 * c->thread_min_distance,
              c->finite ? 1 : 0);
  std::printf("stage,median_ms,p95_ms,worst_ms\n");
  for (const auto& name : stage_order)
    std::printf("%s,%.3f,%.3f,%.3f\n", name.c_str(), percentile(stage_ms[name], 0.5), percentile(stage_ms[name], 0.95),
                percentile(stage_ms[name], 1.0));
  return 0;
}
