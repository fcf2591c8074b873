// soak_dissection — a dissection scene run for minutes: a tissue pad with a
// membrane over it, mesh collision on, a grasper that closes, lifts and
// opens, cautery and blade strokes on both bodies every few frames, at
// random places (a fixed seed). When a third of either body is gone the
// Simulation is destroyed and made again (a new cycle).
//
// Checked every frame: step() succeeds, every position and the frame's
// statistics are finite. Checked every cycle: after its hundreds of
// removals and program rebuilds the device holds as many buffers and
// programs as the Simulation was made with (buffers only grow in place),
// and the process's resident memory is written down (flat across cycles:
// nothing leaks). Writes one CSV line per cycle and exits 1 on the first
// failure.
//
//   soak_dissection --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

#include "command_line.h"
#include "runtime/simulation_internals.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace {

constexpr double kCell = 2e-3;  // [m]
constexpr int kPad = 12;        // pad cells along x and z (4 through its height)

sinew::SceneDesc dissection() {
  sinew::SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 8, .iterations = 2};
  scene.topology_changes = true;
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 5e-4;
  scene.graspers.push_back({.capacity = 64, .compliance = 0.0});
  sinew::TetBodyDesc pad;
  pad.mesh = *sinew::make_tet_grid({.nx = kPad, .ny = 4, .nz = kPad, .origin = {0, 0, 0},
                                    .cell_size = {kCell, kCell, kCell}});
  (void)pad.set_material(sinew::TetMaterial::corotational, 2e4, 0.45);
  pad.velocity_damping = 2.0;
  for (std::uint32_t v = 0; v < pad.mesh.vertices.size(); ++v)
    if (pad.mesh.vertices[v][1] < 1e-9) pad.pinned.push_back(v);  // its bottom face
  scene.tet_bodies.push_back(pad);
  // The membrane: a sheet 1 mm over the pad, fastened along two opposite edges.
  sinew::TriBodyDesc sheet;
  constexpr int n = 2 * kPad;
  for (int i = 0; i <= n; ++i)
    for (int k = 0; k <= n; ++k) sheet.mesh.vertices.push_back({i * 0.5 * kCell, 4 * kCell + 1e-3, k * 0.5 * kCell});
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t a = i * (n + 1) + k, b = a + 1, c = a + n + 1, d = c + 1;
      sheet.mesh.triangles.push_back({a, b, d});
      sheet.mesh.triangles.push_back({a, d, c});
    }
  for (std::uint32_t v = 0; v < sheet.mesh.vertices.size(); ++v)
    if (v <= n || v >= n * (n + 1)) sheet.pinned.push_back(v);
  sheet.density = 1050.0;
  sheet.thickness = 1e-3;
  sheet.distance_compliance = 1.0 / 5e4;
  sheet.area_compliance = 1.0 / 5e4;
  sheet.velocity_damping = 2.0;
  scene.tri_bodies.push_back(sheet);
  return scene;
}

long resident_kb() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

bool finite(const std::vector<float>& x) {
  for (float v : x)
    if (!std::isfinite(v)) return false;
  return true;
}

int fail(const std::string& why) {
  std::fprintf(stderr, "soak_dissection: %s\n", why.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "soak_dissection",
      "A dissection scene run for minutes (a tissue pad with a membrane, mesh collision, a grasper, cautery and\n"
      "blade strokes at random places); the Simulation is made again when a third of a body is gone. Checks\n"
      "every frame finite and that nothing leaks across cycles; writes one CSV line per cycle; exits 1 on the\n"
      "first failure.");
  std::string backend = "cpu", csv = "soak_dissection.csv";
  double minutes = 10.0;
  unsigned seed = 1;
  cli.add_backend(backend);
  cli.app().add_option("--minutes", minutes, "How long to run [min]")->check(sinew::examples::greater_than(0));
  cli.app().add_option("--seed", seed, "Seed of the random places");
  cli.app().add_option("--csv", csv, "The per-cycle CSV file")->type_name("FILE");
  if (auto exit = cli.parse(argc, argv)) return *exit;
  std::FILE* out = std::fopen(csv.c_str(), "w");
  if (!out) return fail("cannot write " + csv);
  std::fprintf(out, "cycle,frames,events,pad_tets_left,sheet_triangles_left,resident_kb,device_buffers,device_bytes,"
                    "device_programs,median_frame_ms\n");

  std::mt19937 random(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const sinew::SceneDesc scene = dissection();
  const double side = kPad * kCell;
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_min = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / 60.0;
  };
  long first_kb = 0, last_kb = 0;
  sinew::DeviceObjects first_objects;
  std::uint64_t total_frames = 0, total_events = 0;
  for (int cycle = 0; elapsed_min() < minutes; ++cycle) {
    auto sim = sinew::Simulation::create(scene, {.backend = backend, .quiet = true});
    if (!sim) return fail(sim.error().message());
    const sinew::DeviceObjects objects = sinew::SimulationInternals::device(*sim).objects();
    sinew::Topology topology = sim->topology();
    const auto pad = *topology.tet_body(0);
    const auto sheet = *topology.tri_body(0);
    const auto grasper = *sim->graspers().grasper(0);
    const std::size_t pad_tets = scene.tet_bodies[0].mesh.tets.size();
    const std::size_t sheet_triangles = scene.tri_bodies[0].mesh.triangles.size();
    std::size_t tets_left = pad_tets, triangles_left = sheet_triangles;
    std::vector<float> x;
    std::vector<double> frame_ms;
    int frames = 0, events = 0, held_since = -1;
    sinew::Pose jaws;
    while (3 * tets_left > 2 * pad_tets && 3 * triangles_left > 2 * sheet_triangles && elapsed_min() < minutes) {
      const double r = u(random);
      const std::array<double, 3> at{side * u(random), 4 * kCell + 1e-3, side * u(random)};
      sinew::Result<sinew::TopologyEvent> event = sinew::TopologyEvent{};
      if (frames % 3 == 0 && r < 0.5) {  // a blade stroke across the sheet, or into the pad
        const sinew::Blade from{{at[0], at[1] + 2e-3, at[2]}, {at[0], at[1] - (r < 0.25 ? 4e-3 : 0.5e-3), at[2]}};
        const sinew::Blade to{{at[0] + 3e-3, from.a[1], at[2] + 2e-3}, {at[0] + 3e-3, from.b[1], at[2] + 2e-3}};
        event = r < 0.25 ? topology.cut(pad, from, to) : topology.cut(sheet, from, to);
      } else if (frames % 3 == 0) {  // a cautery tip on the sheet, or on the pad's top (burns at once)
        event = r < 0.75 ? topology.cauterize(sheet, at, 1.5e-3, 1.0 / 60.0, 1.0 / 60.0)
                         : topology.cauterize(pad, {at[0], 4 * kCell, at[2]}, 1.5e-3, 1.0 / 60.0, 1.0 / 60.0);
      }
      if (!event) return fail("cycle " + std::to_string(cycle) + ": " + event.error().message());
      if (!event->tets_removed.empty() || !event->triangles_removed.empty()) ++events;
      tets_left -= event->tets_removed.size();
      triangles_left -= event->triangles_removed.size();
      // The grasper: closes somewhere on the sheet, lifts 5 mm over 30 frames, opens.
      if (held_since < 0 && frames % 40 == 5) {
        jaws.position = at;
        auto held = sim->graspers().close(grasper, jaws, {2e-3, 1.5e-3, 2e-3});
        if (!held) return fail("grasp: " + held.error().message());
        held_since = frames;
      } else if (held_since >= 0 && frames - held_since < 30) {
        jaws.position[1] += 5e-3 / 30;
        if (auto s = sim->graspers().move(grasper, jaws); !s) return fail("move: " + s.error().message());
      } else if (held_since >= 0) {
        if (auto s = sim->graspers().open(grasper); !s) return fail("open: " + s.error().message());
        held_since = -1;
      }
      if (auto s = sim->step(); !s) return fail("cycle " + std::to_string(cycle) + " frame " +
                                                std::to_string(frames) + ": " + s.error().message());
      const sinew::FrameStats& st = sim->last_frame();
      frame_ms.push_back(st.wall_ms);
      if (!std::isfinite(st.residual_rms) || !std::isfinite(st.kinetic_energy) || !std::isfinite(st.volume_change))
        return fail("cycle " + std::to_string(cycle) + " frame " + std::to_string(frames) + ": statistics not finite");
      if (auto s = sim->read_positions(x); !s || !finite(x))
        return fail("cycle " + std::to_string(cycle) + " frame " + std::to_string(frames) + ": positions not finite");
      ++frames;
    }
    std::sort(frame_ms.begin(), frame_ms.end());
    const sinew::DeviceObjects end = sinew::SimulationInternals::device(*sim).objects();
    const long kb = resident_kb();
    if (cycle == 0) first_kb = kb, first_objects = objects;
    last_kb = kb;
    std::fprintf(out, "%d,%d,%d,%zu,%zu,%ld,%u,%llu,%u,%.3f\n", cycle, frames, events, tets_left, triangles_left, kb,
                 end.buffers, static_cast<unsigned long long>(end.buffer_bytes), end.programs,
                 frame_ms.empty() ? 0.0 : frame_ms[frame_ms.size() / 2]);
    std::fflush(out);
    std::printf("cycle %3d  %4d frames  %3d events  pad %zu/%zu tets, sheet %zu/%zu triangles left  resident %ld kB  "
                "%.1f min\n",
                cycle, frames, events, tets_left, pad_tets, triangles_left, sheet_triangles, kb, elapsed_min());
    total_frames += frames;
    total_events += events;
    if (end.buffers != objects.buffers || end.programs != objects.programs)
      return fail("cycle " + std::to_string(cycle) + ": the device holds " + std::to_string(end.buffers) +
                  " buffers and " + std::to_string(end.programs) + " programs, made with " +
                  std::to_string(objects.buffers) + " and " + std::to_string(objects.programs));
    if (objects.buffers != first_objects.buffers || objects.buffer_bytes != first_objects.buffer_bytes)
      return fail("cycle " + std::to_string(cycle) + ": the same scene made a different device state");
  }
  std::fclose(out);
  const long growth = last_kb - first_kb;
  std::printf("soak: %llu frames, %llu topology events, every frame finite; resident memory at the last cycle's end "
              "%+ld kB from the first's\n",
              static_cast<unsigned long long>(total_frames), static_cast<unsigned long long>(total_events), growth);
  return 0;
}
