// organ_contact — tissue against tissue on the real organ meshes: a probe
// (a kinematic capsule) presses the kidney down onto the liver and slides
// it along the liver's surface. Both organs are tet bodies (the meshes
// under data/meshes/tet, mesher's order, millimetres scaled to metres);
// they touch through their boundary surfaces (SceneDesc::mesh_collision:
// vertex-triangle and edge-edge contacts found each frame, solved colour by
// colour in every sweep). The liver is pinned along its lowest fifth.
// Writes organ_contact.pvd (the liver, the kidney and the probe as
// collider0, from frame 0) and prints per frame the wall time, the collision's share, the
// contacts and their colours, and the deepest contact violation: while it
// stays below the thickness the surfaces have not passed through each other.
//
//   organ_contact --help   (the options, their defaults and units)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace {

struct Box {
  std::array<double, 3> lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
};

Box bounds(const sinew::TetMesh& m) {
  Box b;
  for (const auto& v : m.vertices)
    for (int k = 0; k < 3; ++k) b.lo[k] = std::min(b.lo[k], v[k]), b.hi[k] = std::max(b.hi[k], v[k]);
  return b;
}

sinew::Result<sinew::TetMesh> organ(const char* name) {
  auto m = sinew::read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/" + name + ".node");
  if (m) sinew::scale_mesh(*m, 1e-3);  // the meshes are in millimetres
  return m;
}

// The process's CPU time [ms]: with --threads 1, a frame's cost without the
// time other jobs on a shared machine took.
double cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

// The value at fraction q (0.5: the median) of [in,out] v, sorted here.
double quantile(std::vector<double>& v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[std::min(v.size() - 1, std::size_t(q * double(v.size())))];
}

int fail(const sinew::Error& e) {
  std::fprintf(stderr, "organ_contact: %s\n", e.message().c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "organ_contact",
      "Tissue against tissue on the real organ meshes: a probe (a kinematic capsule) presses the kidney\n"
      "down onto the liver and slides it along the liver's surface (mesh collision between the two tet\n"
      "bodies). Prints per reported frame the wall time, the collision's share, the contacts and the deepest\n"
      "contact violation; writes organ_contact.pvd (liver, kidney, probe) into --out.");
  using sinew::examples::at_least;
  using sinew::examples::greater_than;
  std::string backend = "auto", out = cli.default_out();
  int frames = 60;
  bool self_collision = false, self_culling = true, continuous = false;
  double thickness_mm = 1.0;
  int every = 10, threads = 0;
  cli.add_backend(backend);
  cli.app().add_option("--threads", threads, "cpu backend worker threads (0: all)")->check(at_least(0));
  cli.app().add_option("--frames", frames, "Frames of 1/60 s to run")->check(at_least(1));
  cli.app().add_option("--every", every, "Report and write the VTU files every N frames (and the last)")
      ->check(at_least(1));
  cli.app().add_option("--thickness", thickness_mm, "Contact thickness of the surfaces [mm]")->check(greater_than(0));
  cli.add_switch("--self-collision", self_collision, "Each organ's surface also against itself");
  cli.add_switch("--self-culling", self_culling, "Normal-cone culling of the self-collision pairs");
  cli.add_switch("--continuous", continuous,
                 "The probe's axis against the organs' surfaces by CCD after every substep");
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;
  auto liver = organ("liver_382k");
  if (!liver) return fail(liver.error());
  auto kidney = organ("kidney_57k");
  if (!kidney) return fail(kidney.error());

  // The kidney above the middle of the liver, 3 mm clear of the liver's
  // highest point under the kidney's footprint.
  const Box lb = bounds(*liver), kb0 = bounds(*kidney);
  const double cx = 0.5 * (lb.lo[0] + lb.hi[0]), cz = 0.5 * (lb.lo[2] + lb.hi[2]);
  const double hx = 0.5 * (kb0.hi[0] - kb0.lo[0]), hz = 0.5 * (kb0.hi[2] - kb0.lo[2]);
  double under = lb.lo[1];
  for (const auto& v : liver->vertices)
    if (std::abs(v[0] - cx) <= hx && std::abs(v[2] - cz) <= hz) under = std::max(under, v[1]);
  const std::array<double, 3> shift{cx - 0.5 * (kb0.lo[0] + kb0.hi[0]), under + 0.003 - kb0.lo[1],
                                    cz - 0.5 * (kb0.lo[2] + kb0.hi[2])};
  for (auto& v : kidney->vertices)
    for (int k = 0; k < 3; ++k) v[k] += shift[k];

  sinew::SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 5;
  scene.solver.measure_errors = false;
  // No gravity: the organs lie supported in the abdomen, and the probe's
  // push is what brings them together (with gravity the jelly-soft liver,
  // pinned only at its base, would sag as a whole at tens of cm/s).
  scene.gravity = {0.0, 0.0, 0.0};
  for (auto* mesh : {&*liver, &*kidney}) {
    sinew::TetBodyDesc body;
    body.mesh = *mesh;
    if (auto s = body.set_elastic(5e4, 0.4); !s) return fail(s.error());  // soft tissue, 50 kPa
    body.density = 1060.0;
    body.velocity_damping = 5.0;
    scene.tet_bodies.push_back(std::move(body));
  }
  for (std::uint32_t v = 0; v < liver->vertices.size(); ++v)
    if (liver->vertices[v][1] < lb.lo[1] + 0.2 * (lb.hi[1] - lb.lo[1])) scene.tet_bodies[0].pinned.push_back(v);
  scene.mesh_collision.enabled = true;
  scene.mesh_collision.thickness = 1e-3 * thickness_mm;  // check_scene rejects a bad one
  // Organ against organ only by default; with --self-collision on each
  // organ's surface also against itself (--self-culling off: without the
  // normal cones, to measure what they save).
  scene.mesh_collision.self_collision = self_collision;
  scene.mesh_collision.self_culling = self_culling;
  // With --continuous on, the probe's axis can never pass through either
  // surface, however fast it moves (MeshCollisionDesc::continuous).
  scene.mesh_collision.continuous = continuous;
  // The probe: a capsule of radius 8 mm lying along x, starting 1 cm above the kidney.
  sinew::ColliderDesc probe;
  probe.shape = sinew::ColliderShape::capsule;
  probe.radius = 0.008;
  probe.half_height = 0.02;
  const double s = std::sqrt(0.5);
  probe.rotation = {s, 0.0, 0.0, s};  // y axis onto x
  // Above the kidney's highest point.
  std::array<double, 3> top = kidney->vertices.front();
  for (const auto& v : kidney->vertices)
    if (v[1] > top[1]) top = v;
  const std::array<double, 3> start{top[0], top[1] + probe.radius + 0.005, top[2]};
  probe.position = start;
  scene.colliders.push_back(probe);

  auto sim = sinew::Simulation::create(scene, {.backend = backend, .threads = threads});
  if (!sim) return fail(sim.error());
  const auto probe_id = sim->tools().collider(0);
  if (!probe_id) return fail(probe_id.error());
  std::printf("%s on %s: liver %zu tets, kidney %zu tets, %u particles\n", backend.c_str(),
              sim->device_name().c_str(), liver->tets.size(), kidney->tets.size(), sim->info().particles);
  auto output = sinew::SceneOutput::create(
      scene, out, {.bodies = {{.index = 0, .name = "liver"}, {.index = 1, .name = "kidney"}}, .name = "organ_contact"});
  if (!output) return fail(output.error());
  if (auto w = output->write(*sim, 0); !w) return fail(w.error());
  double worst = 0.0, total_ms = 0.0, collision_ms = 0.0, ccd_ms = 0.0;
  std::vector<double> wall, cpu;                   // per frame [ms]
  std::map<std::string, std::vector<double>> stage;  // per stage, per frame [ms]
  for (int f = 0; f < frames; ++f) {
    // Down by 2 cm over the first quarter (the probe starts 5 mm above the
    // kidney, the kidney 3 mm above the liver: it is pressed about 1.2 cm
    // into the liver's surface), then 3 cm along x.
    const double press = std::min(1.0, (f + 1) / (0.25 * frames)), slide = std::max(0.0, (f + 1 - 0.25 * frames) / (0.75 * frames));
    const sinew::Pose probe_pose{.position = {start[0] + 0.03 * slide, start[1] - 0.02 * press, start[2]},
                                 .rotation = probe.rotation};
    if (auto st = sim->tools().set_pose(*probe_id, probe_pose.position, probe_pose.rotation); !st)
      return fail(st.error());
    const double c0 = cpu_ms();
    if (auto st = sim->step(); !st) return fail(st.error());
    cpu.push_back(cpu_ms() - c0);
    const sinew::FrameStats& st = sim->last_frame();
    wall.push_back(st.wall_ms);
    for (const auto& p : st.stages) stage[p.name].push_back(p.ms);
    total_ms += st.wall_ms;
    collision_ms += st.collision_ms;
    ccd_ms += st.ccd_ms;
    worst = std::max(worst, st.contact_violation);

    if ((f + 1) % every != 0 && f + 1 != frames) continue;
    if (auto w = output->write(*sim, f + 1); !w) return fail(w.error());
    std::printf("frame %4d  %.1f ms (collision %.1f, CCD %.1f)  %u contacts in %u colours  contact violation %.3f mm "
                "(thickness %g mm)\n",
                f + 1, st.wall_ms, st.collision_ms, st.ccd_ms, st.mesh_contacts, st.mesh_contact_colors,
                1e3 * st.contact_violation, thickness_mm);
  }
  std::printf("mean %.1f ms/frame, of which collision %.1f and CCD %.1f; deepest contact violation %.3f mm: %s\n",
              total_ms / frames, collision_ms / frames, ccd_ms / frames, 1e3 * worst,
              worst < scene.mesh_collision.thickness ? "the organs never passed through each other"
                                                      : "the organs came closer than the thickness allows");
  std::printf("frame wall time: median %.1f ms, p95 %.1f, worst %.1f; process CPU time: median %.1f ms\n",
              quantile(wall, 0.5), quantile(wall, 0.95), quantile(wall, 1.0), quantile(cpu, 0.5));
  std::printf("stages, median ms per frame:");
  for (auto& [name, ms] : stage) std::printf("  %s %.2f", name.c_str(), quantile(ms, 0.5));
  std::printf("\n");
  std::printf("open %s/organ_contact.pvd in ParaView\n", out.c_str());
  return 0;
}
