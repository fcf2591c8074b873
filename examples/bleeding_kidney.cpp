// bleeding_kidney — the bleeding reference scene (S4) written for
// ParaView: a cut vessel bleeds onto the kidney (kidney_57k, corotational
// FEM at 20 kPa, pinned where it rests), the blood pools on it and runs
// off into a drain, and from --suction seconds a suction tip comes down
// onto the wound and circles it. The blood and the kidney are coupled both
// ways. The scene: examples/common/bleeding_organ_scene.h (the benchmark
// benchmarks/bleeding_organ.cpp times the same scene).
//
// Prints every --every frames (of 1/60 s): the fluid particles, the blood
// made, suctioned and drained [ml], the books (made - alive - suctioned -
// drained: always 0), the vertical force the blood puts on the kidney
// [mN], the fluid particles inside the kidney (0: none tunnelled), and the
// wall time per frame. Writes bleeding_kidney.pvd into --out: kidney_N.vtu,
// fluid_N.vtu (density, pressure, velocity) and suction_N.vtu.
//
//   bleeding_kidney --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bleeding_organ_scene.h"
#include "command_line.h"
#include "sinew/display_surfaces.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace {

using sinew::examples::BleedingOrganScene;

int fail(const std::string& what) {
  std::fprintf(stderr, "bleeding_kidney: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "bleeding_kidney",
      "A cut vessel bleeds onto the kidney (kidney_57k): the blood pools and runs off into a drain, and a\n"
      "suction tip takes it (SPH coupled both ways with the tissue, 60 Hz frames). Prints every --every frames\n"
      "the particles, the blood made, suctioned and drained, the books, the push on the kidney and the wall\n"
      "time; writes bleeding_kidney.pvd (kidney, fluid, suction tip) into --out.");
  std::string backend = "auto", out = cli.default_out();
  int frames = 120, every = 10;
  sinew::examples::BleedingOrganOptions options;
  options.mesh_path = std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node";
  cli.add_backend(backend);
  cli.app().add_option("--frames", frames, "Frames of 1/60 s")->check(sinew::examples::at_least(1));
  cli.app().add_option("--every", every, "Report and write the VTU files every N frames (and the last)")
      ->check(sinew::examples::at_least(1));
  sinew::examples::add_bleeding_organ_options(cli, options);
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  auto made = sinew::examples::make_bleeding_organ_scene(options);
  if (!made) return fail(made.error().message());
  const BleedingOrganScene& s = *made;
  auto sim = sinew::Simulation::create(s.scene, {.backend = backend});
  if (!sim) return fail(sim.error().message());
  sinew::SceneFluid fluid = sim->fluid();
  const auto info = fluid.info();
  if (!info) return fail(info.error().message());
  std::printf("bleeding_kidney: %s; kidney %zu tets, %u of %u surface triangles coupled (%u boundary particles); "
              "blood up to %u particles, %u steps per frame\n",
              sim->device_name().c_str(), s.mesh.tets.size(), s.coupled_triangles, s.surface_triangles,
              info->coupled_boundary, info->capacity, info->steps_per_frame);
  std::printf("   t [s]  particles  made [ml]  suctioned [ml]  drained [ml]  books  push [mN]  inside  v max [m/s]  moved [mm]  wall ms\n");

  auto output = sinew::SceneOutput::create(s.scene, out, {.bodies = {{.name = "kidney"}}, .name = "bleeding_kidney"});
  if (!output) return fail(output.error().message());
  output->add_surface("suction", sinew::capsule_surface(BleedingOrganScene::kSuctionRadius, 0.0,
                                                        {.position = s.suction_at(0.0).centre}));
  if (auto st = output->write(*sim, 0); !st) return fail(st.error().message());
  const double ml = std::pow(BleedingOrganScene::kSpacing, 3) * 1e6;
  const std::uint32_t first = sim->info().tet_body_first_particle[0];
  sinew::examples::RemovalBooks books;
  std::vector<sinew::FluidParticle> q;
  std::vector<float> x;
  std::vector<double> wall;
  for (int frame = 1; frame <= frames; ++frame) {
    const double t = frame * BleedingOrganScene::kFrame;
    if (auto st = s.script(fluid, t); !st) return fail(st.error().message());
    if (auto st = sim->step(); !st) return fail(st.error().message());
    wall.push_back(sim->last_frame().wall_ms);
    // The books need every frame's particles (a removal between two reads is named by where it was seen last).
    if (auto st = fluid.read(q); !st) return fail(st.error().message());
    const auto stats = fluid.stats();
    if (!stats) return fail(stats.error().message());
    books.update(q, s.suction_at(t), s, BleedingOrganScene::kFrame * std::max(2.0 * stats->max_speed, 0.3) + 2e-3);
    if (frame % every != 0 && frame != frames) continue;

    if (auto st = sim->read_positions(x); !st) return fail(st.error().message());
    const sinew::examples::TetContainment kidney(s.mesh, x, first, 4e-3);
    double moved = 0.0;  // the kidney's largest displacement from its rest shape
    for (std::size_t v = 0; v < s.mesh.vertices.size(); ++v) {
      double d2 = 0.0;
      for (int a = 0; a < 3; ++a) {
        const double d = x[4 * (first + v) + std::size_t(a)] - s.mesh.vertices[v][a];
        d2 += d * d;
      }
      moved = std::max(moved, std::sqrt(d2));
    }
    long inside = 0;
    for (const auto& p : q) inside += kidney.inside({p.position[0], p.position[1], p.position[2]}) ? 1 : 0;
    const auto impulses = fluid.last_impulses();
    if (!impulses) return fail(impulses.error().message());
    const std::uint64_t suctioned = books.suctioned(stats->removed);
    const long long balance = (long long)stats->emitted - (long long)stats->particles - (long long)suctioned -
                              (long long)books.drained;
    std::nth_element(wall.begin(), wall.begin() + std::ptrdiff_t(wall.size() / 2), wall.end());
    std::printf("  %6.3f  %9u  %9.3f  %14.3f  %12.3f  %5lld  %9.3f  %6ld  %11.3f  %10.3f  %7.1f\n", t, stats->particles,
                double(stats->emitted) * ml, double(suctioned) * ml, double(books.drained) * ml, balance,
                1e3 * impulses->tissue[1] / BleedingOrganScene::kFrame, inside, stats->max_speed, 1e3 * moved,
                wall[wall.size() / 2]);
    wall.clear();
    output->add_surface("suction", sinew::capsule_surface(BleedingOrganScene::kSuctionRadius, 0.0,
                                                          {.position = s.suction_at(t).centre}));
    if (auto st = output->write(*sim, frame); !st) return fail(st.error().message());
  }
  std::printf("bleeding_kidney: wrote bleeding_kidney.pvd (kidney, fluid, suction) to %s\n", out.c_str());
  return 0;
}
