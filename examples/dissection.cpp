// dissection — the reference scene S2 (examples/common/dissection_scene.h):
// a grasper lifts the membrane joining the gallbladder to the liver bed
// (attached two ways to both: the gallbladder rises with it), then a
// cautery tip burns along the liver's attachment line and a blade cuts
// along the gallbladder's, the three tools driven by scripted hands through
// the haptic tool bridge. Writes dissection.pvd (sinew/vtk_output.h): the
// gallbladder, the liver bed, the membrane (removed triangles empty) and the
// tools' working parts, to --out.
//
//   dissection --help   (the options, their defaults and units)
#include <cmath>
#include <cstdio>
#include <string>

#include "command_line.h"
#include "dissection_scene.h"
#include "sinew/display_surfaces.h"
#include "sinew/vtk_output.h"

namespace {
int fail(const std::string& what) {
  std::fprintf(stderr, "dissection: %s\n", what.c_str());
  return 1;
}
}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli("dissection", std::string(sinew::examples::kDissectionAbout) +
                                                     "Writes dissection.pvd into --out.");
  sinew::examples::DissectionSettings s{.gallbladder = std::string(SINEW_DATA_DIR) + "/meshes/tet/gallbladder_volumetric.vtk"};
  std::string out = cli.default_out();
  int every = 5;
  cli.add_backend(s.backend);
  cli.app().add_option("--threads", s.threads, "cpu backend worker threads (0: all)")->check(sinew::examples::at_least(0));
  cli.app().add_option("--every", every, "Write the VTU files every N frames of 1/60 s")->check(sinew::examples::at_least(1));
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  auto made = sinew::examples::DissectionScene::create(s);
  if (!made) return fail(made.error().message());
  sinew::examples::DissectionScene& r = **made;
  auto output = sinew::SceneOutput::create(r.scene(), out,
                                           {.bodies = {{.kind = sinew::BodyKind::tet, .name = "gallbladder"},
                                                       {.kind = sinew::BodyKind::tet, .name = "liver_bed"},
                                                       {.kind = sinew::BodyKind::tri, .name = "membrane"}},
                                            .name = "dissection"});
  if (!output) return fail(output.error().message());
  if (auto st = output->write(r.sim(), 0); !st) return fail(st.error().message());
  const int frames = static_cast<int>(std::lround(sinew::examples::kScriptEnd / r.frame_time()));
  for (int f = 1; f <= frames; ++f) {
    if (auto st = r.frame(); !st) return fail(st.error().message());
    if (f % every != 0) continue;
    output->add_surface("grasper", sinew::box_surface(r.jaw_half_extents(), r.jaws()));
    if (r.dissecting()) {
      output->add_surface("cautery", sinew::capsule_surface(r.cautery_radius(), 0.0, {.position = r.cautery_tip()}));
      output->add_polyline("blade", r.blade_edge());
    }
    if (auto st = output->write(r.sim(), f); !st) return fail(st.error().message());
  }
  auto c = r.check();
  if (!c) return fail(c.error().message());
  std::printf("dissection: gallbladder's attached region %+.2f mm since the lift began; %zu topology changes, %zu of "
              "6000 membrane triangles left; wrote %d frames to %s\n",
              1e3 * c->gallbladder_lift, r.topology_events(), c->membrane_triangles, 1 + frames / every, out.c_str());
  return c->finite ? 0 : fail("a position is not finite");
}
