// retraction — the reference scene S1 (examples/common/retraction_scene.h):
// kidney_57k (corotational FEM, 10 kPa), pinned along one side, grasped at its
// upper pole and pulled up while a capsule probe presses its side, with the
// kidney's mesh self-collision on. Both tools are driven by scripted haptic
// devices through the haptic tool bridge, the path a real device takes: each
// device's 1 kHz loop renders the virtual coupling's force, and the tools
// move by minus that force (and the grasper's shaft by the tissue's pull).
//
// Writes into the output folder retraction.pvd (the kidney, the tools and
// the grasper's jaws per written frame, for ParaView) and prints, every
// 10 frames, the frame's time, the pole's lift, the tissue's pull on the
// jaws and the force rendered to the grasper's hand.
//
//   retraction --help   (the options, their defaults and units)
#include <chrono>
#include <cstdio>
#include <string>

#include "command_line.h"
#include "retraction_scene.h"
#include "sinew/display_surfaces.h"
#include "sinew/vtk_output.h"

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "retraction",
      std::string(sinew::examples::kRetractionAbout) + "Writes retraction.pvd (kidney, tools, jaws) into --out.");
  sinew::examples::RetractionSettings s{.mesh = std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node"};
  std::string out = cli.default_out();
  int frames = 120, every = 10;
  cli.add_backend(s.backend);
  cli.app().add_option("--frames", frames, "Frames of 1/60 s")->check(sinew::examples::at_least(1));
  cli.app().add_option("--every", every, "Write every N-th frame")->check(sinew::examples::at_least(1));
  cli.app().add_option("--substeps", s.substeps, "Substeps per frame")->check(sinew::examples::at_least(1));
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;
  auto fail = [](const std::string& what) {
    std::fprintf(stderr, "retraction: %s\n", what.c_str());
    return 1;
  };

  auto scene = sinew::examples::RetractionScene::create(s);
  if (!scene) return fail(scene.error().message());
  sinew::examples::RetractionScene& r = **scene;
  auto output = sinew::SceneOutput::create(
      r.scene(), out, {.bodies = {{.kind = sinew::BodyKind::tet, .name = "kidney"}}, .name = "retraction"});
  if (!output) return fail(output.error().message());
  std::printf("retraction on %s: %u particles, %zu held by the grasper\n", r.sim().device_name().c_str(),
              r.sim().info().particles, r.held().size());
  double worst_ms = 0.0;
  for (int f = 0; f <= frames; ++f) {
    if (f > 0) {
      const auto a = std::chrono::steady_clock::now();
      if (auto st = r.frame(); !st) return fail(st.error().message());
      worst_ms = std::max(worst_ms, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
    }
    if (f % every == 0 || f == frames) {
      output->add_surface("jaws", sinew::box_surface(r.jaw_half_extents(), r.jaws()));
      if (auto st = output->write(r.sim(), f); !st) return fail(st.error().message());
      auto c = r.check();
      if (!c) return fail(c.error().message());
      std::printf("  %5.3f s  %6.2f ms  lift %5.2f mm  pull on jaws (%+.3f, %+.3f, %+.3f) N  hand feels %+.3f N (y)  "
                  "slip %.2f mm  inverted %zu\n",
                  r.sim().last_frame().time, r.sim().last_frame().wall_ms, 1e3 * c->pole_lift, c->grasp_force[0],
                  c->grasp_force[1], c->grasp_force[2], c->device_force[1], 1e3 * c->max_slip, c->inverted_tets);
    }
  }
  std::printf("%d frames, worst %.1f ms; wrote %s/retraction.pvd (open it in ParaView)\n", frames, worst_ms,
              out.c_str());
  return 0;
}
