// stiffness_benchmark — how far a stiff hanging body sags against what the
// solver spends, and residual against time for plain sweeps and the
// Chebyshev accelerator (issue 11, part 5).
//
// The body: a block of nx x ny x nz cells of edge `dx` (6 tets per cell,
// distance + volume constraints from E and nu = 0.3, density 1000 kg/m^3)
// hanging from its top face (pinned, at y = 0) under gravity. Its static
// deflection is the mean vertical displacement of its bottom face after
// `frames` frames of 1/60 s.
//
//   bench_stiffness run [--cells NX,NY,NZ] [--dx M] [--E PA] [--substeps N]
//       [--iterations N] [--tol T] [--max-iterations N] [--check N]
//       [--budget MS] [--rho R] [--gamma G] [--delay S] [--frames N]
//       [--warm 0|1] [--damping K] [--material elastic|neo_hookean|stvk|corotational]
//       [--backend NAME] [--threads N] [--csv FILE]
//     one setting: prints (and appends to FILE) the deflection, the
//     median ms per frame over the last half of the frames, sweeps per
//     frame, the stop reason and the residual.
//   bench_stiffness trace [same options] --sweeps N --out FILE
//     residual against time within one frame: after the body has settled
//     (frames - 1 frames), runs the last frame's substep as 1, 2, 4, ...
//     sweeps up to N in residual mode with a tolerance of 0 (never met)
//     and the cap at that count, writing sweeps, ms, residual_rms.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "command_line.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace {

struct Options {
  int nx = 12, ny = 12, nz = 12;
  double dx = 0.01, young = 3e7, poisson = 0.3;
  int substeps = 1, iterations = 5, max_iterations = 200, check = 4, delay = 10, frames = 60, threads = 0;
  double tol = 0.0, budget = 0.0, rho = 0.0, gamma = 1.0;
  double damping = 0.0;  // velocity_damping [1/s]: settles soft bodies sooner, no effect on the statics
  bool warm = false;
  int sweeps = 256;
  std::string backend = "cpu", csv, out, mode = "run";
  std::string material = "elastic";  // or neo_hookean, stvk, corotational
};

sinew::SceneDesc make_scene(const Options& o) {
  sinew::TetBodyDesc body;
  body.mesh = *sinew::make_tet_grid({.nx = o.nx, .ny = o.ny, .nz = o.nz,
                                     .origin = {-0.5 * o.nx * o.dx, -o.ny * o.dx, -0.5 * o.nz * o.dx},
                                     .cell_size = {o.dx, o.dx, o.dx}});
  body.density = 1000.0;
  body.velocity_damping = o.damping;
  if (o.material == "elastic") {
    (void)body.set_elastic(o.young, o.poisson);
  } else {
    const auto m = o.material == "neo_hookean" ? sinew::TetMaterial::neo_hookean
                   : o.material == "stvk"      ? sinew::TetMaterial::stvk
                                               : sinew::TetMaterial::corotational;
    (void)body.set_material(m, o.young, o.poisson);
  }
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] > -1e-9) body.pinned.push_back(v);
  sinew::SceneDesc scene;
  scene.tet_bodies.push_back(std::move(body));
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = o.substeps;
  scene.solver.iterations = o.iterations;
  scene.solver.residual_tolerance = o.tol;
  scene.solver.max_iterations = std::max(o.max_iterations, o.iterations);
  scene.solver.check_interval = o.check;
  scene.solver.time_budget_ms = o.budget;
  scene.solver.chebyshev_rho = o.rho;
  scene.solver.chebyshev_gamma = o.gamma;
  scene.solver.chebyshev_delay = o.delay;
  scene.solver.warm_start = o.warm;
  return scene;
}

// Mean vertical displacement of the bottom face [m] (negative: down).
double deflection(const sinew::SceneDesc& scene, const std::vector<float>& x) {
  const auto& rest = scene.tet_bodies[0].mesh.vertices;
  double bottom = 1e9;
  for (const auto& p : rest) bottom = std::min(bottom, p[1]);
  double sum = 0.0;
  int n = 0;
  for (std::size_t v = 0; v < rest.size(); ++v)
    if (rest[v][1] < bottom + 1e-9) {
      sum += double(x[4 * v + 1]) - rest[v][1];
      ++n;
    }
  return sum / n;
}

const char* stop_name(sinew::SolveStop s) {
  switch (s) {
    case sinew::SolveStop::fixed: return "fixed";
    case sinew::SolveStop::converged: return "converged";
    case sinew::SolveStop::iteration_cap: return "cap";
    case sinew::SolveStop::time_budget: return "budget";
  }
  return "?";
}

int run(const Options& o) {
  const sinew::SceneDesc scene = make_scene(o);
  auto sim = sinew::Simulation::create(scene, {.backend = o.backend, .threads = o.threads, .quiet = true});
  if (!sim) {
    std::fprintf(stderr, "%s\n", sim.error().message().c_str());
    return 1;
  }
  std::vector<double> ms;
  std::vector<float> x;
  double sweeps = 0.0;
  for (int f = 0; f < o.frames; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    if (auto s = sim->step(); !s) {
      std::fprintf(stderr, "%s\n", s.error().message().c_str());
      return 1;
    }
    const auto t1 = std::chrono::steady_clock::now();
    if (std::getenv("STIFF_VERBOSE")) {
      (void)sim->read_positions(x);
      std::printf("  frame %d deflection %.6e residual %.3e sweeps %llu\n", f, deflection(scene, x),
                  sim->last_frame().residual_rms, static_cast<unsigned long long>(sim->last_frame().sweeps));
    }
    if (f >= o.frames / 2) {
      ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      sweeps += double(sim->last_frame().sweeps);
    }
  }
  (void)sim->read_positions(x);
  std::sort(ms.begin(), ms.end());
  const double median = ms.empty() ? 0.0 : ms[ms.size() / 2];
  const auto& st = sim->last_frame();
  const double d = deflection(scene, x);
  const double tets = double(scene.tet_bodies[0].mesh.tets.size());
  std::printf("%s E=%.0e dx=%.3f cells=%dx%dx%d tets=%.0f substeps=%d iterations=%d tol=%.1e rho=%.4f warm=%d: "
              "deflection %.6e m, %.3f ms/frame, %.1f sweeps/frame, stop %s, residual %.2e\n",
              o.material.c_str(), o.young, o.dx, o.nx, o.ny, o.nz, tets, o.substeps, o.iterations, o.tol, o.rho, int(o.warm), d,
              median, sweeps / std::max<std::size_t>(1, ms.size()), stop_name(st.stop), st.residual_rms);
  if (!o.csv.empty()) {
    std::ofstream f(o.csv, std::ios::app);
    f << o.material << ',' << o.young << ',' << o.dx << ',' << o.nx << ',' << o.ny << ',' << o.nz << ',' << tets << ','
      << o.substeps << ',' << o.iterations << ',' << o.tol << ',' << o.max_iterations << ',' << o.check << ','
      << o.budget << ',' << o.warm << ',' << o.rho << ',' << o.gamma << ',' << o.delay << ',' << o.frames << ',' << o.threads << ','
      << d << ',' << median << ',' << sweeps / std::max<std::size_t>(1, ms.size()) << ',' << stop_name(st.stop)
      << ',' << st.residual_rms << '\n';
  }
  return 0;
}

// Residual against time within one frame of the settled body.
int trace(Options o) {
  std::ofstream out(o.out, std::ios::app);
  for (int n = 1; n <= o.sweeps; n *= 2) {
    Options settled = o;
    settled.tol = 1e-30;  // never met: every frame runs to the cap
    settled.iterations = std::min(n, o.iterations);
    settled.max_iterations = n;
    settled.check = std::max(1, n - settled.iterations);
    sinew::SceneDesc scene = make_scene(settled);
    // Settle with the converged setting, then time the last frame alone.
    auto sim = sinew::Simulation::create(scene, {.backend = o.backend, .threads = o.threads, .quiet = true});
    if (!sim) {
      std::fprintf(stderr, "%s\n", sim.error().message().c_str());
      return 1;
    }
    std::vector<double> ms;
    double residual = 0.0;
    for (int f = 0; f < o.frames; ++f) {
      const auto t0 = std::chrono::steady_clock::now();
      if (auto s = sim->step(); !s) return 1;
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      residual = sim->last_frame().residual_rms;
    }
    std::sort(ms.begin(), ms.end());
    std::printf("rho=%.4f sweeps=%d ms=%.3f residual=%.3e\n", o.rho, n, ms[ms.size() / 2], residual);
    out << o.material << ',' << o.young << ',' << o.rho << ',' << o.gamma << ',' << o.delay << ',' << n << ','
        << ms[ms.size() / 2] << ',' << residual << '\n';
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  sinew::examples::CommandLine cli(
      "bench_stiffness",
      "How far a stiff hanging block sags against what the solver spends (6 tets per cell, distance + volume\n"
      "constraints or an FEM material, pinned at its top face). run: one setting; prints (and with --csv\n"
      "appends) the deflection, the median ms per frame over the last half, sweeps per frame, the stop reason\n"
      "and the residual. trace: the residual after frames of 1, 2, 4 ... --sweeps sweeps, into --out FILE.");
  using sinew::examples::at_least;
  using sinew::examples::greater_than;
  auto& app = cli.app();
  std::string cells = "12,12,12";
  app.add_option("mode", o.mode, "run or trace")->check(CLI::IsMember({"run", "trace"}));
  app.add_option("--cells", cells, "Cells along x, y, z")->type_name("NX,NY,NZ")->check([](const std::string& v) {
    int x = 0, y = 0, z = 0;
    char end = 0;
    if (std::sscanf(v.c_str(), "%d,%d,%d%c", &x, &y, &z, &end) == 3 && x >= 1 && y >= 1 && z >= 1) return std::string();
    return "must be three whole numbers >= 1, NX,NY,NZ (got " + v + ")";
  });
  app.add_option("--dx", o.dx, "Cell edge [m]")->check(greater_than(0));
  app.add_option("--E", o.young, "Young's modulus [Pa]")->check(greater_than(0));
  app.add_option("--nu", o.poisson, "Poisson's ratio")->check(at_least(0));
  app.add_option("--rho", o.rho, "Chebyshev spectral radius estimate (0: plain sweeps)")->check(at_least(0));
  app.add_option("--gamma", o.gamma, "Chebyshev under-relaxation")->check(greater_than(0));
  app.add_option("--delay", o.delay, "Sweeps before the Chebyshev acceleration starts")->check(at_least(0));
  app.add_option("--substeps", o.substeps, "Substeps per frame of 1/60 s")->check(at_least(1));
  app.add_option("--iterations", o.iterations, "Iterations per substep")->check(at_least(1));
  app.add_option("--tol", o.tol, "Residual tolerance (0: fixed iterations)")->check(at_least(0));
  app.add_option("--max-iterations", o.max_iterations, "Residual mode: most iterations per substep")->check(at_least(1));
  app.add_option("--check", o.check, "Residual mode: sweeps between residual checks")->check(at_least(1));
  app.add_option("--budget", o.budget, "Time budget per frame [ms] (0: none)")->check(at_least(0));
  app.add_option("--damping", o.damping, "Velocity damping [1/s]")->check(at_least(0));
  app.add_option("--frames", o.frames, "Frames of 1/60 s")->check(at_least(2));
  app.add_option("--warm", o.warm, "Warm-start the residual mode (0 or 1)");
  app.add_option("--material", o.material, "elastic (distance + volume) or an FEM material")
      ->check(CLI::IsMember({"elastic", "neo_hookean", "stvk", "corotational"}));
  cli.add_backend(o.backend);
  app.add_option("--threads", o.threads, "cpu backend worker threads (0: all)")->check(at_least(0));
  app.add_option("--csv", o.csv, "run: append the result row to this file")->type_name("FILE");
  app.add_option("--out", o.out, "trace: append the rows to this file")->type_name("FILE");
  app.add_option("--sweeps", o.sweeps, "trace: the most sweeps")->check(at_least(1));
  if (auto exit = cli.parse(argc, argv)) return *exit;
  std::sscanf(cells.c_str(), "%d,%d,%d", &o.nx, &o.ny, &o.nz);
  if (o.mode == "trace" && o.out.empty()) {
    std::fprintf(stderr, "bench_stiffness: trace needs --out FILE\n");
    return 2;
  }
  return o.mode == "trace" ? trace(o) : run(o);
}
