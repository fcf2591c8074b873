// vbd_benchmark — error against cost of Vertex Block Descent (SolverSettings::
// method = vbd; Chen et al., "Vertex Block Descent", ACM TOG 43(4), SIGGRAPH
// 2024) and of xPBD on stiff bodies (issue 40's goals), CPU backend.
//
// Cases:
//  beam    E = 30 MPa, nu = 0.3, 1000 kg/m^3, 16 x 2 x 2 cells of 1 cm (two
//          elements through its 2 cm thickness), pinned at x = 0, sagging
//          under gravity from rest; the tip (mean vertical displacement of the
//          x = 16 cm face) after `frames` frames of 1/60 s, against the static
//          solution of linear elasticity on the same mesh
//          (tests/linear_elastic_oracle.h).
//  kidney  kidney_57k (mm scaled to m, the mesher's order), 1060 kg/m^3,
//          nu = 0.45, E = --E (20 kPa), pinned within 5 mm of its lowest x
//          (organ_step's pins); the sag is the mean drop of the vertices within
//          5 mm of its highest x after `frames` frames, against --reference
//          [m] (the converged sag, from a run with many sweeps).
// Solvers (--solver):
//  vbd           corotational material, Vertex Block Descent, `iterations`
//                sweeps per substep (--rho: Chebyshev);
//  corotational  the same material with xPBD, substeps x iterations;
//  network       set_elastic(E, nu) distance + volume constraints with xPBD in
//                the residual mode with warm start (--tol, --max-iterations),
//                docs/tissue.md's recommendation for stiff bodies.
//
//   bench_vbd beam|kidney [--solver vbd|corotational|network] [--substeps N]
//       [--iterations N] [--rho R] [--delay S] [--frames N] [--damping K]
//       [--tol T] [--max-iterations N] [--E PA] [--reference M]
//       [--repeats N] [--threads N] [--csv FILE]
// prints (and appends to FILE) one CSV row: the case, the settings, the
// measured displacement and the oracle's or reference's, the error [%], and
// the median over `repeats` runs of each run's median ms per frame (wall
// time of step(), all frames).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "command_line.h"
#include "kidney_case.h"
#include "linear_elastic_oracle.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace {

using sinew::Vec3d;

struct Options {
  std::string kase = "beam", solver = "vbd", csv;
  int substeps = 1, iterations = 20, frames = 120, repeats = 3, threads = 0, delay = 2, max_iterations = 2000;
  double rho = 0.0, damping = 0.0, tol = 6e-5, young = 0.0, reference = 0.0;
};

// The body's mesh, pins and the vertices whose mean vertical displacement is measured.
struct Body {
  sinew::TetMesh mesh;
  std::vector<std::uint32_t> pinned, measured;
  double density = 1000.0, poisson = 0.3;
};

Body beam() {
  Body b;
  b.mesh = *sinew::make_tet_grid({.nx = 16, .ny = 2, .nz = 2, .origin = {0, 0, 0}, .cell_size = {0.01, 0.01, 0.01}});
  for (std::uint32_t v = 0; v < b.mesh.vertices.size(); ++v) {
    if (b.mesh.vertices[v][0] < 1e-9) b.pinned.push_back(v);
    if (b.mesh.vertices[v][0] > 0.16 - 1e-9) b.measured.push_back(v);
  }
  return b;
}

Body kidney() {
  Body b;
  sinew::test::Kidney k = sinew::test::kidney_case();
  if (!k.error.empty()) std::fprintf(stderr, "%s\n", k.error.c_str());
  b.mesh = std::move(k.mesh);
  b.pinned = std::move(k.pinned);
  b.measured = std::move(k.free_end);
  b.density = 1060.0;
  b.poisson = 0.45;
  return b;
}

sinew::SceneDesc make_scene(const Options& o, const Body& b) {
  sinew::TetBodyDesc body;
  body.mesh = b.mesh;
  body.density = b.density;
  body.pinned = b.pinned;
  body.velocity_damping = o.damping;
  sinew::SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = o.substeps;
  scene.solver.iterations = o.iterations;
  scene.solver.measure_errors = false;
  if (o.solver == "network") {
    (void)body.set_elastic(o.young, b.poisson);
    scene.solver.residual_tolerance = o.tol;
    scene.solver.max_iterations = std::max(o.max_iterations, o.iterations);
    scene.solver.warm_start = true;
  } else {
    (void)body.set_material(sinew::TetMaterial::corotational, o.young, b.poisson);
    if (o.solver == "vbd") scene.solver.method = sinew::SolverMethod::vbd;
    scene.solver.chebyshev_rho = o.rho;
    scene.solver.chebyshev_delay = o.delay;
  }
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

double mean_drop(const Body& b, const std::vector<float>& x) {
  double sum = 0.0;
  for (std::uint32_t v : b.measured) sum += double(x[4 * v + 1]) - b.mesh.vertices[v][1];
  return sum / double(b.measured.size());
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  sinew::examples::CommandLine cli("bench_vbd", "Error against ms per frame of Vertex Block Descent and xPBD on a "
                                                "stiff beam (against linear elasticity) and on kidney_57k.");
  CLI::App& app = cli.app();
  using sinew::examples::at_least;
  app.add_option("case", o.kase, "beam or kidney")->check(CLI::IsMember({"beam", "kidney"}));
  app.add_option("--solver", o.solver, "vbd, corotational (xPBD) or network (set_elastic, residual mode, warm start)")
      ->check(CLI::IsMember({"vbd", "corotational", "network"}));
  app.add_option("--substeps", o.substeps, "Substeps per frame of 1/60 s")->check(at_least(1));
  app.add_option("--iterations", o.iterations, "Sweeps per substep (network: before the first residual check)")
      ->check(at_least(1));
  app.add_option("--rho", o.rho, "Chebyshev spectral radius estimate (0: off)")->check(at_least(0));
  app.add_option("--delay", o.delay, "Sweeps before the Chebyshev acceleration starts")->check(at_least(2));
  app.add_option("--frames", o.frames, "Frames of 1/60 s")->check(at_least(1));
  app.add_option("--damping", o.damping, "Velocity damping [1/s]")->check(at_least(0));
  app.add_option("--tol", o.tol, "network: residual tolerance")->check(at_least(0));
  app.add_option("--max-iterations", o.max_iterations, "network: the most sweeps per substep")->check(at_least(1));
  app.add_option("--E", o.young, "Young's modulus [Pa] (0: the case's, 30 MPa beam, 20 kPa kidney)")
      ->check(at_least(0));
  app.add_option("--reference", o.reference, "kidney: the converged sag [m] (0: none)")->check(at_least(0));
  app.add_option("--repeats", o.repeats, "Runs; the ms per frame is the median of their medians")->check(at_least(1));
  app.add_option("--threads", o.threads, "cpu backend worker threads (0: all)")->check(at_least(0));
  app.add_option("--csv", o.csv, "Append the row to this file");
  if (auto exit = cli.parse(argc, argv)) return *exit;

  const bool is_beam = o.kase == "beam";
  if (o.young <= 0.0) o.young = is_beam ? 3e7 : 2e4;
  const Body b = is_beam ? beam() : kidney();
  if (b.mesh.vertices.empty()) return 1;
  double target = -o.reference;  // [m], negative: down
  if (is_beam) {
    sinew::test::StaticLoads loads;
    loads.density = b.density;
    loads.gravity = {0.0, -9.81, 0.0};
    loads.pinned = b.pinned;
    std::string error;
    const std::vector<Vec3d> u = sinew::test::solve_linear_elastic(b.mesh, o.young, b.poisson, loads, &error);
    if (u.empty()) {
      std::fprintf(stderr, "oracle: %s\n", error.c_str());
      return 1;
    }
    target = sinew::test::mean_displacement(b.mesh, u, 1, 0, 0.16);
  }
  const sinew::SceneDesc scene = make_scene(o, b);
  std::vector<double> run_ms;
  double drop = 0.0;
  for (int r = 0; r < std::max(1, o.repeats); ++r) {
    auto sim = sinew::Simulation::create(scene, {.backend = "cpu", .threads = o.threads, .quiet = true});
    if (!sim) {
      std::fprintf(stderr, "%s\n", sim.error().message().c_str());
      return 1;
    }
    std::vector<double> ms;
    for (int f = 0; f < o.frames; ++f) {
      const auto t0 = std::chrono::steady_clock::now();
      if (auto s = sim->step(); !s) {
        std::fprintf(stderr, "frame %d: %s\n", f, s.error().message().c_str());
        return 1;
      }
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::vector<float> x;
    if (!sim->read_positions(x)) return 1;
    drop = mean_drop(b, x);  // deterministic: the same in every run
    run_ms.push_back(median(ms));
  }
  const double error = target != 0.0 ? 100.0 * (drop / target - 1.0) : 0.0;
  const bool fresh = !o.csv.empty() && !std::ifstream(o.csv).good();
  char row[512];
  std::snprintf(row, sizeof row, "%s,%s,%g,%d,%d,%g,%d,%g,%.6g,%.6g,%.2f,%.3f\n", o.kase.c_str(), o.solver.c_str(),
                o.young, o.substeps, o.iterations, o.rho, o.frames, o.damping, -drop * 1e3, -target * 1e3, error,
                median(run_ms));
  const char* header =
      "case,solver,E_Pa,substeps,iterations,rho,frames,velocity_damping,displacement_mm,target_mm,error_pct,"
      "ms_per_frame_median\n";
  std::printf("%s%s", header, row);
  if (!o.csv.empty()) {
    std::ofstream out(o.csv, std::ios::app);
    if (fresh) out << header;
    out << row;
  }
  return 0;
}
