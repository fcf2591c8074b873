// bleeding — blood from a cut vessel fills a cavity in tissue, and a
// suction tip removes it (issue 15's example). The tissue is a 32 x 12 x
// 32 mm block pinned at its base with a 20 x 8 x 20 mm pit carved in its
// top (a tet grid of 2 mm cells); its surface carries the fluid's boundary
// particles and is pushed by the blood (SceneDesc::fluid: two-way,
// momentum-conserving, run on the scene's device as a stage of its frame). A source on the pit's wall bleeds a pulsing 1 ml/s
// (the heart's 72 beats a minute, +-50%); at 1.5 s a suction tip (a sink
// of 3 mm radius) comes down into the pool and sweeps it.
//
// Prints every 0.1 s: the particles, the blood made and removed [ml], the
// mass books (particles - made + removed - initial: always 0), the blood's
// compressibility error (the densest particle's rho / rho0 - 1) and its
// Mach number, the wall time per 2 ms frame of the fluid's stage and of the
// rest of the frame (the tissue's). Writes bleeding.pvd for ParaView
// (sinew/vtk_output.h): fluid_N.vtu (density, pressure, velocity per
// particle), tissue_N.vtu and suction_N.vtu (the tip's ball).
//
//   bleeding --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/mesh.h"
#include "sinew/display_surfaces.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace {

constexpr double kCell = 2e-3;     // the tissue's tet grid [m]
constexpr double kSpacing = 1e-3;  // the blood's particles [m]
constexpr double kFrame = 2e-3;    // the tissue's frame [s]
constexpr double kPi = 3.14159265358979323846;

int fail(const std::string& what) {
  std::fprintf(stderr, "bleeding: %s\n", what.c_str());
  return 1;
}

// The block with the pit carved: cells [3, 13) x [2, 6) x [3, 13) removed.
sinew::Result<sinew::TetMesh> tissue_block() {
  auto grid = sinew::make_tet_grid({.nx = 16, .ny = 6, .nz = 16, .cell_size = {kCell, kCell, kCell}});
  if (!grid) return grid.error();
  sinew::TetMesh carved;
  carved.vertices = grid->vertices;
  for (const auto& t : grid->tets) {
    std::array<double, 3> c{};
    for (std::uint32_t v : t)
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * grid->vertices[v][a] / kCell;
    if (c[0] > 3 && c[0] < 13 && c[2] > 3 && c[2] < 13 && c[1] > 2) continue;
    carved.tets.push_back(t);
  }
  return sinew::drop_unused_vertices(carved);
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "bleeding",
      "Blood from a cut vessel fills a pit in a block of tissue (SPH coupled both ways with the tissue), and\n"
      "from 1.5 s a suction tip removes it. Prints every --every frames (of 2 ms) the particles, the blood\n"
      "made and removed, the mass books, the compressibility error and the wall time per frame; writes\n"
      "bleeding.pvd (the tissue, the blood and the suction tip, frame 0 on) into --out.");
  using sinew::examples::at_least;
  std::string backend = "auto", out = cli.default_out();
  double seconds = 3.0, flow_ml = 1.0;
  int every = 25;
  cli.add_backend(backend);
  cli.app().add_option("--seconds", seconds, "Simulated time [s]")->check(sinew::examples::greater_than(0));
  cli.app().add_option("--flow", flow_ml, "The vessel's mean flow [ml/s] (pulsing +-50% at 72 beats a minute)")
      ->check(at_least(0));
  cli.app().add_option("--every", every, "Report and write the VTU files every N frames of 2 ms (and the last)")
      ->check(at_least(1));
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;

  // The tissue: 20 kPa, pinned at its base.
  auto mesh = tissue_block();
  if (!mesh) return fail(mesh.error().message());
  sinew::SceneDesc scene;
  sinew::TetBodyDesc body;
  body.mesh = *mesh;
  body.density = 1060.0;
  if (auto s = body.set_elastic(2e4, 0.45); !s) return fail(s.error().message());
  body.stiffness_damping = 0.01;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] < 1e-9) body.pinned.push_back(v);
  // The surface the blood can reach: the pit's walls and floor and the
  // block's top (y = 12 mm); its sides and base get no boundary particles.
  sinew::TriMesh surface = sinew::extract_boundary_surface(body.mesh);
  std::erase_if(surface.triangles, [&](const std::array<std::uint32_t, 3>& t) {
    std::array<double, 3> c{};
    for (std::uint32_t v : t)
      for (int a = 0; a < 3; ++a) c[a] += surface.vertices[v][a] / 3.0;
    const bool pit = c[0] > 5.9e-3 && c[0] < 26.1e-3 && c[2] > 5.9e-3 && c[2] < 26.1e-3 && c[1] > 3.9e-3;
    return !pit && c[1] < 11.9e-3;
  });
  scene.tet_bodies.push_back(body);
  scene.solver.time_step = kFrame;
  scene.solver.substeps = 4;
  scene.solver.iterations = 8;

  // The blood: c0 = 5 m/s for flows up to about 0.5 m/s (density within
  // about 1%), 16 steps of 1.25e-4 s per frame (the CFL bound at rest is 1.6e-4).
  sinew::SceneFluidDesc blood;
  blood.fluid.settings.spacing = kSpacing;
  blood.fluid.settings.rest_density = 1060.0;
  blood.fluid.settings.speed_of_sound = 5.0;
  blood.fluid.settings.time_step = 1.25e-4;
  blood.fluid.settings.viscosity = 0.2;
  blood.fluid.capacity = 8000;  // 1.5 ml/s at the pulse's peak for 3 s is 4,500 particles
  // The cut vessel: a 1.5 mm disc 1.5 mm off the pit's wall at x = 6 mm, bleeding into the pit.
  sinew::FluidEmitter vessel{.centre = {7.5e-3, 9e-3, 16e-3}, .direction = {1, -0.3, 0},
                             .radius = 1.5e-3, .flow_rate = flow_ml * 1e-6};
  blood.fluid.emitters.push_back(vessel);
  const std::array<double, 3> parked{0.0, 1.0, 0.0};  // the suction tip's place before it comes in
  blood.fluid.sinks.push_back({.centre = parked, .radius = 3e-3});
  blood.surfaces.push_back({.body_kind = sinew::BodyKind::tet, .body = 0, .triangles = surface.triangles});
  scene.fluid = blood;
  auto sim = sinew::Simulation::create(scene, {.backend = backend});
  if (!sim) return fail(sim.error().message());
  sinew::SceneFluid fluid = sim->fluid();
  const auto fluid_info = fluid.info();
  if (!fluid_info) return fail(fluid_info.error().message());
  std::printf("bleeding: %s; tissue %zu tets, %u particles; %u boundary particles on its surface; blood up to %u particles\n",
              sim->device_name().c_str(), mesh->tets.size(), sim->info().particles, fluid_info->coupled_boundary,
              fluid_info->capacity);
  std::printf("   t [s]  particles  made [ml]  removed [ml]  books  rho err  Mach   fluid ms  tissue ms\n");

  const int frames = static_cast<int>(std::lround(seconds / kFrame));
  const double ml = kSpacing * kSpacing * kSpacing * 1e6;
  // The tissue is named as in scenes/bleeding.json: the runner's output of it is the same.
  auto output = sinew::SceneOutput::create(scene, out, {.bodies = {{.name = "tissue"}}, .name = "bleeding"});
  if (!output) return fail(output.error().message());
  output->add_surface("suction", sinew::capsule_surface(3e-3, 0.0, {.position = parked}));
  if (auto s = output->write(*sim, 0); !s) return fail(s.error().message());
  std::vector<sinew::FluidParticle> q;
  int written = 1;
  std::vector<double> fluid_ms, tissue_ms;
  for (int frame = 1; frame <= frames; ++frame) {
    const double t = frame * kFrame;
    // The heart beats: the flow pulses at 1.2 Hz, +-50%.
    vessel.flow_rate = flow_ml * 1e-6 * (1.0 + 0.5 * std::sin(2.0 * kPi * 1.2 * t));
    if (auto s = fluid.set_emitter(0, vessel); !s) return fail(s.error().message());
    // Suction: from 1.5 s the tip comes down 8 mm into the pit's far half
    // in 0.3 s and sweeps across it along z and back, 1 mm above the floor.
    std::array<double, 3> tip = parked;
    if (t >= 1.5) {
      const double down = std::min((t - 1.5) / 0.3, 1.0), sweep = std::max(t - 1.8, 0.0);
      tip = {20e-3, 16e-3 - 8e-3 * down, 16e-3 + 6e-3 * std::sin(2.0 * kPi * 0.5 * sweep)};
    }
    if (auto s = fluid.set_sink(0, {.centre = tip, .radius = 3e-3}); !s) return fail(s.error().message());
    if (auto s = sim->step(); !s) return fail(s.error().message());
    const double fluid_stage_ms = sim->last_frame().stage_ms("fluid");
    fluid_ms.push_back(fluid_stage_ms);
    tissue_ms.push_back(sim->last_frame().wall_ms - fluid_stage_ms);
    if (frame % every != 0 && frame != frames) continue;

    if (auto s = fluid.read(q); !s) return fail(s.error().message());
    const auto stats = fluid.stats();
    if (!stats) return fail(stats.error().message());
    const sinew::FluidStats& st = *stats;
    double densest = 0.0;
    for (const auto& p : q) densest = std::max(densest, double(p.density) / 1060.0 - 1.0);
    const long long books = static_cast<long long>(st.particles) - static_cast<long long>(st.emitted) +
                            static_cast<long long>(st.removed);
    auto median = [](std::vector<double> v) {
      std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    std::printf("  %6.2f  %9u  %9.3f  %12.3f  %5lld  %6.2f%%  %5.3f  %8.2f  %9.2f\n", t, st.particles,
                double(st.emitted) * ml, double(st.removed) * ml, books, 100.0 * densest, st.max_speed / 5.0,
                median(fluid_ms), median(tissue_ms));
    fluid_ms.clear(), tissue_ms.clear();
    output->add_surface("suction", sinew::capsule_surface(3e-3, 0.0, {.position = tip}));
    if (auto s = output->write(*sim, frame); !s) return fail(s.error().message());
    ++written;
  }
  std::printf("bleeding: wrote %d frames of bleeding.pvd (tissue, fluid, suction) to %s\n", written, out.c_str());
  return 0;
}
