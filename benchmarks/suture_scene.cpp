// bench_suture_scene — the reference scene S3 (examples/common/suture_scene.h):
// a 20,064-tet pad with a slit, a needle and its 200-segment thread stitched
// through both lips and pulled to the knot, mesh collision and the thread's
// continuous collision on; 60 Hz frames. Times whole frames (the needle's
// pose and step()) over the whole script, or its first FRAMES frames.
//
//   bench_suture_scene BACKEND [FRAMES] [--threads N] [--substeps N] [--iterations N] [--continuous on|off]
//                      [--positions FILE]
//   e.g. bench_suture_scene cpu --threads 2
//
// Prints CSV: a header and one line of the frame times (median, p95, worst
// [ms]; the median and p95 process CPU time; the 1-minute load average at the
// end)
// and the scene's figures at the last frame; then the per-stage profile
// (FrameStats::stages), one line per stage with its median, p95 and worst
// [ms] over the frames. --positions writes the particles' positions at the
// last frame (float32 x, y, z, w per particle, as read_positions gives
// them), for comparing settings against a converged run
// (benchmarks/compare_positions.py).
#include <cstdio>
#include <vector>
#include <string>

#include "command_line.h"
#include "frame_profile.h"
#include "suture_scene.h"

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
  std::string positions;
  cli.app().add_option("--positions", positions, "Write the last frame's positions here (float32 xyzw per particle)");
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
  sinew::bench::FrameProfile profile;
  std::uint64_t forced = 0, touches = 0;
  while (!r.done() && (frames == 0 || r.frames() < frames)) {
    profile.start();
    if (auto st = r.frame(); !st) return fail(st.error().message());
    profile.stop(r.sim().last_frame());
    forced += r.sim().last_frame().ccd_forced;
    touches += r.sim().last_frame().ccd_hits;
  }
  auto c = r.check();
  if (!c) return fail(c.error().message());
  std::printf("backend,tets,thread_segments,substeps,iterations,continuous,frames,median_ms,p95_ms,worst_ms,"
              "cpu_median_ms,cpu_p95_ms,load_1min,punctures,knot_frame,gap_before_mm,gap_after_mm,ccd_touches,ccd_forced,"
              "thread_min_distance_mm,finite\n");
  std::printf("%s,%zu,%d,%d,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.2f,%zu,%d,%.3f,%.3f,%llu,%llu,%.4f,%d\n", s.backend.c_str(),
              r.scene().tet_bodies[0].mesh.tets.size(), s.thread_segments, s.substeps, s.iterations,
              s.continuous ? 1 : 0, r.frames(), profile.wall(0.5), profile.wall(0.95), profile.wall(1.0),
              profile.cpu(0.5), profile.cpu(0.95), sinew::bench::load_average(), c->punctures, r.knot_frame(), 1e3 * *gap_before,
              1e3 * c->gap, static_cast<unsigned long long>(touches), static_cast<unsigned long long>(forced), 1e3 * c->thread_min_distance,
              c->finite ? 1 : 0);
  profile.print_stages();
  if (!positions.empty()) {
    std::vector<float> x;
    if (auto st = r.sim().read_positions(x); !st) return fail(st.error().message());
    std::FILE* f = std::fopen(positions.c_str(), "wb");
    if (!f || std::fwrite(x.data(), sizeof(float), x.size(), f) != x.size()) return fail("cannot write " + positions);
    std::fclose(f);
  }
  return 0;
}
