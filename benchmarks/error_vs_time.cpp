// error_vs_time — the error of a run against its wall time, sweeping
// substeps x iterations, to test the "Small Steps" finding on sinew's solver
// (Macklin, Storey, Lu, Terdiman, Chentanez, Jeschke, Müller, "Small Steps in
// Physics Simulation", SCA 2019: n substeps of one iteration beat one step of
// n iterations at equal cost).
//
// Cases:
//  chain    a hanging chain of 20 links released from its rest length; error
//           of the final positions against a converged reference run, and
//           the static stretch error against the closed form alpha k m g.
//  nh_bar   a stable Neo-Hookean bar hanging from its top face, released
//           from rest; error against a converged reference run.
//  nh_cube  the foundation benchmark's cube (8^3 cells) with Neo-Hookean
//           material, hanging from its top face.
//  kidney   the real organ mesh kidney_57k (mm scaled to m, in the mesher's
//           vertex order) with distance + volume constraints, E = 30 kPa,
//           nu = 0.45, pinned within 5 mm of its lowest x, sagging under
//           gravity (the organ_step / bench_organs setup).
//  chain_damped, kidney_damped
//           the same scenes damped (scene.h): the chain with stiffness
//           damping tau = 5 ms and velocity damping 2 1/s, the kidney with
//           velocity damping 4 1/s (the flagship example's value).
// --method vbd runs the FEM cases (nh_bar, nh_cube) with Vertex Block Descent
// (SolverSettings::method; Chen et al., SIGGRAPH 2024), the reference too, so
// each error is against the converged run of the same method; the other cases
// (a line body, the edge network) are xPBD's only and are skipped. Its rows
// are named CASE_vbd (nh_bar_vbd, nh_cube_vbd).
// The error is the RMS distance of the particles from the reference run's
// after `seconds` of simulated time, divided by the body's size. The
// reference is 16 substeps of 32 iterations per 1/60 s frame. Why not more
// substeps: positions are float32 and velocities are (x - x_prev) / h, so
// each substep quantises a velocity by ~ulp(x) / h (1.2e-7 m / h at 1 m from
// the origin). On the chain, runs of 8, 16 and 32 substeps agree to ~1e-3
// of its length, while 32 vs 64 and 64 vs 128 substeps differ by 1e-2 and
// 4e-2: past ~16 substeps per 60 Hz frame float rounding, not the time
// step, sets the error (numbers in benchmarks/README.md).
//
//   error_vs_time --help   (the options, their defaults and units)
// writes DIR/error_vs_time.csv; benchmarks/plot_error_vs_time.sh draws it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/simulation.h"

#include "command_line.h"

namespace {

struct Case {
  std::string name;
  double size;  // characteristic length [m] the error is divided by
  std::function<sinew::SceneDesc()> scene;
};

sinew::SceneDesc chain_scene() {
  const int links = 20;
  sinew::LineBodyDesc chain;
  for (int i = 0; i <= links; ++i) {
    chain.vertices.push_back({0.0, -0.05 * i, 0.0});
    chain.masses.push_back(0.01);
    if (i > 0) chain.segments.push_back({std::uint32_t(i - 1), std::uint32_t(i)});
  }
  chain.compliance = 1e-2;  // 100 N/m links: a visible, well-resolved stretch
  chain.pinned = {0};
  sinew::SceneDesc scene;
  scene.line_bodies.push_back(chain);
  return scene;
}

sinew::SceneDesc nh_block_scene(int nx, int ny, int nz, double cell, double young) {
  sinew::TetBodyDesc body;
  body.mesh = *sinew::make_tet_grid({.nx = nx, .ny = ny, .nz = nz, .origin = {0, 0, 0},
                                     .cell_size = {cell, cell, cell}});
  body.density = 1000.0;
  (void)body.set_material(sinew::TetMaterial::neo_hookean, young, 0.4);
  const double top = ny * cell;
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] > top - 1e-9) body.pinned.push_back(v);
  sinew::SceneDesc scene;
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

sinew::SceneDesc kidney_scene() {
  auto mesh = sinew::read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node");
  sinew::SceneDesc scene;
  if (!mesh) {
    std::fprintf(stderr, "kidney: %s\n", mesh.error().message().c_str());
    return scene;  // no body: Simulation::create reports it
  }
  sinew::scale_mesh(*mesh, 1e-3);
  sinew::TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1060.0;
  (void)body.set_elastic(3e4, 0.45);
  double lo = 1e30;
  for (const auto& v : body.mesh.vertices) lo = std::min(lo, v[0]);
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] < lo + 0.005) body.pinned.push_back(v);
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

// A case's scene with every body's damping set [1/s], [s].
std::function<sinew::SceneDesc()> damped(std::function<sinew::SceneDesc()> scene, double velocity_damping,
                                         double stiffness_damping) {
  return [=] {
    sinew::SceneDesc s = scene();
    for (auto& b : s.tet_bodies) {
      b.velocity_damping = velocity_damping;
      b.stiffness_damping = stiffness_damping;
    }
    for (auto& b : s.line_bodies) {
      b.velocity_damping = velocity_damping;
      b.stiffness_damping = stiffness_damping;
    }
    return s;
  };
}

struct Run {
  double ms_per_frame = 0.0;
  double residual = 0.0;
  std::vector<float> x;
  std::string error;
};

Run run(sinew::SceneDesc scene, int substeps, int iterations, double seconds, const std::string& backend,
        sinew::SolverMethod method) {
  scene.solver.method = method;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = substeps;
  scene.solver.iterations = iterations;
  Run r;
  auto sim = sinew::Simulation::create(scene, {.backend = backend, .quiet = true});
  if (!sim) {
    r.error = sim.error().message();
    return r;
  }
  const int frames = static_cast<int>(std::lround(seconds * 60.0));
  double total = 0.0;
  for (int f = 0; f < frames; ++f) {
    if (auto s = sim->step(); !s) {
      r.error = s.error().message();
      return r;
    }
    total += sim->last_frame().wall_ms;
  }
  r.ms_per_frame = total / frames;
  r.residual = sim->last_frame().residual_rms;
  (void)sim->read_positions(r.x);
  return r;
}

double rms_distance(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0.0;
  const std::size_t n = a.size() / 4;
  for (std::size_t p = 0; p < n; ++p)
    for (int k = 0; k < 3; ++k) sum += std::pow(double(a[4 * p + k]) - b[4 * p + k], 2);
  return std::sqrt(sum / double(n));
}

// The chain's static error: max over links of |stretch / (alpha k m g) - 1|.
double chain_static_error(const std::vector<float>& x) {
  const int links = 20;
  double worst = 0.0;
  for (int k = 1; k <= links; ++k) {
    const int upper = links - k, lower = upper + 1;
    const double stretch = std::abs(double(x[4 * upper + 1]) - x[4 * lower + 1]) - 0.05;
    worst = std::max(worst, std::abs(stretch / (1e-2 * k * 0.01 * 9.81) - 1.0));
  }
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "error_vs_time",
      "The error of a run against its wall time, sweeping substeps x iterations (every product 1..64 in powers\n"
      "of two) on the cases chain, nh_bar, nh_cube, kidney, chain_damped and kidney_damped; the error is the\n"
      "RMS particle distance from a converged reference run, divided by the body's size. Writes\n"
      "error_vs_time.csv into --out (plot it with benchmarks/plot_error_vs_time.sh).");
  std::string backend = "auto", out = cli.default_out(), only, reference_text = "16x32";
  double seconds = 1.0;
  int ref_substeps = 16, ref_iterations = 32;
  cli.add_backend(backend);
  cli.app().add_option("--seconds", seconds, "Simulated time of each run [s]")->check(sinew::examples::greater_than(0));
  cli.app().add_option("--cases", only, "Only these cases, comma-separated (default: all)")->type_name("A,B,...");
  cli.app().add_option("--reference", reference_text, "The reference run's substeps x iterations per 1/60 s frame")
      ->type_name("SxI")
      ->check([](const std::string& v) {
        int a = 0, b = 0;
        char end = 0;
        if (std::sscanf(v.c_str(), "%dx%d%c", &a, &b, &end) == 2 && a >= 1 && b >= 1) return std::string();
        return "must be SUBSTEPSxITERATIONS, both >= 1 (got " + v + ")";
      });
  std::string method_name = "xpbd";
  cli.app().add_option("--method", method_name, "The solver: xpbd, or vbd (the FEM cases only)")
      ->check(CLI::IsMember({"xpbd", "vbd"}));
  cli.add_out(out);
  if (auto exit = cli.parse(argc, argv)) return *exit;
  const sinew::SolverMethod method = method_name == "vbd" ? sinew::SolverMethod::vbd : sinew::SolverMethod::xpbd;
  std::sscanf(reference_text.c_str(), "%dx%d", &ref_substeps, &ref_iterations);
  const std::vector<Case> cases = {
      {"chain", 1.0, chain_scene},
      {"nh_bar", 0.1, [] { return nh_block_scene(3, 15, 3, 0.01 / 1.5, 5e4); }},
      {"nh_cube", 1.0, [] { return nh_block_scene(8, 8, 8, 1.0 / 8, 1e5); }},
      {"kidney", 0.1, kidney_scene},
      {"chain_damped", 1.0, damped(chain_scene, 2.0, 0.005)},
      {"kidney_damped", 0.1, damped(kidney_scene, 4.0, 0.0)},
  };
  for (std::size_t at = 0; !only.empty() && at <= only.size();) {  // every name in --cases is a case
    const std::size_t comma = std::min(only.find(',', at), only.size());
    const std::string name = only.substr(at, comma - at);
    if (std::none_of(cases.begin(), cases.end(), [&](const Case& c) { return c.name == name; })) {
      std::fprintf(stderr, "error_vs_time: --cases: no case named '%s'\n", name.c_str());
      return 2;
    }
    at = comma + 1;
  }
  // Pairs (substeps, iterations): every product 1..64 in powers of two, so
  // runs of equal total sweeps (substeps x iterations) can be compared.
  std::vector<std::pair<int, int>> configs;
  for (int s = 1; s <= 64; s *= 2)
    for (int n = 1; s * n <= 64; n *= 2) configs.emplace_back(s, n);

  std::ofstream csv(out + "/error_vs_time.csv");
  csv << "case,substeps,iterations,sweeps,ms_per_frame,error,residual_rms,static_error\n";
  std::printf("%-8s %8s %10s %7s %12s %12s %12s\n", "case", "substeps", "iterations", "sweeps", "ms/frame", "error",
              "residual");
  for (const Case& c : cases) {
    if (!only.empty() && ("," + only + ",").find("," + c.name + ",") == std::string::npos) continue;
    if (method == sinew::SolverMethod::vbd && !c.name.starts_with("nh_")) continue;  // xPBD-only bodies
    const Run reference = run(c.scene(), ref_substeps, ref_iterations, seconds, backend, method);
    if (!reference.error.empty()) {
      std::fprintf(stderr, "%s: %s\n", c.name.c_str(), reference.error.c_str());
      return 1;
    }
    std::map<int, std::pair<double, double>> one_step, one_iteration;  // sweeps -> (error, ms)
    for (auto [s, n] : configs) {
      const Run r = run(c.scene(), s, n, seconds, backend, method);
      if (!r.error.empty()) {
        std::fprintf(stderr, "%s: %s\n", c.name.c_str(), r.error.c_str());
        return 1;
      }
      const double error = rms_distance(r.x, reference.x) / c.size;
      const double static_error = c.name.starts_with("chain") ? chain_static_error(r.x) : std::nan("");
      csv << c.name << (method == sinew::SolverMethod::vbd ? "_vbd" : "") << ',' << s << ',' << n << ',' << s * n << ',' << r.ms_per_frame << ',' << error << ','
          << r.residual << ',' << static_error << '\n';
      std::printf("%-8s %8d %10d %7d %12.4f %12.3e %12.3e\n", c.name.c_str(), s, n, s * n, r.ms_per_frame, error,
                  r.residual);
      if (s == 1) one_step[n] = {error, r.ms_per_frame};
      if (n == 1) one_iteration[s] = {error, r.ms_per_frame};
    }
    std::printf("%s: Small Steps at equal sweeps (n substeps x 1 iteration vs 1 substep x n iterations):\n",
                c.name.c_str());
    for (const auto& [sweeps, step] : one_step) {
      if (sweeps == 1 || !one_iteration.count(sweeps)) continue;
      const auto [e_sub, ms_sub] = one_iteration[sweeps];
      std::printf("  %2d sweeps: substeps error %.3e (%.3f ms), iterations error %.3e (%.3f ms): %s\n", sweeps,
                  e_sub, ms_sub, step.first, step.second, e_sub < step.first ? "substeps win" : "iterations win");
    }
  }
  std::printf("wrote %s/error_vs_time.csv\n", out.c_str());
  return 0;
}
