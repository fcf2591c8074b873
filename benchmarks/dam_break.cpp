// dam_break — the weakly compressible SPH solver (issue 15, part 2;
// src/fluid/sph_solver.h) against Martin and Moyce's dam break (Phil.
// Trans. R. Soc. A 244, 1952; data/sph, digitised by PySPH): a water column
// of width a and height 2 a collapses along x; the surge front's distance
// from the back wall, Z = z / a, against T = t sqrt(2 g / a).
//
// The column is a slab `--depth` particles thick between two walls (the
// experiment is two-dimensional), in a tank of one boundary layer, 16 a
// long (the data's front reaches 14 a). The walls are free-slip by default:
// water's viscosity is negligible at these resolutions, and Monaghan's
// viscosity against the walls, the only friction the solver has, acts
// like a fluid some 400 times more viscous than water, which the slab's
// two side walls turn into a brake (README, "SPH fluid"). The front is the
// largest x of the fluid body connected to the column (particles binned by
// x at one spacing; two empty bins in a row end it, and what lies beyond
// is spray), plus half a spacing. The error is the RMS and largest
// |Z_sim - Z_data| / Z_data over the data's points, with Z_sim interpolated
// in time; it is given twice: at the data's time origin, and at the time
// origin that fits best (the experiment's release is not modelled, and its
// front starts late; the shift is printed).
//
// Writes: --out/dam_break.csv (T, Z and the farthest particle's Z_spray every 25 steps), dam_break.png (with
// the data, when gnuplot exists), the fluid particles with their density,
// pressure and velocity every --vtu-every steps (particles_N.vtu and
// dam_break.pvd, for ParaView); prints the error and the run time.
//
//   build/benchmarks/dam_break --help   (the options, their defaults and units)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "command_line.h"
#include "backends/backend.h"
#include "fluid/sph_solver.h"
#include "sinew/mesh.h"

namespace {

using namespace sinew;
using P3 = std::array<double, 3>;

struct Options {
  std::string backend = "cpu";
  int cells = 24;  // particles across the column's width a
  int depth = 8;   // particles across the slab
  double alpha = 0.1;       // Monaghan's viscosity between fluid particles
  double wall_alpha = 0.0;  // ... against the tank (0: free slip)
  std::string out;
  int vtu_every = 500;  // steps between the particles' VTU files (0: none)
  double length = 16.0;  // the tank's length in a (the data's front reaches 14 a)
};

std::vector<std::array<double, 2>> read_data(const std::string& path) {
  std::vector<std::array<double, 2>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'T') continue;
    std::istringstream s(line);
    double t = 0, z = 0;
    char comma = 0;
    if (s >> t >> comma >> z) rows.push_back({t, z});
  }
  return rows;
}

// The surge front: the largest x of the fluid body that is connected to
// the column. Particles are binned by x in bins of one spacing; walking from
// the back wall, the first two empty bins in a row (a gap wider than the
// support) end the body, and what lies beyond is spray, which the
// experiment's front did not count.
double connected_front(const std::vector<SphParticle>& q, double spacing) {
  double far = 0.0;
  for (const auto& p : q) far = std::max(far, double(p.position[0]));
  const std::size_t bins = static_cast<std::size_t>(far / spacing) + 2;
  std::vector<double> largest(bins, -1.0);
  for (const auto& p : q) {
    const double x = std::max(0.0, double(p.position[0]));
    auto& l = largest[static_cast<std::size_t>(x / spacing)];
    l = std::max(l, x);
  }
  double front = 0.0;
  for (std::size_t b = 0; b < bins; ++b) {
    if (largest[b] >= 0.0) front = largest[b];
    else if (b + 1 < bins && largest[b + 1] < 0.0) break;
  }
  return front;
}

double farthest(const std::vector<SphParticle>& q) {
  double far = 0.0;
  for (const auto& p : q) far = std::max(far, double(p.position[0]));
  return far;
}

struct FrontError {
  double rms = 0.0, worst = 0.0;  // relative |Z_sim - Z_data| / Z_data
};

// The error over the data's points, comparing the data at T with the
// simulation at T - shift (interpolated linearly; a point outside the
// simulated range counts in full).
FrontError front_error(const std::vector<std::array<double, 2>>& series,
                       const std::vector<std::array<double, 2>>& data, double shift) {
  FrontError e;
  for (const auto& [T, Z] : data) {
    const double t = T - shift;
    const auto it = std::lower_bound(series.begin(), series.end(), t, [](const auto& r, double v) { return r[0] < v; });
    double z = series.back()[1];
    if (it == series.begin()) z = series.front()[1];
    else if (it != series.end()) z = (it - 1)[0][1] + (it[0][1] - (it - 1)[0][1]) * (t - (it - 1)[0][0]) / (it[0][0] - (it - 1)[0][0]);
    const double r = std::abs(z - Z) / Z;
    e.rms += r * r;
    e.worst = std::max(e.worst, r);
  }
  e.rms = std::sqrt(e.rms / double(data.size()));
  return e;
}

constexpr int kSampleEvery = 25;  // steps between the front's samples

}  // namespace

int main(int argc, char** argv) {
  Options o;
  sinew::examples::CommandLine cli(
      "dam_break",
      "The weakly compressible SPH solver against Martin and Moyce's dam break (1952): a water column of\n"
      "width a and height 2 a collapses along x; the surge front's Z = z / a against T = t sqrt(2 g / a).\n"
      "Prints the error against the data and the run time; writes dam_break.csv, dam_break.png (with\n"
      "gnuplot) and the particles' VTU series (dam_break.pvd) into --out.");
  using sinew::examples::at_least;
  o.out = cli.default_out();
  cli.add_backend(o.backend);
  cli.app().add_option("--cells", o.cells, "Particles across the column's width a")->check(at_least(4));
  cli.app().add_option("--depth", o.depth, "Particles across the slab (its thickness)")->check(at_least(1));
  cli.app().add_option("--viscosity", o.alpha, "Monaghan's viscosity alpha between fluid particles")
      ->check(at_least(0));
  cli.app().add_option("--wall-viscosity", o.wall_alpha, "Monaghan's viscosity against the tank (0: free slip)")
      ->check(at_least(0));
  cli.app().add_option("--length", o.length, "The tank's length [in units of a]")->check(at_least(2));
  cli.app().add_option("--vtu-every", o.vtu_every, "Steps between the particles' VTU files (0: none)")
      ->check(at_least(0));
  cli.add_out(o.out);
  if (auto exit = cli.parse(argc, argv)) return *exit;
  const auto data = read_data(std::string(SINEW_DATA_DIR) + "/sph/martin_moyce_1952_n2_2_a2.25in.csv");
  if (data.empty()) {
    std::fprintf(stderr, "dam_break: no data in %s/sph\n", SINEW_DATA_DIR);
    return 1;
  }
  // a = 5.715 cm (2.25 in), as in the experiment's series.
  const double a = 0.05715, s = a / o.cells, g = 9.81;
  const int nx = o.cells, ny = 2 * o.cells, nz = o.depth;
  const int length = static_cast<int>(std::ceil(o.length * a / s));
  const int height = ny + 4;
  std::vector<P3> fluid, boundary;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) fluid.push_back({(i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s});
  for (int i = -1; i <= length; ++i)
    for (int k = -1; k <= nz; ++k) boundary.push_back({(i + 0.5) * s, -0.5 * s, (k + 0.5) * s});  // floor
  for (int j = 0; j < height; ++j) {
    for (int k = -1; k <= nz; ++k) {
      boundary.push_back({-0.5 * s, (j + 0.5) * s, (k + 0.5) * s});  // back wall
      boundary.push_back({(length + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s});  // far wall
    }
    for (int i = 0; i < length; ++i) {  // the slab's two side walls
      boundary.push_back({(i + 0.5) * s, (j + 0.5) * s, -0.5 * s});
      boundary.push_back({(i + 0.5) * s, (j + 0.5) * s, (nz + 0.5) * s});
    }
  }
  // c0: ten times the surge's speed, about 2 sqrt(g H) (Monaghan 1994);
  // the step leaves room for particles up to c0 / 4 (free-slip walls let
  // splashes pass c0 / 10).
  SphSettings settings;
  settings.spacing = s;
  settings.speed_of_sound = 10.0 * 2.0 * std::sqrt(g * 2.0 * a);
  settings.time_step = 0.4 * 2.0 * s / (1.25 * settings.speed_of_sound);  // the CFL bound with v_max = c0 / 4
  settings.viscosity = o.alpha;
  settings.boundary_viscosity = o.wall_alpha;
  auto device = create_device({.backend = o.backend, .quiet = true});
  if (!device) {
    std::fprintf(stderr, "dam_break: %s\n", device.error().message().c_str());
    return 1;
  }
  auto solver = SphSolver::create(**device, settings, fluid, boundary);
  if (!solver) {
    std::fprintf(stderr, "dam_break: %s\n", solver.error().message().c_str());
    return 1;
  }
  const double t_end = data.back()[0] / std::sqrt(2.0 * g / a) * 1.02;
  const int steps = static_cast<int>(std::ceil(t_end / settings.time_step));
  std::printf("dam_break on %s: a = %.4f m in %d x %d x %d particles (%zu fluid, %zu boundary), c0 = %.1f m/s, dt = "
              "%.3g s, %d steps\n",
              (*device)->device_name().c_str(), a, nx, ny, nz, fluid.size(), boundary.size(),
              settings.speed_of_sound, settings.time_step, steps);
  const std::string csv = o.out + "/dam_break.csv";
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "dam_break: cannot write %s\n", csv.c_str());
    return 1;
  }
  std::fprintf(f, "T,Z,Z_spray\n");
  std::vector<std::array<double, 2>> series;
  std::vector<SphParticle> q;
  std::vector<std::filesystem::path> vtu_files;
  std::vector<double> vtu_times;
  const auto t0 = std::chrono::steady_clock::now();
  double stepping_s = 0.0;
  for (int done = 0; done <= steps; done += kSampleEvery) {
    if (done > 0) {
      const auto a0 = std::chrono::steady_clock::now();
      if (auto st = (*solver)->step(kSampleEvery); !st) {
        std::fprintf(stderr, "dam_break: %s\n", st.error().message().c_str());
        return 1;
      }
      stepping_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - a0).count();
    }
    if (auto st = (*solver)->read(q); !st) return 1;
    const double front = connected_front(q, s), spray = farthest(q);
    if (o.vtu_every > 0 && done % o.vtu_every == 0) {
      std::vector<float> xyz, density, pressure, velocity;
      for (const auto& p : q) {
        xyz.insert(xyz.end(), p.position.begin(), p.position.end());
        velocity.insert(velocity.end(), p.velocity.begin(), p.velocity.end());
        density.push_back(p.density);
        pressure.push_back(p.pressure);
      }
      const VertexField fields[] = {{"density", 1, density}, {"pressure", 1, pressure}, {"velocity", 3, velocity}};
      vtu_files.push_back(o.out + "/particles_" + std::to_string(vtu_files.size()) + ".vtu");
      vtu_times.push_back(done * settings.time_step);
      if (auto st = write_vtu_points(vtu_files.back(), xyz, 3, fields); !st) {
        std::fprintf(stderr, "dam_break: %s\n", st.error().message().c_str());
        return 1;
      }
    }
    const double T = done * settings.time_step * std::sqrt(2.0 * g / a), Z = (front + 0.5 * s) / a;
    series.push_back({T, Z});
    std::fprintf(f, "%.4f,%.4f,%.4f\n", T, Z, (spray + 0.5 * s) / a);
  }
  std::fclose(f);
  if (!vtu_files.empty())
    if (auto st = write_pvd(o.out + "/dam_break.pvd", vtu_files, vtu_times); !st) {
      std::fprintf(stderr, "dam_break: %s\n", st.error().message().c_str());
      return 1;
    }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const FrontError raw = front_error(series, data, 0.0);
  FrontError shifted = raw;
  double best_shift = 0.0;
  for (int k = -200; k <= 200; ++k)  // the time origin, within +-2 in T, in steps of 0.01
    if (const FrontError e = front_error(series, data, 0.01 * k); e.rms < shifted.rms) {
      shifted = e;
      best_shift = 0.01 * k;
    }
  std::printf("surge front against Martin and Moyce (%zu points): RMS %.1f%%, worst %.1f%%; with the time origin "
              "fitted (data T against the simulation's T - %.2f): RMS %.1f%%, worst %.1f%%\n",
              data.size(), 100.0 * raw.rms, 100.0 * raw.worst, best_shift, 100.0 * shifted.rms,
              100.0 * shifted.worst);
  std::printf("%.1f s of stepping (%.0f ns per particle per step), %.1f s in all\n", stepping_s,
              1e9 * stepping_s / double(steps) / double(fluid.size() + boundary.size()), wall);
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    const std::string gp = o.out + "/dam_break.gp";
    if (std::FILE* p = std::fopen(gp.c_str(), "w")) {
      std::fprintf(p,
                   "set terminal pngcairo size 800,600 font 'sans,10'\nset output '%s/dam_break.png'\n"
                   "set datafile separator ','\nset grid; set key top left\n"
                   "set title 'dam break: surge front (WCSPH, a / s = %d)'\n"
                   "set xlabel 'T = t sqrt(2 g / a)'; set ylabel 'Z = z / a'\n"
                   "plot '%s' using 1:2 with lines lw 2 title 'sinew', '%s/sph/martin_moyce_1952_n2_2_a2.25in.csv' "
                   "using 1:2 with points pt 7 title 'Martin and Moyce 1952'\n",
                   o.out.c_str(), o.cells, csv.c_str(), SINEW_DATA_DIR);
      std::fclose(p);
      if (std::system(("gnuplot '" + gp + "'").c_str()) == 0) std::printf("wrote %s/dam_break.png\n", o.out.c_str());
    }
  }
  return 0;
}
