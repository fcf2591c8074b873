// needle_forces — the force a needle feels over depth as it is pushed at
// constant speed into a pinned tissue pad of 2 mm cells
// (tests/needle_forces_scene.h), for several Young's moduli: the stiffness
// phase before the capsule is punctured, the drop at puncture, then the
// shaft's friction and the cutting force (Okamura, Simone and O'Leary,
// "Force modeling for needle insertion into soft tissue", IEEE TBME 51(10),
// 2004; docs/needles.md, "Needle forces").
//
//   bench_needle_forces [--E PA,PA,...] [--tip-radius M] [--puncture N]
//       [--friction N/M] [--static-friction N/M] [--viscous NS/M2]
//       [--stick-velocity M/S] [--cutting N] [--speed M/S] [--depth M]
//       [--substeps N] [--iterations N] [--csv FILE]
//     prints (and with --csv writes) E, frame, depth, force, tip force,
//     punctured, inverted tets; then per E the force and depth at puncture,
//     the pre-puncture stiffness (least-squares slope of force over depth
//     between 0.2 and 1.2 mm) and the most inverted tets before puncture.
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "command_line.h"
#include "needle_forces_scene.h"

// The depths [m] over which the stiffness is the slope of force over depth:
// the same for every E (a rounded tip stiffens as it goes in).
constexpr double kFrom = 2e-4, kTo = 1.2e-3;

int main(int argc, char** argv) {
  sinew::test::NeedlePushSettings s;
  std::string moduli = "5000,20000,50000", csv;
  double depth = 0.011;
  sinew::examples::CommandLine cli(
      "bench_needle_forces",
      "The force over depth of a needle pushed at constant speed into a pinned pad of 2 mm cells, for each --E:\n"
      "the stiffness before puncture, the drop at puncture, then the shaft's friction (docs/needles.md).");
  using sinew::examples::at_least;
  using sinew::examples::greater_than;
  auto& app = cli.app();
  app.add_option("--E", moduli, "Young's moduli [Pa], comma-separated");
  app.add_option("--tip-radius", s.tip_radius, "NeedleDesc::tip_radius [m]")->check(at_least(0));
  app.add_option("--puncture", s.puncture_force, "NeedleDesc::puncture_force [N]")->check(greater_than(0));
  app.add_option("--friction", s.shaft_friction, "NeedleDesc::shaft_friction [N/m]")->check(at_least(0));
  app.add_option("--static-friction", s.shaft_static_friction, "NeedleDesc::shaft_static_friction [N/m]")
      ->check(at_least(0));
  app.add_option("--viscous", s.shaft_viscous_friction, "NeedleDesc::shaft_viscous_friction [N s/m^2]")
      ->check(at_least(0));
  app.add_option("--stick-velocity", s.shaft_stick_velocity, "NeedleDesc::shaft_stick_velocity [m/s]")
      ->check(greater_than(0));
  app.add_option("--cutting", s.cutting_force, "NeedleDesc::cutting_force [N]")->check(at_least(0));
  app.add_option("--speed", s.speed, "Of the push [m/s]")->check(greater_than(0));
  app.add_option("--depth", depth, "How deep the tip goes [m]")->check(greater_than(0));
  app.add_option("--substeps", s.substeps, "Substeps per frame of 1/60 s")->check(at_least(1));
  app.add_option("--iterations", s.iterations, "Sweeps per substep")->check(at_least(1));
  app.add_option("--csv", csv, "Write the trace to FILE");
  if (auto code = cli.parse(argc, argv)) return *code;
  std::FILE* out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (!csv.empty() && !out) {
    std::fprintf(stderr, "cannot write %s\n", csv.c_str());
    return 1;
  }
  const char* header = "E_Pa,frame,depth_mm,force_N,tip_force_N,punctured,inverted_tets,punctures,pushing\n";
  std::printf("%s", header);
  if (out) std::fprintf(out, "%s", header);
  std::stringstream list(moduli);
  std::string item;
  std::vector<std::string> summary;
  while (std::getline(list, item, ',')) {
    s.young = std::stod(item);
    auto sim = sinew::Simulation::create(sinew::test::needle_push_scene(s), {.backend = "cpu", .threads = 1});
    if (!sim) {
      std::fprintf(stderr, "%s\n", sim.error().message().c_str());
      return 1;
    }
    std::vector<sinew::test::NeedlePushSample> trace;
    if (auto st = sinew::test::push_needle(*sim, s, depth, trace); !st) {
      std::fprintf(stderr, "%s\n", st.error().message().c_str());
      return 1;
    }
    double at_force = 0.0, at_depth = 0.0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    std::uint32_t inverted = 0;
    bool punctured = false;
    for (std::size_t f = 0; f < trace.size(); ++f) {
      const auto& t = trace[f];
      char line[160];
      std::snprintf(line, sizeof line, "%g,%zu,%.4f,%.5f,%.5f,%d,%u,%zu,%d\n", s.young, f + 1, t.depth * 1e3,
                    t.force, t.tip_force, t.punctured ? 1 : 0, t.inverted_tets, t.punctures, t.pushing ? 1 : 0);
      std::printf("%s", line);
      if (out) std::fprintf(out, "%s", line);
      if (!punctured) inverted = std::max(inverted, t.inverted_tets);
      if (!punctured && t.punctured) at_force = t.tip_force, at_depth = t.depth;  // the frame whose push punctured
      punctured = punctured || t.punctured;
      if (!punctured && t.depth >= kFrom && t.depth <= kTo)
        sx += t.depth, sy += t.force, sxx += t.depth * t.depth, sxy += t.depth * t.force, ++n;
    }
    const double slope = n >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0.0;
    char line[240];
    std::snprintf(line, sizeof line,
                  "# E %g Pa: punctured %s at depth %.2f mm after a push of %.4f N; stiffness %.1f N/m; most "
                  "inverted tets before puncture %u\n",
                  s.young, punctured ? "yes" : "no", at_depth * 1e3, at_force, slope, inverted);
    summary.push_back(line);
  }
  for (const auto& line : summary) std::printf("%s", line.c_str());
  if (out) std::fclose(out);
  return 0;
}
