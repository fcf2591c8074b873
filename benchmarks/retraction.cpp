// bench_retraction — the reference scene S1 (examples/common/retraction_scene.h):
// kidney_57k, corotational FEM, pinned along one side, grasped at its pole
// and pulled while a capsule probe presses its side, mesh self-collision on,
// both tools driven through the haptic tool bridge; 60 Hz frames. Times
// whole frames (the loops' ticks, the tools' hand-off and step()).
//
//   bench_retraction BACKEND FRAMES [--mesh M] [--substeps N] [--iterations N] [--threads N] [--haptics]
//                    [--haptic-cpus C0 C1] [--local-contacts] [--probe-trace FILE]
//                    [--probe-force N] [--contact-sweeps N]
//   e.g. bench_retraction cpu 180
//        bench_retraction cpu 60 --probe-force 5 --contact-sweeps 4   (contacts under a 5 N press)
//
// Prints CSV: a header and one line of the frame times (median, p95, worst
// [ms]; the median process CPU time; the 1-minute load average at the end)
// and the scene's figures at the last frame; the contacts' worst over the
// frames (RetractionCheck: the kidney's self-contacts, its faces against
// the tools, its vertices inside the probe, each [m] against the
// thickness) and the probe's push and depth at the end; then the per-stage
// profile (FrameStats::stages), one line per stage with its median and p95
// [ms] over the frames. --haptics runs both haptic loops on their own threads
// at 1 kHz of wall time while the frames run back to back (the solver using
// every worker), and adds each loop's timing: ticks, missed ticks
// (tick-to-tick > 2 periods), period jitter p50/p99.9/max [us] and the age
// of the state it rendered p50 [ms]. Every run prints the probe's press as
// its hand felt it (report_probe below); --local-contacts renders it with
// the local contact model, --probe-trace writes its every tick as CSV.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include "bench_support.h"
#include "command_line.h"
#include "frame_profile.h"
#include "retraction_scene.h"

namespace {

using sinew::bench::percentile;

int fail(const std::string& what) {
  std::fprintf(stderr, "bench_retraction: %s\n", what.c_str());
  return 1;
}

// The probe's press as its hand felt it, from the probe loop's telemetry:
// the force along the press (-z: the push is +z) before the device reached
// the kidney (the coupling's pull alone), how soon after it the push rose
// past 1 mN above that, its peak over the force held at the end, its
// largest fall from one tick to the next while pressing in, the least
// energy the local model kept over any 100-tick window (< 0: created), and
// the passivity observer's violations (HapticCounters).
// [in] path: also writes every tick as CSV when not empty.
sinew::Status report_probe(sinew::examples::RetractionScene& r, const sinew::examples::RetractionSettings& s,
                           const std::string& path) {
  std::vector<sinew::haptics::TickRecord> t;
  if (auto st = r.probe_loop().copy_telemetry(t); !st) return st;
  if (t.size() < 2) return sinew::Error(sinew::ErrorCode::bad_parameter, "too few probe ticks");
  const double t0 = 1e-9 * double(t.front().start_ns) - 1e-3, contact = sinew::examples::probe_contact_time() / s.script_speed;
  auto sec = [&](const sinew::haptics::TickRecord& k) { return 1e-9 * double(k.start_ns) - t0; };
  const double press_end = sinew::examples::kPressEnd / s.script_speed;
  double before = 0.0, onset = -1.0, peak = 0.0, kept = INFINITY, fall = 0.0;
  for (const auto& k : t)
    if (sec(k) < contact) before = std::max(before, k.force[2]);
  std::vector<double> put_in(t.size(), 0.0);
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (onset < 0.0 && sec(t[i]) >= contact && t[i].force[2] > before + 1e-3) onset = sec(t[i]) - contact;
    if (sec(t[i]) >= contact) peak = std::max(peak, t[i].force[2]);
    if (i == 0) continue;
    if (sec(t[i]) > contact && sec(t[i]) <= press_end) fall = std::max(fall, t[i - 1].force[2] - t[i].force[2]);
    double w = 0.0;
    for (int c = 0; c < 3; ++c) w -= t[i - 1].force[c] * (t[i].device_position[c] - t[i - 1].device_position[c]);
    put_in[i] = put_in[i - 1] + w;
    if (i >= 100)
      kept = std::min(kept, (put_in[i] - put_in[i - 100]) - (t[i].contact_energy - t[i - 100].contact_energy));
  }
  auto probe = r.sim().tools().tool(1);
  if (!probe) return probe.error();
  auto state = r.sim().tools().state(*probe);
  if (!state) return state.error();
  const double held = t.back().force[2];
  std::printf("probe,local_contacts,contact_s,force_before_contact_n,onset_ms,held_force_n,physics_contact_force_n,"
              "peak_over_held,largest_fall_pressing_n,least_window_energy_j,passivity_violations\n");
  std::printf("probe,%d,%.4f,%.4f,%.1f,%.4f,%.4f,%.4f,%.4f,%.3e,%llu\n", s.local_contacts ? 1 : 0, contact, before,
              onset < 0.0 ? -1.0 : 1e3 * onset, held, state->contact_force[2], held > 0.0 ? peak / held - 1.0 : 0.0,
              fall, s.local_contacts ? kept : NAN,
              static_cast<unsigned long long>(r.probe_loop().counters().passivity_violations));
  if (path.empty()) return {};
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return sinew::Error(sinew::ErrorCode::bad_input_file, "cannot write " + path);
  std::fprintf(f, "t_s,device_z_m,rendered_z_m,force_z_n,contact_energy_j,local_contacts,gap_offset_m\n");
  for (const auto& k : t)
    std::fprintf(f, "%.4f,%.6f,%.6f,%.6f,%.6e,%u,%.3e\n", sec(k), k.device_position[2], k.tool_position[2], k.force[2],
                 k.contact_energy, k.local_contacts, k.contact_gap_offset);
  std::fclose(f);
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  sinew::examples::CommandLine cli(
      "bench_retraction",
      std::string(sinew::examples::kRetractionAbout) +
          "Prints CSV: the frame times (median, p95, worst [ms]) and the per-stage profile.\n"
          "e.g. bench_retraction cpu 180 --threads 2");
  sinew::examples::RetractionSettings s{.mesh = std::string(SINEW_DATA_DIR) + "/meshes/tet/kidney_57k.node"};
  int frames = 0;
  bool haptics = false, self_collision = true;
  cli.app().add_option("backend", s.backend, "Backend: cpu, opencl, vulkan or auto")
      ->required()
      ->check(CLI::IsMember({"auto", "cpu", "opencl", "vulkan"}));
  cli.app().add_option("frames", frames, "Frames of 1/60 s to time")->required()->check(sinew::examples::at_least(1));
  cli.app().add_option("--mesh", s.mesh, "The kidney's tet mesh (millimetres)");
  cli.app().add_option("--substeps", s.substeps, "Substeps per frame")->check(sinew::examples::at_least(1));
  cli.app().add_option("--iterations", s.iterations, "Iterations per substep")->check(sinew::examples::at_least(1));
  cli.app().add_option("--threads", s.threads, "cpu backend worker threads (0: all)")->check(sinew::examples::at_least(0));
  cli.app().add_option("--young", s.young, "Young's modulus [Pa]")->check(sinew::examples::greater_than(0));
  cli.add_switch("--self-collision", self_collision, "The kidney's mesh self-collision");
  cli.app().add_option("--poisson", s.poisson, "Poisson ratio")->check(CLI::Range(0.01, 0.49));
  cli.app().add_flag("--haptics", haptics, "Both haptic loops on their own threads at 1 kHz of wall time; their timing");
  std::string probe_trace;
  cli.app().add_flag("--local-contacts", s.local_contacts, "The probe's loop renders the local contact model");
  std::vector<int> haptic_cpus;
  cli.app()
      .add_option("--haptic-cpus", haptic_cpus, "--haptics: pin the grasper's and the probe's loops to these two CPUs")
      ->expected(2);
  cli.app().add_option("--probe-trace", probe_trace, "Write the probe loop's ticks (force against time) as CSV");
  cli.app()
      .add_option("--probe-force", s.probe_force, "Press the probe with this force [N] instead of its hand (0: the hand)")
      ->check(CLI::NonNegativeNumber);
  cli.app()
      .add_option("--contact-sweeps", s.contact_sweeps, "SolverSettings::contact_sweeps")
      ->check(sinew::examples::at_least(0));
  if (auto exit = cli.parse(argc, argv)) return *exit;
  s.self_collision = self_collision;
  s.realtime_haptics = haptics;
  if (haptic_cpus.size() == 2) s.haptic_cpus = {haptic_cpus[0], haptic_cpus[1]};

  auto scene = sinew::examples::RetractionScene::create(s);
  if (!scene) return fail(scene.error().message());
  sinew::examples::RetractionScene& r = **scene;
  if (haptics)
    if (auto st = r.start_haptics(); !st) return fail(st.error().message());
  sinew::bench::FrameProfile profile;
  sinew::examples::RetractionCheck worst;  // the contacts' worst over the frames
  for (int f = 0; f < frames; ++f) {
    profile.start();
    if (auto st = r.frame(); !st) return fail(st.error().message());
    profile.stop(r.sim().last_frame());
    auto c = r.check();
    if (!c) return fail(c.error().message());
    worst.self_violation = std::max(worst.self_violation, c->self_violation);
    worst.tool_violation = std::max(worst.tool_violation, c->tool_violation);
    worst.probe_penetration = std::max(worst.probe_penetration, c->probe_penetration);
  }
  r.stop_haptics();
  auto c = r.check();
  if (!c) return fail(c.error().message());
  const auto& st = r.sim().last_frame();
  std::printf("backend,particles,held,substeps,iterations,frames,median_ms,p95_ms,worst_ms,cpu_median_ms,"
              "load_1min,mesh_contacts,contact_violation_m,max_slip_m,pole_lift_m,grasp_force_y_n,device_force_y_n,"
              "inverted_tets\n");
  std::printf("%s,%u,%zu,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.2f,%u,%.3e,%.3e,%.3e,%.4f,%.4f,%zu\n", s.backend.c_str(),
              r.sim().info().particles, r.held().size(), s.substeps, s.iterations, frames, profile.wall(0.5),
              profile.wall(0.95), profile.wall(1.0), profile.cpu(0.5), sinew::bench::load_average(), st.mesh_contacts,
              c->contact_violation, c->max_slip, c->pole_lift, c->grasp_force[1], c->device_force[1],
              c->inverted_tets);
  std::printf("contacts,contact_sweeps,probe_force_set_n,thickness_m,worst_self_violation_m,worst_tool_violation_m,"
              "worst_probe_penetration_m,probe_push_n,probe_depth_m\n");
  std::printf("contacts,%d,%.3f,%.3e,%.4e,%.4e,%.4e,%.4f,%.4e\n", s.contact_sweeps, s.probe_force,
              r.scene().mesh_collision.thickness, worst.self_violation, worst.tool_violation, worst.probe_penetration,
              c->probe_force, c->probe_depth);
  profile.print_stages();
  // Each stage's own figures of the last frame (StageProfile::counters).
  std::printf("stage,counter,last_frame\n");
  for (const auto& p : st.stages)
    for (const auto& k : p.counters) std::printf("%s,%s,%.6g\n", p.name.c_str(), k.name.c_str(), k.value);
  if (!probe_trace.empty() || !haptics)
    if (auto rep = report_probe(r, s, probe_trace); !rep) return fail(rep.error().message());
  if (!haptics) return 0;

  // Each loop's timing, from its telemetry (after the first 100 ticks: the thread's start).
  std::printf("haptic_loop,scheduling,rate_hz,ticks,missed_ticks,jitter_p50_us,jitter_p99_9_us,jitter_max_us,"
              "render_age_p50_ms\n");
  for (int hand = 0; hand < 2; ++hand) {
    sinew::haptics::HapticLoop& loop = hand == 0 ? r.grasper_loop() : r.probe_loop();
    std::vector<sinew::haptics::TickRecord> ticks;
    if (auto t = loop.copy_telemetry(ticks); !t) return fail(t.error().message());
    if (ticks.size() > 100) ticks.erase(ticks.begin(), ticks.begin() + 100);
    if (ticks.size() < 2) return fail("too few haptic ticks: run more frames");
    const double period_us = 1e3;
    std::vector<double> jitter, age;
    std::uint64_t missed = 0;
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      age.push_back(1e3 * ticks[i].render_age);
      if (i == 0) continue;
      const double p = 1e-3 * double(ticks[i].start_ns - ticks[i - 1].start_ns);
      jitter.push_back(std::abs(p - period_us));
      if (p > 2 * period_us) ++missed;
    }
    const double span = 1e-9 * double(ticks.back().start_ns - ticks.front().start_ns);
    std::printf("%s,\"%s\",%.3f,%zu,%llu,%.1f,%.1f,%.1f,%.3f\n", hand == 0 ? "grasper" : "probe",
                loop.scheduling().describe().c_str(), double(ticks.size() - 1) / span, ticks.size(),
                static_cast<unsigned long long>(missed), percentile(jitter, 0.5), percentile(jitter, 0.999),
                percentile(jitter, 1.0), percentile(age, 0.5));
  }
  return 0;
}
