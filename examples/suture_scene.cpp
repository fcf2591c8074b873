// suture_scene — the reference scene S3 (examples/common/suture_scene.h): a
// tissue pad of 20,064 tets with a 2 mm slit, a curved needle and its
// 200-segment thread turned through both lips twice, then pulled until the
// thread's knot holds and the stitches close the slit; the thread's mesh
// collision and continuous collision on.
//
// Writes into the output folder suture_scene.pvd (the pad and the thread,
// per written frame, for ParaView; the needle as lines) and prints, every
// --every frames, the frame's time, the punctures and the slit's width.
//
//   suture_scene --help   (the options, their defaults and units)
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "command_line.h"
#include "suture_scene.h"
#include "sinew/vtk_output.h"

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "suture_scene", std::string(sinew::examples::kSutureAbout) + "Writes suture_scene.pvd (pad, thread, needle) into --out.");
  sinew::examples::SutureSettings s;
  std::string out = cli.default_out();
  int every = 20, frames = 0;
  cli.add_backend(s.backend);
  cli.app().add_option("--every", every, "Report and write every N-th frame (and the last)")
      ->check(sinew::examples::at_least(1));
  cli.app().add_option("--frames", frames, "Stop after N frames of 1/60 s (0: the whole script, ~600 frames)")
      ->check(sinew::examples::at_least(0));
  cli.app().add_option("--substeps", s.substeps, "Substeps per frame")->check(sinew::examples::at_least(1));
  cli.app().add_option("--threads", s.threads, "cpu backend worker threads (0: all)")->check(sinew::examples::at_least(0));
  cli.add_switch("--continuous", s.continuous, "The thread's continuous collision");
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;
  auto fail = [](const std::string& what) {
    std::fprintf(stderr, "suture_scene: %s\n", what.c_str());
    return 1;
  };

  auto scene = sinew::examples::SutureScene::create(s);
  if (!scene) return fail(scene.error().message());
  sinew::examples::SutureScene& r = *scene;
  auto output = sinew::SceneOutput::create(
      r.scene(), out,
      {.bodies = {{.kind = sinew::BodyKind::tet, .name = "pad"}, {.kind = sinew::BodyKind::line, .name = "thread"}},
       .name = "suture_scene"});
  if (!output) return fail(output.error().message());
  if (auto st = output->write(r.sim(), 0); !st) return fail(st.error().message());
  auto before = r.gap();
  if (!before) return fail(before.error().message());
  std::printf("suture_scene on %s: %zu tets, a %d-segment thread; %d frames of stitching, then the pull\n",
              r.sim().device_name().c_str(), r.scene().tet_bodies[0].mesh.tets.size(), s.thread_segments,
              sinew::examples::kSutureStitchFrames);
  std::vector<double> ms;
  while (!r.done() && (frames == 0 || r.frames() < frames)) {
    if (auto st = r.frame(); !st) return fail("frame " + std::to_string(r.frames()) + ": " + st.error().message());
    ms.push_back(r.sim().last_frame().wall_ms);
    if (r.frames() % every != 0 && !r.done() && r.frames() != frames) continue;
    auto c = r.check();
    if (!c) return fail(c.error().message());
    std::printf("frame %4d  %7.2f ms  slit %.2f mm  %zu punctures (%zu left lip, %zu right, %zu on the thread)%s\n",
                r.frames(), ms.back(), 1e3 * c->gap, c->punctures, c->left_lip, c->right_lip, c->on_thread,
                c->knot_holds ? "  the knot holds" : "");
    if (auto st = output->write(r.sim(), r.frames()); !st) return fail(st.error().message());
  }
  auto c = r.check();
  if (!c) return fail(c.error().message());
  std::sort(ms.begin(), ms.end());
  std::printf("%d frames, median %.2f ms; the knot held from frame %d; the slit at the stitches %.2f -> %.2f mm\n",
              r.frames(), ms[ms.size() / 2], r.knot_frame(), 1e3 * *before, 1e3 * c->gap);
  std::printf("open %s/suture_scene.pvd in ParaView\n", out.c_str());
  return 0;
}
