// bench_scaling — how the CPU backend scales from one thread to all: the
// same scene on 1 thread, on N threads with the adaptive choice between
// the team and one thread (the default), and on N threads always as a team,
// stepped in turns so that the three see the same machine (this project's
// machines are shared VMs whose speed drifts by tens of percent within a
// minute: only times taken in the same minute compare).
//
// Scenes: the benchmark cube (bench_cube's: distance + volume at 5
// iterations, and Neo-Hookean), the kidney and the liver in the mesher's
// vertex order (organ_step's settings: 10 substeps x 1 iteration), and two
// blocks colliding (mesh contacts, the tests' scene).
//
// Each configuration first steps `--warmup` frames unmeasured (the adaptive
// choice times the team and one thread in its first runs: what is measured
// is the steady state). Then each round steps each configuration
// `--frames` frames back to back after one unmeasured frame, with a pause
// before it long enough for every other configuration's idle workers to
// fall asleep. Reports per configuration
// the median and 90th percentile of the frame time over all rounds, and
// the speedup over 1 thread: the median over rounds of the ratio of the
// round's median frame times (paired, so a drift of the machine's speed
// between rounds cancels).
//
// --busy starts another process that spins on one core for the whole run
// (the "second core is busy" case; the 1-thread time is then also measured
// beside it).
//
//   bench_scaling --help   (the options, their defaults)
//   e.g. bench_scaling --csv benchmarks/results/scaling_2026-11-28.csv
// Prints a table and, with --csv, writes one row per scene and configuration:
//   scene,constraints,particles,busy,config,threads,median_ms,p90_ms,speedup,speedup_p10,speedup_p90
// (speedup_p10/p90: the 10th and 90th percentiles of the rounds' ratios).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "command_line.h"

#include "bench_support.h"
#include "mesh_contact_support.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace {

using namespace sinew;

struct Scene {
  std::string name;
  std::function<Result<SceneDesc>()> make;
  int rounds_scale = 1;  // divides the rounds for the slowest scenes
};

// bench_cube's cube: 1 m, n^3 cells of 6 tets, hanging from its top face.
SceneDesc cube(int n, TetMaterial material) {
  TetBodyDesc body;
  const double h = 1.0 / n;
  body.mesh = *make_tet_grid({.nx = n, .ny = n, .nz = n, .origin = {0, 0, 0}, .cell_size = {h, h, h}});
  body.density = 1000.0;
  if (material == TetMaterial::none)
    (void)body.set_elastic(1e5, 0.4);
  else
    (void)body.set_material(material, 1e5, 0.4);
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] >= 1.0 - 1e-9) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver = {.time_step = 1.0 / 60.0, .substeps = 1, .iterations = 5, .measure_errors = false};
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

// organ_step's organ: millimetres to metres, E = 30 kPa, nu = 0.45, pinned
// within 5 mm of its lowest x, 10 substeps x 1 iteration.
Result<SceneDesc> organ(const std::string& file, TetMaterial material) {
  auto mesh = read_tet_mesh(std::string(SINEW_DATA_DIR) + "/meshes/tet/" + file);
  if (!mesh) return mesh.error();
  scale_mesh(*mesh, 1e-3);
  TetBodyDesc body;
  body.mesh = std::move(*mesh);
  body.density = 1060.0;
  Status made = material == TetMaterial::none ? body.set_elastic(3e4, 0.45) : body.set_material(material, 3e4, 0.45);
  if (!made) return made.error();
  double lo = 1e30;
  for (const auto& v : body.mesh.vertices) lo = std::min(lo, v[0]);
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][0] < lo + 0.005) body.pinned.push_back(v);
  SceneDesc scene;
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = 10;
  scene.solver.iterations = 1;
  scene.solver.measure_errors = false;
  scene.tet_bodies.push_back(std::move(body));
  return scene;
}

std::vector<Scene> scenes(bool quick) {
  std::vector<Scene> s;
  for (int n : quick ? std::vector<int>{8, 24} : std::vector<int>{4, 8, 12, 16, 24, 32})
    s.push_back({"cube" + std::to_string(n) + "_xpbd", [n] { return Result<SceneDesc>(cube(n, TetMaterial::none)); }});
  for (int n : quick ? std::vector<int>{16} : std::vector<int>{8, 16, 24})
    s.push_back({"cube" + std::to_string(n) + "_neo_hookean",
                 [n] { return Result<SceneDesc>(cube(n, TetMaterial::neo_hookean)); }});
  s.push_back({"kidney_57k_xpbd", [] { return organ("kidney_57k.node", TetMaterial::none); }});
  s.push_back({"kidney_57k_corotational", [] { return organ("kidney_57k.node", TetMaterial::corotational); }});
  if (!quick) s.push_back({"liver_382k_xpbd", [] { return organ("liver_382k.node", TetMaterial::none); }, 4});
  s.push_back({"blocks_mesh_contacts",
               [] { return Result<SceneDesc>(test::dropped_blocks_scene(ContactSchedule::colored)); }});
  return s;
}

struct Config {
  const char* name;
  int threads;  // 0: all
  bool adaptive;
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * double(v.size())))];
}

// Another process spinning on one core until killed.
pid_t start_spinner() {
  const pid_t pid = fork();
  if (pid == 0) {
    volatile unsigned long x = 0;
    for (;;) x = x + 1;
  }
  return pid;
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "bench_scaling",
      "How the CPU backend scales from one thread to all: each scene stepped on 1 thread, on all threads with\n"
      "the adaptive choice (the default) and on all threads always as a team, in turns within each round.\n"
      "Prints the median frame time and the paired speedup over 1 thread; with --csv one row per scene and\n"
      "configuration (scene,constraints,particles,busy,config,threads,median_ms,p90_ms,speedup,...).");
  using sinew::examples::at_least;
  int rounds = 15, frames = 4, warmup = 10, threads = 0;
  bool busy = false, quick = false;
  std::string csv, only;
  cli.app().add_option("--rounds", rounds, "Rounds (each configuration measured once per round)")->check(at_least(1));
  cli.app().add_option("--frames", frames, "Measured frames per configuration and round")->check(at_least(1));
  cli.app().add_option("--warmup", warmup, "Unmeasured frames per configuration first")->check(at_least(0));
  cli.app().add_option("--threads", threads, "Threads of the multi-thread configurations (0: all)")->check(at_least(0));
  cli.app().add_flag("--busy", busy, "Another process spins on one core throughout");
  cli.app().add_flag("--quick", quick, "Fewer scenes (cubes of 8 and 24 cells, Neo-Hookean 16, no liver)");
  cli.app().add_option("--only", only, "Only the scenes whose name contains this");
  cli.app().add_option("--csv", csv, "Write the rows to this CSV file")->type_name("FILE");
  if (auto exit = cli.parse(argc, argv)) return *exit;
  const Config configs[] = {{"1_thread", 1, true}, {"adaptive", threads, true}, {"team", threads, false}};
  std::FILE* out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (!csv.empty() && !out) {
    std::fprintf(stderr, "bench_scaling: cannot write %s\n", csv.c_str());
    return 1;
  }
  if (out)
    std::fprintf(out, "scene,constraints,particles,busy,config,threads,median_ms,p90_ms,speedup,speedup_p10,speedup_p90\n");
  const unsigned team_threads = threads > 0 ? unsigned(threads) : std::max(1u, std::thread::hardware_concurrency());
  const pid_t spinner = busy ? start_spinner() : -1;
  std::printf("%-26s %9s %12s %12s %12s   (median ms per frame, paired speedup over 1 thread; %s)\n", "scene", "constr.",
              "1 thread", "adaptive", "team", busy ? "another process spinning" : "quiet");
  int status = 0;
  for (const Scene& scene : scenes(quick)) {
    if (!only.empty() && scene.name.find(only) == std::string::npos) continue;
    auto desc = scene.make();
    if (!desc) {
      std::fprintf(stderr, "%s: %s\n", scene.name.c_str(), desc.error().message().c_str());
      status = 1;
      continue;
    }
    std::vector<Simulation> sims;
    for (const Config& c : configs) {
      auto sim = Simulation::create(*desc, {.backend = "cpu", .threads = c.threads, .cpu_adaptive_team = c.adaptive, .quiet = true});
      if (!sim) {
        std::fprintf(stderr, "%s: %s\n", scene.name.c_str(), sim.error().message().c_str());
        return 1;
      }
      for (int f = 0; f < warmup; ++f)
        if (Status s = sim->step(); !s) {
          std::fprintf(stderr, "%s: %s\n", scene.name.c_str(), s.error().message().c_str());
          return 1;
        }
      sims.push_back(std::move(*sim));
    }
    std::vector<std::vector<double>> times(std::size(configs));
    std::vector<std::vector<double>> ratios(std::size(configs));  // per round: 1 thread's median / this one's
    const int scene_rounds = std::max(3, rounds / scene.rounds_scale);
    for (int r = 0; r < scene_rounds; ++r) {
      for (std::size_t k = 0; k < sims.size(); ++k) {
        const std::size_t c = (k + static_cast<std::size_t>(r)) % sims.size();  // rotate who goes first
        std::this_thread::sleep_for(std::chrono::milliseconds(4));  // past every team's idle spin
        for (int f = -1; f < frames; ++f) {
          const auto a = std::chrono::steady_clock::now();
          if (Status s = sims[c].step(); !s) {
            std::fprintf(stderr, "%s: %s\n", scene.name.c_str(), s.error().message().c_str());
            return 1;
          }
          if (f >= 0) times[c].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
        }
      }
      const auto round_median = [&](std::size_t c) {
        return percentile(std::vector<double>(times[c].end() - frames, times[c].end()), 0.5);
      };
      for (std::size_t c = 0; c < sims.size(); ++c) ratios[c].push_back(round_median(0) / round_median(c));
    }
    const SceneInfo& info = sims[0].info();
    std::printf("%-26s %9u", scene.name.c_str(), info.constraints());
    for (std::size_t c = 0; c < sims.size(); ++c) {
      const double median = percentile(times[c], 0.5), speedup = percentile(ratios[c], 0.5);
      std::printf(" %7.3f %4.2fx", median, speedup);
      if (out)
        std::fprintf(out, "%s,%u,%u,%d,%s,%u,%.4f,%.4f,%.3f,%.3f,%.3f\n", scene.name.c_str(), info.constraints(),
                     info.particles, busy ? 1 : 0, configs[c].name, c == 0 ? 1u : team_threads, median,
                     percentile(times[c], 0.9), speedup, percentile(ratios[c], 0.1), percentile(ratios[c], 0.9));
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  if (spinner > 0) {
    kill(spinner, SIGKILL);
    waitpid(spinner, nullptr, 0);
  }
  if (out) std::fclose(out);
  return status;
}
