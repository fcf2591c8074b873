// organ_step — median wall time of Simulation::step() on a real organ mesh, in the mesher's vertex
// order, timed outside step(): how a frame costs on livers and kidneys, not only on the benchmark
// cube, and the projections per second that compare the two per constraint.
//
//   organ_step BACKEND MESH.node FRAMES [OPTIONS]   (organ_step --help: the options)
//   e.g. organ_step cpu build/data/meshes/tet/liver_382k.node 10 --errors
//   MESH.node may be cube:N, the benchmark cube of N^3 cells (100 mm wide) at the same settings.
//
// The mesh is in millimetres (scaled to metres), density 1060 kg/m^3, E = 30 kPa, nu = 0.45
// (distance + volume constraints, or the FEM material), pinned within 5 mm of its lowest x,
// 10 substeps x 1 iteration at 60 Hz unless told otherwise. --no-reorder keeps the particles in the
// mesher's order on the device (SolverSettings::reorder_particles = false), for before/after.
// Prints one CSV line after a header:
//   backend,mesh,material,reorder,particles,constraints,colors,median_ms,mprojections_per_s,min_ms,
//   cpu_ms (median process CPU time per frame), residual_rms,kinetic_energy,volume_change
// --sag adds the free end's sag: the mean drop [mm] under gravity of the vertices within 5 mm of the
// mesh's highest x after the last frame (sag_mm), and its largest over the frames (max_sag_mm); it reads
// the positions after every frame (outside the timing).
#include <sinew/simulation.h>

#include "command_line.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "organ_step",
      "Median wall time of Simulation::step() on a real organ mesh (millimetres, scaled to metres) in the\n"
      "mesher's vertex order: E = 30 kPa, nu = 0.45, pinned within 5 mm of its lowest x, 60 Hz frames.\n"
      "Prints one CSV line after a header (backend, mesh, material, reorder, particles, constraints, colors,\n"
      "median_ms, mprojections_per_s, min_ms, cpu_ms, residual_rms, kinetic_energy, volume_change).\n"
      "e.g. organ_step cpu build/data/meshes/tet/liver_382k.node 10 --errors");
  std::string backend, path, material = "none";
  int frames = 0, substeps = 10, iterations = 1, threads = 0;
  double damping = 0.0, tolerance = 0.0;
  bool errors = false, reorder = true, simd = true, sag = false;
  cli.app().add_option("backend", backend, "Backend: cpu, opencl, vulkan or auto")
      ->required()
      ->check(CLI::IsMember({"auto", "cpu", "opencl", "vulkan"}));
  cli.app().add_option("mesh", path, "The tet mesh (.node, .msh, .vtk), or cube:N (N^3 cells, 100 mm wide)")
      ->required();
  cli.app().add_option("frames", frames, "Frames of 1/60 s to time")->required()->check(sinew::examples::at_least(1));
  cli.app().add_flag("--errors", errors, "Measure the frame's errors (residual, energy, volume)");
  cli.app().add_flag("--sag", sag, "Also print the free end's sag under gravity [mm] (vertices within 5 mm of the highest x)");
  cli.app().add_option("--material", material, "none (distance + volume constraints) or an FEM material")
      ->check(CLI::IsMember({"none", "neo_hookean", "stvk", "corotational"}));
  cli.app().add_flag_callback("--no-reorder", [&reorder] { reorder = false; }, "Keep the mesher's particle order on the device");
  // cpu: the scalar reference solves (DeviceOptions::cpu_simd).
  cli.app().add_flag_callback("--no-simd", [&simd] { simd = false; }, "cpu backend: the scalar reference solves, no AVX2");
  cli.app().add_option("--substeps", substeps, "Substeps per frame")->check(sinew::examples::at_least(1));
  cli.app().add_option("--iterations", iterations, "Iterations per substep")->check(sinew::examples::at_least(1));
  cli.app().add_option("--velocity-damping", damping, "TetBodyDesc::velocity_damping [1/s]")->check(CLI::NonNegativeNumber);
  // The residual mode (SolverSettings::residual_tolerance, with the warm start for the edge network):
  // the statics of the material, the reference the fixed settings are compared with.
  cli.app().add_option("--tolerance", tolerance, "Residual mode: sweep each substep to this residual (0: fixed sweeps)")
      ->check(CLI::NonNegativeNumber);
  cli.app().add_option("--threads", threads, "cpu backend worker threads (0: all)")->check(sinew::examples::at_least(0));
  if (auto exit = cli.parse(argc, argv)) return *exit;
  if (path.rfind("cube:", 0) == 0 && std::atoi(path.c_str() + 5) < 1) {
    std::fprintf(stderr, "organ_step: cube:N needs N >= 1 (got %s)\n", path.c_str());
    return 2;
  }
  // "cube:N": the benchmark cube (bench_cube's mesh: N^3 cells of 6 tets, here 10 cm wide) at the
  // same settings, for the per-constraint comparison.
  auto mesh = path.rfind("cube:", 0) == 0
                  ? sinew::make_tet_grid({.nx = std::atoi(path.c_str() + 5), .ny = std::atoi(path.c_str() + 5),
                                          .nz = std::atoi(path.c_str() + 5), .origin = {0, 0, 0},
                                          .cell_size = {100.0 / std::atoi(path.c_str() + 5),
                                                        100.0 / std::atoi(path.c_str() + 5),
                                                        100.0 / std::atoi(path.c_str() + 5)}})
                  : sinew::read_tet_mesh(path);
  if (!mesh) {
    std::fprintf(stderr, "%s\n", mesh.error().message().c_str());
    return 1;
  }
  sinew::scale_mesh(*mesh, 1e-3);
  sinew::TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1060.0;
  body.velocity_damping = damping;
  sinew::Status made;
  if (material == "none") made = body.set_elastic(3e4, 0.45);
  else if (material == "neo_hookean") made = body.set_material(sinew::TetMaterial::neo_hookean, 3e4, 0.45);
  else if (material == "stvk") made = body.set_material(sinew::TetMaterial::stvk, 3e4, 0.45);
  else made = body.set_material(sinew::TetMaterial::corotational, 3e4, 0.45);  // the only other choice
  if (!made) {
    std::fprintf(stderr, "%s\n", made.error().message().c_str());
    return 1;
  }
  double lo = 1e30, hi = -1e30;
  for (const auto& v : body.mesh.vertices) lo = std::min(lo, v[0]), hi = std::max(hi, v[0]);
  std::vector<std::uint32_t> free_end;  // the vertices whose sag --sag reports
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v) {
    if (body.mesh.vertices[v][0] < lo + 0.005) body.pinned.push_back(v);
    if (body.mesh.vertices[v][0] > hi - 0.005) free_end.push_back(v);
  }
  double rest_y = 0.0;
  for (std::uint32_t v : free_end) rest_y += body.mesh.vertices[v][1] / double(free_end.size());
  sinew::SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = substeps;
  scene.solver.iterations = iterations;
  scene.solver.measure_errors = errors;
  scene.solver.reorder_particles = reorder;
  scene.solver.residual_tolerance = tolerance;
  scene.solver.max_iterations = std::max(iterations, 2000);
  scene.solver.warm_start = tolerance > 0.0 && material == "none";  // FEM materials have no warm start
  scene.tet_bodies.push_back(std::move(body));
  auto sim = sinew::Simulation::create(scene, {.backend = backend, .threads = threads, .cpu_simd = simd, .quiet = true});
  if (!sim) {
    std::fprintf(stderr, "%s\n", sim.error().message().c_str());
    return 1;
  }
  // Wall time, and the process's CPU time: with --threads 1 the latter is
  // the frame's cost without the time other jobs on a shared machine took.
  auto cpu_ms = [] {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
  };
  std::vector<double> t, cpu;
  std::vector<float> x;
  double sag_mm = 0.0, max_sag_mm = 0.0;
  for (int f = 0; f < frames; ++f) {
    const double c0 = cpu_ms();
    const auto a = std::chrono::steady_clock::now();
    if (auto s = sim->step(); !s) {
      std::fprintf(stderr, "%s\n", s.error().message().c_str());
      return 1;
    }
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
    cpu.push_back(cpu_ms() - c0);
    if (!sag) continue;
    if (auto r = sim->read_positions(x); !r) {
      std::fprintf(stderr, "%s\n", r.error().message().c_str());
      return 1;
    }
    double y = 0.0;
    for (std::uint32_t v : free_end) y += x[4 * v + 1] / double(free_end.size());
    sag_mm = 1e3 * (rest_y - y);
    max_sag_mm = std::max(max_sag_mm, sag_mm);
  }
  std::sort(t.begin(), t.end());
  std::sort(cpu.begin(), cpu.end());
  const double median = t[t.size() / 2];
  const sinew::SceneInfo& info = sim->info();
  const double projections = double(info.constraints()) * substeps * iterations;
  const auto& st = sim->last_frame();
  const char* name = std::strrchr(path.c_str(), '/');
  std::printf("backend,mesh,material,reorder,particles,constraints,colors,median_ms,mprojections_per_s,"
              "min_ms,cpu_ms,residual_rms,kinetic_energy,volume_change%s\n", sag ? ",sag_mm,max_sag_mm" : "");
  std::printf("%s,%s,%s,%d,%u,%u,%u,%.3f,%.1f,%.3f,%.3f,%.6e,%.6e,%.6e", backend.c_str(), name ? name + 1 : path.c_str(),
              material.c_str(), reorder ? 1 : 0, info.particles, info.constraints(), info.colors, median,
              projections / (median * 1e3), t.front(), cpu[cpu.size() / 2], st.residual_rms, st.kinetic_energy, st.volume_change);
  if (sag) std::printf(",%.3f,%.3f", sag_mm, max_sag_mm);
  std::printf("\n");
}
