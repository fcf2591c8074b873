// dam_break — the weakly compressible SPH solver (issue 15, part 2;
// src/fluid/sph_solver.h) against Martin and Moyce's dam break (Phil.
// Trans. R. Soc. A 244, 1952; data/sph, digitised by PySPH): a water column
// of width a and height 2 a collapses along x; the surge front's distance
// from the back wall, Z = z / a, against T = t sqrt(2 g / a).
//
// The column is a slab `--depth` particles thick between two walls (the
// experiment is two-dimensional), in a tank of one boundary layer; the
// front is the largest x of the fluid particles, plus half a spacing. The
// error is the RMS and largest |Z_sim - Z_data| / Z_data over the data's
// points, with Z_sim interpolated in time.
//
// Writes: --out/dam_break.csv (T, Z every 100 steps), dam_break.png (with
// the data, when gnuplot exists), the fluid particles with their density,
// pressure and velocity every --vtu-every steps (particles_N.vtu and
// dam_break.pvd, for ParaView); prints the error and the run time.
//
//   build/benchmarks/dam_break [--backend cpu] [--cells 24] [--depth 4] [--viscosity 0.1] [--wall-viscosity 0.1]
//                              [--vtu-every 500] [--out DIR]
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

#include "backends/backend.h"
#include "fluid/sph_solver.h"
#include "sinew/mesh.h"

namespace {

using namespace sinew;
using P3 = std::array<double, 3>;

struct Options {
  std::string backend = "cpu";
  int cells = 24;  // particles across the column's width a
  int depth = 4;   // particles across the slab
  double alpha = 0.1;       // Monaghan's viscosity between fluid particles
  double wall_alpha = 0.1;  // ... against the tank (0: free slip)
  std::string out = "dam_break_out";
  int vtu_every = 500;  // steps between the particles' VTU files (0: none)
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

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--backend") o.backend = argv[i + 1];
    else if (a == "--cells") o.cells = std::atoi(argv[i + 1]);
    else if (a == "--depth") o.depth = std::atoi(argv[i + 1]);
    else if (a == "--wall-viscosity") o.wall_alpha = std::atof(argv[i + 1]);
    else if (a == "--viscosity") o.alpha = std::atof(argv[i + 1]);
    else if (a == "--out") o.out = argv[i + 1];
    else if (a == "--vtu-every") o.vtu_every = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  if (o.cells < 4 || o.depth < 1) {
    std::fprintf(stderr, "dam_break: --cells must be >= 4 and --depth >= 1\n");
    return 2;
  }
  const auto data = read_data(std::string(SINEW_DATA_DIR) + "/sph/martin_moyce_1952_n2_2_a2.25in.csv");
  if (data.empty()) {
    std::fprintf(stderr, "dam_break: no data in %s/sph\n", SINEW_DATA_DIR);
    return 1;
  }
  // a = 5.715 cm (2.25 in), as in the experiment's series.
  const double a = 0.05715, s = a / o.cells, g = 9.81;
  const int nx = o.cells, ny = 2 * o.cells, nz = o.depth;
  const int length = static_cast<int>(std::ceil(13.0 * a / s));  // the tank: 13 a long, the front reaches 11 a
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
  // c0: ten times the surge's speed, about 2 sqrt(g H) (Monaghan 1994).
  SphSettings settings;
  settings.spacing = s;
  settings.speed_of_sound = 10.0 * 2.0 * std::sqrt(g * 2.0 * a);
  settings.time_step = 0.4 * 2.0 * s / (1.1 * settings.speed_of_sound);  // the CFL bound with v_max = c0 / 10
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
  std::filesystem::create_directories(o.out);
  const std::string csv = o.out + "/dam_break.csv";
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "dam_break: cannot write %s\n", csv.c_str());
    return 1;
  }
  std::fprintf(f, "T,Z\n");
  std::vector<std::array<double, 2>> series;
  std::vector<SphParticle> q;
  std::vector<std::filesystem::path> vtu_files;
  std::vector<double> vtu_times;
  const auto t0 = std::chrono::steady_clock::now();
  double stepping_s = 0.0;
  for (int done = 0; done <= steps; done += 100) {
    if (done > 0) {
      const auto a0 = std::chrono::steady_clock::now();
      if (auto st = (*solver)->step(100); !st) {
        std::fprintf(stderr, "dam_break: %s\n", st.error().message().c_str());
        return 1;
      }
      stepping_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - a0).count();
    }
    if (auto st = (*solver)->read(q); !st) return 1;
    double front = 0.0;
    for (const auto& p : q) front = std::max(front, double(p.position[0]));
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
    std::fprintf(f, "%.4f,%.4f\n", T, Z);
  }
  std::fclose(f);
  if (!vtu_files.empty())
    if (auto st = write_pvd(o.out + "/dam_break.pvd", vtu_files, vtu_times); !st) {
      std::fprintf(stderr, "dam_break: %s\n", st.error().message().c_str());
      return 1;
    }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double sum = 0.0, worst = 0.0;
  for (const auto& [T, Z] : data) {
    const auto it = std::lower_bound(series.begin(), series.end(), T, [](const auto& r, double t) { return r[0] < t; });
    if (it == series.begin() || it == series.end()) continue;
    const auto& lo = *(it - 1);
    const auto& hi = *it;
    const double z = lo[1] + (hi[1] - lo[1]) * (T - lo[0]) / (hi[0] - lo[0]);
    const double e = std::abs(z - Z) / Z;
    sum += e * e;
    worst = std::max(worst, e);
  }
  const double rms = std::sqrt(sum / double(data.size()));
  std::printf("surge front against Martin and Moyce (%zu points): RMS %.1f%%, worst %.1f%%; %.1f s of stepping "
              "(%.0f ns per particle per step), %.1f s in all\n",
              data.size(), 100.0 * rms, 100.0 * worst, stepping_s,
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
